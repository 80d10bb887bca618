"""Positions in a TOML file: tomllib keeps none, so a Locator finds a table's or key's line:col in the text.

The scene loader (load.py), the schema check (schema.py) and the placement files locate every error with it. A
scene of 100,000 permutations asks for hundreds of thousands of positions (every part of a permutation key records
where it was asked for, spec/where.py), so a lookup reads no more than its own table: the headers are indexed
once, a key a table lacks is answered from the table's first keys, and the patterns are made once per key path.
"""
from __future__ import annotations

import functools
import re

from ..lang import SourceError

_TABLE = re.compile(r"^\s*\[")  # a line that opens a table: a key search stops there
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_FIRST_KEY = re.compile(r"""^\s*(?:([A-Za-z0-9_-]+)|"([^"]*)"|'([^']*)')\s*[.=]""")  # a line's first key, as find reads it


class Locator:
    """Finds line:col of tables and keys in TOML text (tomllib keeps no positions).

    Knows the forms a scene is written in: [a.b] and [[a]] headers (quoted parts too: [materials."m"]),
    keys inside inline tables (params = { n = 1 }), dotted keys (params.n = 1) and sub-tables
    ([materials.m.params]). What it cannot find is located at its table's header, or at 1:1."""

    _HEADER = re.compile(r"^\s*\[\[?\s*([^\[\]]*?)\s*\]\]?")

    def __init__(self, path: str, text: str):
        self.path, self.lines = path, text.splitlines()
        self._headers: dict[str, list[int]] | None = None  # "a.b" -> the lines of its [a.b] / [[a.b]] headers
        self._parents: set[str] = set()
        self._first_keys: dict[int, set[str]] | None = None  # a header's line -> _firsts

    @staticmethod
    @functools.lru_cache(maxsize=65536)
    def _name(header: str) -> str:
        return ".".join(p.strip().strip("\"'") for p in header.split("."))

    def _firsts(self, start: int) -> set[str]:
        """The first key of every line of the table whose header is line `start` (up to the next header): what
        a key path must begin with for find to find it there, so that a key the table lacks (a material's alpha,
        most often) is answered without a scan. A quoted key counts by its text; a superset of what find's
        patterns can match, so leaving a key out of it never changes an answer."""
        if self._first_keys is None:
            self._first_keys = {}
        found = self._first_keys.get(start)
        if found is None:
            found = self._first_keys[start] = set()
            for i in range(start + 1, len(self.lines)):
                line = self.lines[i]
                if _TABLE.match(line):
                    break
                m = _FIRST_KEY.match(line)
                if m:
                    found.add(m[1] if m[1] is not None else m[2] if m[2] is not None else m[3])
        return found

    def _index(self) -> dict[str, list[int]]:
        """The headers' lines by name, and (self._parents) every header's dotted prefixes: only a table named
        there can have a sub-table ([materials.m.params]). One pass over the text, on the first lookup: every
        lookup is then O(1)."""
        if self._headers is None:
            self._headers = {}
            for i, line in enumerate(self.lines):
                m = self._HEADER.match(line)
                if m:
                    self._headers.setdefault(self._name(m[1]), []).append(i)
            self._parents = {".".join(parts[:j]) for name in self._headers
                             for parts in [name.split(".")] for j in range(1, len(parts))}
        return self._headers

    def _header(self, header: str, nth: int = 0) -> int:
        hits = self._index().get(self._name(header), [])
        return hits[nth] if len(hits) > nth else -1

    @staticmethod
    def _key(k: str) -> str:
        e = re.escape(k)
        return rf"(?:{e}|\"{e}\"|'{e}')"

    @staticmethod
    @functools.lru_cache(maxsize=4096)
    def _patterns(keys: tuple[str, ...]) -> tuple:
        """find's patterns for a key path, made once per path (a scene of 10,000 materials asks for the same few
        paths in every table): per dotted prefix, longest first, `a . b =` and the last key's `b =`; and the
        keys after it inside an inline table."""
        k = Locator._key
        prefixes = tuple((j, re.compile(r"^\s*" + r"\s*\.\s*".join(k(x) for x in keys[:j]) + r"\s*="),
                          re.compile(k(keys[j - 1]) + r"\s*=")) for j in range(len(keys), 0, -1))
        inner = tuple(re.compile(r"(?<![\w.])" + k(x) + r"\s*=") for x in keys)
        return prefixes, inner

    def find(self, header: str, *keys: str, nth: int = 0) -> tuple[int, int]:
        """(line, col) of header's key path (keys may continue inside an inline table)."""
        if header and keys and header != "objects":
            self._index()
            for j in range(len(keys), 0, -1) if self._name(header) in self._parents else ():
                sub = ".".join((header, *keys[:j]))  # the deepest sub-table: [materials.m.params], [….samplers.t]
                if self._header(sub) >= 0:
                    return self.find(sub, *keys[j:])
        start = self._header(header, nth) if header else -1
        if header and start < 0:
            return 1, 1
        line_no, col = start + 1, 1
        if not keys or (_BARE_KEY.fullmatch(keys[0]) and keys[0] not in self._firsts(start)):
            return line_no, col
        prefixes, inner = self._patterns(tuple(keys))
        i = start + 1
        while i < len(self.lines):
            line = self.lines[i]
            if _TABLE.match(line):
                break
            for j, full, tail in prefixes:  # the longest dotted prefix of the path: params.n = 1
                m = full.match(line)
                if m:
                    break
            if m:
                last = tail.search(line[:m.end()])
                line_no, col = i + 1, (last.start() if last else line.index(keys[0])) + 1
                for pattern in inner[j:]:
                    km = pattern.search(line[col:])
                    if km:
                        col = col + km.start() + 1
                return line_no, col
            i += 1
        return line_no, col

    def top(self, key: str) -> tuple[int, int]:
        """(line, col) of a top-level table [key] / [[key]] or a top-level `key =`."""
        for i, line in enumerate(self.lines):
            if re.match(r"^\s*\[\[?\s*" + re.escape(key) + r"\b", line) or re.match(r"^\s*" + re.escape(key) + r"\s*=", line):
                return i + 1, line.index(key) + 1
        return 1, 1

    def error(self, where: tuple[int, int], message: str, hint: str = "") -> SourceError:
        return SourceError(self.path, where[0], where[1], message, hint)
