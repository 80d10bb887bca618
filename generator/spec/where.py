"""Where a permutation was asked for, so that an error about it points there.

A permutation has no file of its own: its key is built from a scene's declarations (a material's
`brdf` and `packing`, its surface keys, the scene's `output`, each light's `type`), from a spec
string given on the command line, or by code. An `Origin` records the position of each part of
the key; resolution and linking raise a `KeyProblem` (what is wrong with which part, and what to
do) and `within(origin)` turns it into a located SourceError at that part's position, as naga's
`WithSpan` adds the span of what asked for a value to the error raised while handling it. Errors
with a position of their own (a brick's line) keep it: the brick line is the one to edit.

A position in a spec string reads `spec string 'lambert+phong':1:9` (the column of the token); a
key built by code, with no scene behind it, points into the key's own text:
`permutation key 'brdf=…;packing=…':1:27`.
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

from ..lang.errors import SourceError, UserError


@dataclass(frozen=True)
class Where:
    """One position: a file (or a spec string, or a key's text), line and column."""

    path: str
    line: int = 1
    col: int = 1

    def error(self, message: str, hint: str = "") -> SourceError:
        return SourceError(self.path, self.line, self.col, message, hint)


def spec_where(spec: str, col: int = 1) -> Where:
    """A column of a spec string given on the command line or by code."""
    return Where(f"spec string '{spec}'", 1, col)


@dataclass(frozen=True)
class Origin:
    """The positions of a permutation key's parts in the scene that asked for it: (part, Where) pairs, the
    first the fallback for a part not listed. Parts: brdf, packing, output, alpha, double_sided,
    vertex_color, emissive, light0, light1, …"""

    parts: tuple[tuple[str, Where], ...]

    def at(self, part: str) -> Where:
        return dict(self.parts).get(part) or self.parts[0][1]


class KeyProblem(UserError):
    """What is wrong with one part of a permutation key, without a position: `within` gives it the position of
    that part in whatever asked for the permutation."""

    def __init__(self, part: str, message: str, hint: str = ""):
        self.part, self.message, self.hint = part, message, hint
        super().__init__(f"{message} — {hint}" if hint else message)


def key_where(key: str, part: str) -> Where:
    """The column of `part` in a canonical key's text (its `part=` field; a light's in `lights=`), for keys no
    scene asked for."""
    field = "lights" if part.startswith("light") else "surface" if part in _SURFACE else part
    at = key.find(f"{field}=") if field != "surface" else key.find(f";{part}=") + 1
    return Where(f"permutation key '{key}'", 1, at + 1 if at >= 0 else 1)


_SURFACE = ("alpha", "double_sided", "vertex_color", "emissive")


@contextmanager
def within(origin: Origin | Where | None, key: str = ""):
    """Locate the KeyProblems raised inside at the part of `origin` they name (at `key`'s own text without one)."""
    try:
        yield
    except KeyProblem as e:
        if isinstance(origin, Where):
            where = origin
        elif origin is not None:
            where = origin.at(e.part)
        else:
            where = key_where(key, e.part)
        raise where.error(e.message, e.hint) from None
