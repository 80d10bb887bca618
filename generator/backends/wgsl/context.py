"""WGSL's templates (templates/*.wgsl.j2), its part of the template context, and its front end."""
from __future__ import annotations

from ..front_end import FrontEnd
from ..language import Language
from .emit import WgslHalfTarget, WgslTarget

# naga, without its y flip: the templates' matrices place vertices alike in every language.
FRONT_END = FrontEnd("naga", flags=("--keep-coordinate-space",))

LANGUAGE = Language("wgsl", __package__, "wgsl", imports=("wgsl/macros.wgsl.j2",), spelling="wgsl",
                    full=WgslTarget(), half=WgslHalfTarget(), material_index="draw.material.x", front_end=FRONT_END)
