"""HLSL's templates (templates/*.hlsl.j2) and its part of the template context."""
from __future__ import annotations

from ..language import Language
from .emit import HlslHalfTarget, HlslTarget

# The ubershader's Draw block is a cbuffer: its member is a global (templates/ubershader.hlsl.j2).
LANGUAGE = Language("hlsl", __package__, "hlsl", imports=("hlsl/macros.hlsl.j2",), spelling="hlsl",
                    full=HlslTarget(), half=HlslHalfTarget(), material_index="draw_material.x")
