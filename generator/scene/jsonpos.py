"""Where a JSON pointer's value starts in a JSON text, so that an error about a glTF object can name its line.

`json.loads` keeps no positions. `locate(text, pointers)` scans the text once and returns the character
offset at which each wanted pointer's value begins (its `{`, `[`, `"` or first digit); `Lines` turns
offsets into the 1-based line and column an editor shows (lines broken at \\r\\n, \\r or \\n, columns in
characters, as lang/errors.position counts them).

The scan is iterative and bounded: it descends only into the containers on the way to a wanted pointer
and skips every other value by counting brackets outside strings (a string jumps to its closing
quote with str.find), so each step moves forward and the work is linear in the text's length, whatever it nests.
It expects text that json.loads has accepted; on anything else it stops and returns what it found.
A key given twice: the last one's position, as json.loads keeps the last value (what the loader read).
"""
from __future__ import annotations

import bisect
import re
from dataclasses import dataclass
from json.decoder import scanstring

from ..lang.errors import SourceError
from ..spec.where import Origin, Where

_WS = re.compile(r"[ \t\n\r]*")
_PLAIN = re.compile(r'[^"\[\]{}]+')  # inside a skipped container: anything but strings and brackets
_SCALAR = re.compile(r"-?(?:0|[1-9][0-9]*)(?:\.[0-9]+)?(?:[eE][-+]?[0-9]+)?|true|false|null")
_LINE_BREAK = re.compile(r"\r\n|\r|\n")


def pointer(*parts) -> str:
    """The JSON pointer (RFC 6901) of a path of keys and indices: ("materials", 2) → "/materials/2"."""
    return "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in parts)


class _Node:
    """A node of the trie of wanted pointers: one per reference token on the way to one."""

    __slots__ = ("children", "pointer", "seen")

    def __init__(self):
        self.children: dict[str, _Node] = {}
        self.pointer: str | None = None  # set where a wanted pointer ends
        self.seen = False


def _trie(pointers) -> _Node:
    root = _Node()
    for p in pointers:
        node = root
        for token in p.split("/")[1:] if p else ():
            token = token.replace("~1", "/").replace("~0", "~")
            node = node.children.setdefault(token, _Node())
        node.pointer = p
    return root


def locate(text: str, pointers) -> dict[str, int]:
    """{pointer: offset in text of its value} for each of `pointers` the text has ("" is the whole document)."""
    found: dict[str, int] = {}
    stack: list[list] = []  # open containers: [trie node, is an array, index of the current element]
    node, i = _trie(pointers), _WS.match(text, 0).end()
    n = len(text)
    while i < n:
        if node is not None:
            if node.seen:  # a repeated key: what was found in the earlier value is stale
                _forget(node, found)
            node.seen = True
            if node.pointer is not None:
                found[node.pointer] = i
        c = text[i]
        if c in "{[" and node is not None and node.children:
            stack.append([node, c == "[", 0])
            i = _WS.match(text, i + 1).end()
            if text[i:i + 1] not in ("]", "}", ""):
                node, i = _member(text, i, stack[-1])
                if i < 0:
                    return found
                continue
            stack.pop()
            i += 1
        else:
            i = _skip(text, i)
        while True:  # after a value: the next member of its container, or the container's end
            if not stack:
                return found
            i = _WS.match(text, i).end()
            c = text[i:i + 1]
            if c == ",":
                stack[-1][2] += 1
                node, i = _member(text, _WS.match(text, i + 1).end(), stack[-1])
                if i < 0:
                    return found
                break
            if c not in ("]", "}"):
                return found
            stack.pop()
            i += 1
    return found


def _forget(node: _Node, found: dict) -> None:
    todo = list(node.children.values())
    while todo:
        x = todo.pop()
        x.seen = False
        found.pop(x.pointer, None)
        todo += x.children.values()


def _member(text: str, i: int, frame: list) -> tuple[_Node | None, int]:
    """(trie node or None when no wanted pointer goes there, offset of the value) of the container member that
    starts at i; offset -1 when it cannot be read."""
    if frame[1]:
        return frame[0].children.get(str(frame[2])), i
    if text[i:i + 1] != '"':
        return None, -1
    try:
        key, i = scanstring(text, i + 1)
    except ValueError:
        return None, -1
    i = _WS.match(text, i).end()
    if text[i:i + 1] != ":":
        return None, -1
    return frame[0].children.get(key), _WS.match(text, i + 1).end()


def _skip(text: str, i: int) -> int:
    """The offset just past the value that starts at i (past the text's end when it is cut short)."""
    c = text[i]
    if c == '"':
        return _string_end(text, i)
    if c not in "{[":
        m = _SCALAR.match(text, i)
        return m.end() if m and m.end() > i else i + 1
    depth, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == '"':
            i = _string_end(text, i)
        elif c in "{[":
            depth, i = depth + 1, i + 1
        elif c in "}]":
            depth, i = depth - 1, i + 1
            if depth == 0:
                return i
        else:
            i = _PLAIN.match(text, i).end()
    return n


def _string_end(text: str, i: int) -> int:
    """The offset just past the string that opens at i: its first quote not escaped by an odd run of backslashes."""
    j = text.find('"', i + 1)
    while j > 0:
        k = j
        while text[k - 1] == "\\":
            k -= 1
        if (j - k) % 2 == 0:
            return j + 1
        j = text.find('"', j + 1)
    return len(text)


class Lines:
    """Offsets of a text → (line, column), 1-based: the line starts are found once, each lookup is a bisection."""

    def __init__(self, text: str):
        self._starts = [0] + [m.end() for m in _LINE_BREAK.finditer(text)]

    def position(self, offset: int) -> tuple[int, int]:
        k = bisect.bisect_right(self._starts, offset) - 1
        return k + 1, offset - self._starts[k] + 1


@dataclass(frozen=True)
class JsonWhere(Where):
    """A position in a JSON file that also names the JSON pointer there: its errors read
    `model.gltf:12:5: /materials/2: what is wrong — what to do`."""

    pointer: str = ""

    def error(self, message: str, hint: str = "") -> SourceError:
        return SourceError(self.path, self.line, self.col, f"{self.pointer}: {message}", hint)


GLB_JSON_START = 20  # a .glb's JSON chunk data begins after the 12-byte header and its 8-byte chunk header


def origins(path: str, text: str, asks: dict, glb: bool = False) -> dict:
    """{key: Origin} for asks = {key: ((part, pointer), ...)}: each part at its pointer's value in `text`, one
    scan for all of them. In a .gltf a part is at its value's line and column; a .glb has no lines, so its
    parts are at 1:1 and name the value's byte offset in the file beside the pointer. A pointer the text
    does not have (none should be missing) is at 1:1."""
    found = locate(text, {p for parts in asks.values() for _, p in parts})
    at: dict[str, Where] = {}
    if glb:  # byte offsets: the UTF-8 length of the text before each value, counted once in offset order
        done, size = 0, GLB_JSON_START
        for p, off in sorted(found.items(), key=lambda kv: kv[1]):
            size += len(text[done:off].encode("utf-8"))
            done = off
            at[p] = JsonWhere(path, 1, 1, f"{p} (byte {size})")
    else:
        lines = Lines(text)
        at = {p: JsonWhere(path, *lines.position(off), p) for p, off in found.items()}
    return {key: Origin(tuple((part, at.get(p) or JsonWhere(path, 1, 1, p)) for part, p in parts))
            for key, parts in asks.items()}
