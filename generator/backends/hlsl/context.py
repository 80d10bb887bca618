"""HLSL's templates (templates/*.hlsl.j2), its part of the template context, and its front end."""
from __future__ import annotations

from ..front_end import FrontEnd
from ..language import Language
from .emit import HlslHalfTarget, HlslTarget

# glslc's HLSL front end. -fhlsl-16bit-types: `half` is a real 16-bit float (DXC's -enable-16bit-types), what the
# fp16 target emits (emit.py HlslHalfTarget); fp32 HLSL never spells half, so its SPIR-V does not depend on it.
FRONT_END = FrontEnd("glslc", flags=("-x", "hlsl"), process_flags=("-fhlsl-16bit-types",),
                     sentinel="#error {message}\n")

# The ubershader's Draw block is a cbuffer: its member is a global (templates/ubershader.hlsl.j2).
LANGUAGE = Language("hlsl", __package__, "hlsl", imports=("hlsl/macros.hlsl.j2",), spelling="hlsl",
                    full=HlslTarget(), half=HlslHalfTarget(), material_index="draw_material.x", front_end=FRONT_END)
