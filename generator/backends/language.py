"""What composition needs of a back end besides its emitter: where its templates are, which template renders
each shader, and the language's part of the template context.

One Language per shading language (glsl/, hlsl/, wgsl/: each package's context.py) and one per platform
dialect (gl/context.py: "gl", "essl"); the registry (generator.backends) collects them. compose/ renders the
templates with the language-neutral context (interface, slots, provenance) plus Language.context().
"""
from __future__ import annotations

from dataclasses import dataclass

from ..lang.types import BUILTIN_TYPES
from .base import Target
from .front_end import FrontEnd


@dataclass(frozen=True, eq=False)
class Language:
    name: str  # "glsl"; names the generated sources ("<hash>.frag.glsl")
    package: str  # the package whose templates/ folder holds the templates
    folder: str  # the prefix of the templates' names ("glsl/fragment.glsl.j2")
    imports: tuple[str, ...]  # the templates the skeletons import: provenance and cache keys name them too
    spelling: str  # the language whose fp32 target spells built-in types in the templates (spell())
    full: Target | None = None  # the emitters at fp32 and fp16 (a dialect makes one per interface: target())
    half: Target | None = None
    # The ubershader fragment's expression for the draw's material variant (its template's Draw block).
    material_index: str = ""
    # How its text becomes SPIR-V (front_end.py); None for a platform dialect, which is validated, not compiled.
    front_end: FrontEnd | None = None

    def template(self, kind: str) -> str:
        """The template rendering `kind`: "vertex", "fragment", "ubershader", "eval" or "shade"."""
        return f"{self.folder}/{kind}.{self.folder}.j2"

    def target(self, precision: str = "fp32", iface=None) -> Target:
        """The emitter for sources at `precision` (a dialect binds `iface`'s resources its own way)."""
        from . import get_target
        return get_target(self.name, precision)

    def context(self) -> dict:
        """This language's part of a skeleton's context: spell(NAME), the spelling of built-in type NAME."""
        from . import get_target
        spelling = get_target(self.spelling)
        return {"spell": lambda name: spelling.type_name(BUILTIN_TYPES[name])}
