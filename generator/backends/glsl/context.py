"""GLSL's templates (templates/*.glsl.j2) and its part of the template context."""
from __future__ import annotations

from ..language import Language
from .emit import GlslHalfTarget, GlslTarget

LANGUAGE = Language("glsl", __package__, "glsl", imports=("glsl/macros.glsl.j2",), spelling="glsl",
                    full=GlslTarget(), half=GlslHalfTarget(), material_index="draw.material.x")
