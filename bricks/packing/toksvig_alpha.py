"""Toksvig's variance added to a microfacet roughness, α'² = α² + 2σ², and the course's per-MIP reduction as an option.

The microfacet form of `toksvig_n` (its docstring: Hoffman & Baker 2006, "Texture Filtering
Review" to "Better Hack: Level of Detail"; Toksvig 2005, "Mipmapping Normal Maps", JGT 10(3)).
The box-filtered normal N_a of a MIP level is kept unnormalized; its length gives the spread of
the normals it averages, σ² = (1 − |N_a|)/|N_a|. Toksvig's 1/n' = 1/n + σ² for Blinn-Phong, with
Walter et al. 2007 eq. 30 (n = 2/α² − 2, so α² ≈ 2/n; Beckmann's per-axis slope variance is α²/2,
as LEAN mapping, Olano & Baker 2010, and the "roughness² += 2 variance" of Kaplanyan et al. 2016
use), is

    α'² = α_lod² + 2 w σ²,    w = `toksvig_weight` (1: Toksvig's; 0: off).

The 2 is measured, not assumed: tests/library/test_lod.py finds the GGX highlight's error at MIP levels 3–6
1.5–2.1 times larger with α² + σ² (a form also quoted). GGX is not Gaussian (heavier tails), so
the variance sum is an approximation for it; the test's bound is measured on GGX.

The course's reduction, "decreasing the n parameter by about 30% for each MIP level", goes through
the same eq. 30: n_lod = (2/α² − 2)(1 − r)^lod, α_lod² = 2/(n_lod + 2), written without a division
by α: α_lod² = α² / (α² + (1 − r)^lod (1 − α²)), so α = 0 gives 0 and α = 1 stays 1. `mip_reduction`
r (0 = off) and the explicit `lod` are as in `toksvig_n` (no LOD query in the brick language: `lod`
is set per draw).

Texture `normal_map`, linear RGB = (t + 1)/2, shared with the normal slot's default `normal_map`
filler (one binding). Provides alpha, for the microfacet BRDFs (microfacet(ndf=…), lambert+…):
GGX, Beckmann and the Blinn-Phong NDF read the same α. Float64 reference:
generator/reference/lod.py (lod_alpha).
"""
BRICK = {
    "kind": "packing",
    "fp16": "unsafe: half resolves 1 - |Na| in steps of 2^-11 near 1 (a unit texel widens alpha = 0.05 to about 0.06), and (1 - r)^lod leaves half's normal range below 6.1e-5 (r = 0.9 from lod 5) and may flush to 0: 0/0 at alpha = 0",
    "cite": "Toksvig 2005, Mipmapping Normal Maps (JGT 10(3)), as variance: alpha'^2 = alpha^2 + 2 (1 - |Na|) / |Na| (Walter et al. 2007 eq. 30); Hoffman & Baker 2006, Level of Detail (30 % per MIP level)",
    "params": {
        "mip_reduction": {"type": "float", "range": [0.0, 0.9], "default": 0.0, "doc": "exponent reduction per MIP level through n = 2/alpha^2 - 2 (0: off; the course's 0.3); below 1 so that (1 - r)^lod > 0"},
        "lod": {"type": "float", "range": [0.0, 16.0], "default": 0.0, "doc": "the MIP level the reduction assumes (explicit: no LOD query in the brick language); 16 levels: a 65536² map"},
        "toksvig_weight": {"type": "float", "range": [0.0, 1.0], "default": 1.0, "doc": "scale of Toksvig's variance (1: Toksvig 2005; 0: off, the course's reduction alone)"},
    },
    "textures": {"normal_map": {"srgb": False, "holds": "normal", "keep_length": True,
                                "doc": "linear RGB: tangent-space normal as (t + 1) / 2, MIP-mapped with a box filter, not renormalized"}},
    "slots": {"normal": {"kind": "normal", "default": "normal_map"}},
}

# |N_a| is clamped to [1e-4, 1] as in toksvig_n: quantization can lengthen a texel past 1 (σ² < 0 would
# sharpen the lobe), and normals that cancel (|N_a| = 0) give σ² = 1e4 instead of 1/0.
NA_MIN = 0.0001
# α'² is capped at 1, the top of α's range: beyond it the blinn_phong NDF filler's n = 2/α² − 2 turns
# negative (its lobe grows toward the horizon). Cost: footprints whose spread exceeds α' = 1 (σ² > 0.5 − α²/2,
# |N_a| < 0.67 at α = 0) shade with α = 1, already a nearly flat lobe.
ALPHA2_MAX = 1.0


def normal_variance(uv: vec2, normal_map: texture2d) -> float:
    t = sample(normal_map, uv).xyz * 2.0 - vec3(1.0)
    na = clamp(length(t), NA_MIN, 1.0)
    return (1.0 - na) / na


def get_alpha(uv: vec2, normal_map: texture2d, alpha: float, mip_reduction: float, lod: float,
              toksvig_weight: float) -> float:
    a2 = alpha * alpha
    a2_lod = a2 / (a2 + pow(1.0 - mip_reduction, lod) * (1.0 - a2))
    return sqrt(min(a2_lod + 2.0 * toksvig_weight * normal_variance(uv, normal_map), ALPHA2_MAX))
