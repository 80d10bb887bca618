"""WGSL's templates (templates/*.wgsl.j2) and its part of the template context."""
from __future__ import annotations

from ..language import Language
from .emit import WgslHalfTarget, WgslTarget

LANGUAGE = Language("wgsl", __package__, "wgsl", imports=("wgsl/macros.wgsl.j2",), spelling="wgsl",
                    full=WgslTarget(), half=WgslHalfTarget(), material_index="draw.material.x")
