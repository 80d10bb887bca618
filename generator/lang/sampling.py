"""The sampling intrinsics' typing (sample, sample_level, sample_compare) on every texture type, and the one
builder of their IR, which the checker and the link stage share.

Argument order, the same in the brick language, the IR and every target's spelling: the texture, its
coordinate (vec2 uv; vec3 direction for cubes), for an array its layer (int or uint), then sample_level's
lod or sample_compare's depth reference. A layer is an integer on purpose: WGSL takes an integer index,
GLSL and HLSL a float coordinate that Vulkan rounds to nearest even, so an integer converted exactly
(|layer| < 2^24) reads the same layer in every target with no rounding rule to agree on; every target then
clamps it to [0, L-1] (Vulkan's clamp of the rounded layer, WGSL's of the index, the NumPy target's own).
"""
from __future__ import annotations

from . import ir
from .types import FLOAT, INT, UINT, Type, vector

SAMPLING_SIGS = ("sample", "sample_lod", "sample_compare")  # the typing rules of the intrinsics that read a texture
_SIG = {"sample": "sample", "sample_level": "sample_lod", "sample_compare": "sample_compare"}
LAYER_TYPES = (INT, UINT)
_FORMS = {
    "sample": "(texture2d, vec2), (texturecube, vec3), (texture2d_array, vec2, int layer) or "
              "(texturecube_array, vec3, int layer)",
    "sample_lod": "(texture2d, vec2, float lod), (texturecube, vec3, float lod), (texture2d_array, vec2, int "
                  "layer, float lod) or (texturecube_array, vec3, int layer, float lod)",
    "sample_compare": "(texture2d_shadow, vec2 uv, float depth_ref) or (texture2d_array_shadow, vec2 uv, int "
                      "layer, float depth_ref)",
}


class SamplingError(ValueError):
    """A sampling call that is not defined: what is wrong, and what to do."""

    def __init__(self, message: str, hint: str):
        self.message, self.hint = message, hint
        super().__init__(f"{message} — {hint}")


def expected_args(sig: str, tex: Type) -> list[Type] | None:
    """The argument types after texture `tex` that typing rule `sig` takes (a layer: INT, which a UINT also
    satisfies), or None when the rule does not read that texture."""
    if tex.kind != "texture" or (sig == "sample_compare") != tex.compare:
        return None
    coord = vector("float", 3 if tex.dim.startswith("cube") else 2)
    return [coord] + ([INT] if tex.arrayed else []) + ([FLOAT] if sig in ("sample_lod", "sample_compare") else [])


def result_type(name: str, types: list[Type]) -> Type:
    """The result of intrinsic `name` (sample, sample_level, sample_compare) on arguments of `types`;
    SamplingError when that call is not defined."""
    sig = _SIG[name]
    tex = types[0] if types else None
    if tex is not None and tex.compare and sig != "sample_compare":
        raise SamplingError(f"{name}() cannot read a {tex}: a depth texture is read through its comparison "
                            "sampler", "call sample_compare(shadow_tex, uv, depth_ref) (an array: "
                            "sample_compare(shadow_tex, uv, layer, depth_ref)), which returns the filtered "
                            "compare result")
    want = expected_args(sig, tex) if tex is not None else None
    got = types[1:]
    if want is not None and len(got) == len(want):
        if tex.arrayed and got[1].kind == "scalar" and got[1].scalar == "float":
            raise SamplingError(f"the layer of a {tex} is an int or uint, not a float",
                                "pass int(floor(x + 0.5)) to round a float (a layer is an index: every target "
                                "then clamps it to [0, layers - 1])")
        layer_ok = not tex.arrayed or got[1] in LAYER_TYPES
        rest = [t for i, t in enumerate(got) if not (tex.arrayed and i == 1)]
        if layer_ok and rest == [t for i, t in enumerate(want) if not (tex.arrayed and i == 1)]:
            return FLOAT if sig == "sample_compare" else vector("float", 4)
    raise SamplingError(f"{name}({', '.join(map(str, types))}) is not defined", f"{name} takes {_FORMS[sig]}")


def sample_call(name: str, loc: ir.Loc, tex: ir.Expr, coord: ir.Expr, *rest: ir.Expr,
                layer: ir.Expr | None = None) -> ir.Intrinsic:
    """The IR of `name(tex, coord[, layer][, lod or ref])`, typed as the checker types it (SamplingError when
    not defined). `rest` is sample_level's lod or sample_compare's reference; `layer` goes after the
    coordinate for a texture array. The link stage builds the sample of an arrayed shadow map this way:
    sample_call("sample_compare", loc, ir.Var(texture2d_array_shadow, loc, name, "param"), uv, ref,
    layer=light_layer)."""
    args = [tex, coord] + ([layer] if layer is not None else []) + list(rest)
    return ir.Intrinsic(result_type(name, [a.ty for a in args]), loc, name, args)


def with_layer(call: ir.Intrinsic, tex: ir.Expr, layer: ir.Expr) -> ir.Intrinsic:
    """A sampling call of a single texture rewritten to read `layer` of `tex`, an array of that texture's
    type (types.arrayed_texture): what retyping a brick's texture2d_shadow parameter into a
    texture2d_array_shadow asks of each of its sample calls."""
    assert call.name in _SIG and not call.args[0].ty.arrayed, call
    return sample_call(call.name, call.loc, tex, call.args[1], *call.args[2:], layer=layer)
