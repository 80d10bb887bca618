"""The one interface every target emitter implements."""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

from ..lang import ir
from ..lang.types import Type


@dataclass
class Emitted:
    """Emitted source text plus a map from its lines back to brick lines.

    line_map: [(line in `text`, 1-based; brick path; brick line)], sorted by
    the first element; a line maps to the closest entry at or above it.
    """

    text: str
    line_map: list[tuple[int, str, int]] = field(default_factory=list)

    def shifted(self, offset: int) -> list[tuple[int, str, int]]:
        """The line map for this text placed `offset` lines into a larger file."""
        return [(line + offset, path, src) for line, path, src in self.line_map]


class Target(ABC):
    """A language back end: type names, identifiers, structs and functions from IR."""

    name: str  # "glsl" | "hlsl" | "wgsl" | "numpy"
    ext: str  # file extension of emitted sources ("glsl", "hlsl", "wgsl", "py")
    reserved: frozenset[str] = frozenset()

    def ident(self, name: str) -> str:
        """A brick identifier as spelled in this target (reserved words get the prefix '_r_')."""
        return "_r_" + name if name in self.reserved else name

    @abstractmethod
    def type_name(self, t: Type) -> str:
        """The spelling of a brick-language type (struct names pass through ident())."""

    @abstractmethod
    def emit(self, structs: list[Type], functions: list[ir.Function], globals: list[ir.Global] = ()) -> Emitted:
        """Struct declarations, then global resources (buffers, textures; C-like targets
        declare them, the NumPy target receives them at load()), then functions, callees
        before callers (the caller orders them)."""
