"""Errors that point at a place in a user's file: `path:line:col: what is wrong — what to do`."""
from __future__ import annotations

import re


class UserError(Exception):
    """An error the user can fix; the message says what is wrong and what to do."""


class UsageError(UserError):
    """A command line that cannot mean anything: an option's value out of its range or not of its form (exit 2)."""


class EnvironmentMissing(UserError):
    """A tool or the Vulkan device a command needs is not on this machine (exit 3): never silently skipped."""


class SourceError(UserError):
    """An error in a brick, scene or other input file, with its location."""

    def __init__(self, path: str, line: int, col: int, message: str, hint: str = ""):
        self.path, self.line, self.col = str(path), int(line), int(col)
        self.message, self.hint = message, hint
        super().__init__(str(self))

    def __str__(self) -> str:
        text = f"{self.path}:{self.line}:{self.col}: {self.message}"
        text = f"{text} — {self.hint}" if self.hint else text
        # one line, whatever an input put into a name it quotes: control characters and line breaks shown escaped
        return "".join(c if c.isprintable() else ascii(c)[1:-1] for c in text)


def at(loc, message: str, hint: str = "") -> SourceError:
    """A SourceError at an ir.Loc (or anything with path/line/col)."""
    return SourceError(loc.path, loc.line, loc.col, message, hint)


MAX_INPUT_BYTES = 16 << 20  # a brick or scene file larger than this is refused (the shipped ones are < 20 KB)
_LINE_BREAK = re.compile(r"\r\n|\r|\n")  # line breaks as Python and editors count them (a form feed is none)
_BOMS = {b"\xff\xfe\x00\x00": "UTF-32", b"\x00\x00\xfe\xff": "UTF-32", b"\xff\xfe": "UTF-16",
         b"\xfe\xff": "UTF-16"}


def position(text: str, index: int) -> tuple[int, int]:
    """The 1-based line and column (in characters, as editors show them) of text[index]."""
    line, start = 1, 0
    for m in _LINE_BREAK.finditer(text, 0, index):
        line, start = line + 1, m.end()
    return line, index - start + 1


def read_bytes(path, what: str, limit: int = MAX_INPUT_BYTES) -> bytes:
    """A regular file's bytes, at most `limit` of them; anything else (a FIFO, a device, a larger file, an
    unreadable path) is one SourceError naming the file."""
    import os
    import stat

    shown = str(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO opens without waiting
    except OSError as e:
        raise SourceError(shown, 1, 1, f"cannot read {what}: {e.strerror}", "check the path") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = ("a FIFO" if stat.S_ISFIFO(st.st_mode) else "a device" if stat.S_ISCHR(st.st_mode) or
                    stat.S_ISBLK(st.st_mode) else "a socket" if stat.S_ISSOCK(st.st_mode) else "not a file")
            raise SourceError(shown, 1, 1, f"the {what} is {kind}, not a regular file", f"give a {what} file")
        if st.st_size > limit:
            raise SourceError(shown, 1, 1, f"the {what} is {st.st_size} bytes, more than the {limit} "
                              "allowed", f"split it, or check that this is a {what}")
        chunks, size = [], 0
        while True:
            part = os.read(fd, 1 << 20)
            if not part:
                break
            size += len(part)
            if size > limit:
                raise SourceError(shown, 1, 1, f"the {what} is more than {limit} bytes", "check the path")
            chunks.append(part)
        return b"".join(chunks)
    except OSError as e:
        raise SourceError(shown, 1, 1, f"cannot read {what}: {e.strerror}", "check the path") from None
    finally:
        os.close(fd)


def read_text(path, what: str, limit: int = MAX_INPUT_BYTES) -> str:
    """A UTF-8 file's text; a decoding or reading problem is a SourceError at the offending byte.

    Only regular files are read (a FIFO would block forever, a device or a symlink to /dev/zero never
    ends), and at most `limit` bytes of them: anything else is one located error. A UTF-8 byte-order mark
    at the start is dropped (Windows editors write one; Python reads source files the same way); a UTF-16
    or UTF-32 one is an error that says so.
    """
    data = read_bytes(path, what, limit)
    shown = str(path)
    for bom, encoding in _BOMS.items():
        if data.startswith(bom):
            raise SourceError(shown, 1, 1, f"the {what} is {encoding} text (it starts with a {encoding} byte-order "
                              "mark)", f"save the {what} as UTF-8")
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as e:
        before = data[:e.start].decode("utf-8")  # the bytes before the first bad one decode
        line, col = position(before, len(before))
        raise SourceError(shown, line, col, f"byte 0x{data[e.start]:02x} is not UTF-8",
                          f"save the {what} as UTF-8") from None
