"""The ubershader's surface state (link/uber.py): a material's alpha mode (MaterialEntry.ids.y) and the coverage a
masked or blended variant returns as alpha, and its emission (ids.z) added to the radiance, computed as the
specialized glue does (link/glue.py coverage, coverage_alpha, emission), with the values read from the entry
instead of the Material block."""
from __future__ import annotations

from ..lang import ir
from ..lang.types import FLOAT, INT, VEC3, VEC4, Type, vector
from ..library.inputs import SURFACE
from ..spec.surface import EMISSIVE_MAP
from .glue import UV_LOCAL, _Binder, _sample, coverage_texture, read_slot
from .interface import Slot
from .irgen import Builder

IVEC4 = vector("int", 4)
ALPHA_IDS = {"opaque": 0, "mask": 1, "blend": 2}  # MaterialEntry.ids.y: the material's alpha mode
EMISSIVE_IDS = {"none": 0, "factor": 1, "texture": 2}  # MaterialEntry.ids.z: the material's emission
ALPHA_MODE_FUNCTION = "surface_alpha_mode"  # int (int material): ids.y of its entry, for the fragment main


def surface_alpha(b: Builder, bind: _Binder, me: ir.Expr, mat_data: Type, at: int, packing, filtered_uv: bool
                   ) -> list[ir.Stmt]:
    """`if (me.ids.y != 0) color.a = coverage or 1 / 0 against the cutoff`: the specialized glue's surface_output
    (link/glue.py coverage, coverage_alpha) with base_alpha and alpha_cutoff read from data[at] (x, y). The base
    colour texture is sampled at uv_t where the variant's packing has a uv filler (what its other samples read)."""
    mode = ir.Swizzle(INT, b.here(), ir.Member(IVEC4, b.here(), b.copy(me), "ids"), "y")
    cov = read_slot(b, me, mat_data, Slot("m_base_alpha", "base_alpha", FLOAT, at, component=0))
    cutoff = read_slot(b, me, mat_data, Slot("m_alpha_cutoff", "alpha_cutoff", FLOAT, at, component=1))
    tex = coverage_texture(packing)
    if tex:
        bind.uv = b.var(UV_LOCAL, SURFACE["uv"]) if filtered_uv else None
        cov = b.arith("*", cov, ir.Swizzle(FLOAT, b.here(), _sample(b, bind, f"t_{tex}", tex, True), "w"))
        bind.uv = None
    masked = ir.Select(FLOAT, b.here(), b.compare(">=", b.var("coverage", FLOAT), cutoff), b.const(1.0), b.const(0.0))
    alpha = ir.Select(FLOAT, b.here(), b.compare("==", b.copy(mode), ir.Const(INT, b.here(), ALPHA_IDS["mask"])),
                      masked, b.var("coverage", FLOAT))
    rgb = ir.Swizzle(VEC3, b.here(), b.var("color", VEC4), "xyz")
    return [b.if_(b.compare("!=", mode, ir.Const(INT, b.here(), ALPHA_IDS["opaque"])),
                  [b.decl("coverage", cov), b.assign(b.var("color", VEC4), b.construct(VEC4, rgb, alpha))])]


def emission(b: Builder, bind: _Binder, me: ir.Expr, mat_data: Type, at: int, textured: bool, filtered_uv: bool
             ) -> list[ir.Stmt]:
    """`if (me.ids.z != 0) Lo += data[at].xyz [· sample(t_emissive_map, uv).rgb where ids.z says texture]`: the
    specialized glue's emission (glTF emissiveFactor · emissiveTexture), at uv_t where a variant has a uv filler
    (uv_t then holds each variant's own coordinates: its case set it)."""
    mode = ir.Swizzle(INT, b.here(), ir.Member(IVEC4, b.here(), b.copy(me), "ids"), "z")
    e = read_slot(b, me, mat_data, Slot("m_emissive", "emissive", VEC3, at))
    body = [b.decl("emitted", e)]
    if textured:
        bind.uv = b.var(UV_LOCAL, SURFACE["uv"]) if filtered_uv else None
        rgb = ir.Swizzle(VEC3, b.here(), _sample(b, bind, f"t_{EMISSIVE_MAP}", EMISSIVE_MAP, True), "xyz")
        bind.uv = None
        body.append(b.if_(b.compare("==", b.copy(mode), ir.Const(INT, b.here(), EMISSIVE_IDS["texture"])),
                          [b.assign(b.var("emitted", VEC3), b.arith("*", b.var("emitted", VEC3), rgb))]))
    body.append(b.assign(b.var("Lo", VEC3), b.var("emitted", VEC3), "+"))
    return [b.if_(b.compare("!=", mode, ir.Const(INT, b.here(), EMISSIVE_IDS["none"])), body)]
