"""GLSL's templates (templates/*.glsl.j2), its part of the template context, and its front end."""
from __future__ import annotations

from ..front_end import FrontEnd
from ..language import Language
from .emit import GlslHalfTarget, GlslTarget

# glslc's GLSL front end. The sentinel has a #version: without one glslang reports that as well, a second message
# that the batch's split would give to the file before it.
FRONT_END = FrontEnd("glslc", flags=("-x", "glsl"), sentinel="#version 450\n#error {message}\n")

LANGUAGE = Language("glsl", __package__, "glsl", imports=("glsl/macros.glsl.j2",), spelling="glsl",
                    full=GlslTarget(), half=GlslHalfTarget(), material_index="draw.material.x", front_end=FRONT_END)
