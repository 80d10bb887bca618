"""Errors that point at a place in a user's file: `path:line:col: what is wrong — what to do`."""
from __future__ import annotations


class SourceError(Exception):
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
