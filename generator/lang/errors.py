"""Errors that point at a place in a user's file: `path:line:col: what is wrong — what to do`."""
from __future__ import annotations


class UserError(Exception):
    """An error the user can fix; the message says what is wrong and what to do."""


class SourceError(UserError):
    """An error in a brick, scene or other input file, with its location."""

    def __init__(self, path: str, line: int, col: int, message: str, hint: str = ""):
        self.path, self.line, self.col = str(path), int(line), int(col)
        self.message, self.hint = message, hint
        super().__init__(str(self))

    def __str__(self) -> str:
        text = f"{self.path}:{self.line}:{self.col}: {self.message}"
        return f"{text} — {self.hint}" if self.hint else text


def at(loc, message: str, hint: str = "") -> SourceError:
    """A SourceError at an ir.Loc (or anything with path/line/col)."""
    return SourceError(loc.path, loc.line, loc.col, message, hint)


def read_text(path, what: str) -> str:
    """A UTF-8 file's text; a decoding or reading problem is a SourceError at the offending byte."""
    shown = str(path)
    try:
        data = open(path, "rb").read()
    except OSError as e:
        raise SourceError(shown, 1, 1, f"cannot read {what}: {e.strerror}", "check the path") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data.count(b"\n", 0, e.start) + 1
        col = e.start - (data.rfind(b"\n", 0, e.start) + 1) + 1
        raise SourceError(shown, line, col, f"byte 0x{data[e.start]:02x} is not UTF-8",
                          f"save the {what} as UTF-8") from None
