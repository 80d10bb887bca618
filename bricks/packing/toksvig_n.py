"""Toksvig's exponent for a MIP-mapped normal map, n' = f_t n, and the course's per-MIP reduction as an option.

Hoffman & Baker 2006, "Texture Filtering Review" to "Better Hack: Level of Detail": a MIP level
averages normals, and Blinn-Phong of the averaged normal is not the average of Blinn-Phong,
Σ_r W_r (N_r·H)^n ≠ (H·Σ_r W_r N_r)^n: minified, a normal-mapped highlight turns too narrow and
too bright, and shimmers. Toksvig 2005, "Mipmapping Normal Maps" (JGT 10(3)), keeps the filtered
normal N_a unnormalized: its length measures the spread of the normals it averages, σ² =
(1 − |N_a|)/|N_a| (|N_a| ≈ 1/(1 + σ²) for a Gaussian spread), and the exponent becomes

    n' = f_t n,   f_t = |N_a| / (|N_a| + n (1 − |N_a|))   ⇔   1/n' = 1/n + σ²,

computed here in the variance form n' = n / (1 + n w σ²), w = `toksvig_weight` (1: Toksvig's; 0: off).
The hardware's implicit LOD picks the MIP level, so Toksvig needs no LOD estimate.

The course's heuristic, "decreasing the n parameter by about 30% for each MIP level" (n = 32, 24,
18, 12, 7), is the option `mip_reduction` r (0 = off; 0.3 the course's): n_lod = n (1 − r)^lod,
applied before Toksvig's variance. It needs the MIP level, and the brick language has no
screen-space derivatives or LOD query (generator/lang/intrinsics.py; WGSL has no textureQueryLod
either, and eval kernels are compute shaders, without implicit derivatives), so `lod` is an explicit
material parameter: the engine sets it per draw from the object's distance, as games apply the
course's LOD hack per object. With both on, the reduction stacks on Toksvig's (tests/library/test_lod.py
measures each alone: the course's alone is toksvig_weight = 0, mip_reduction = 0.3).

Texture `normal_map`, linear RGB = (t + 1)/2, the one binding the normal slot's default filler
`normal_map` samples too (it normalizes N_a for the shading normal). The length needs all three
channels: `normal_map_xy` reconstructs z and loses it. Box-filtered MIP levels of unit normals
keep |N_a| ≤ 1, but 8-bit texels are not unit: rounding each channel to 1/255 (t to 2/255) gives
base-level lengths 1 ± 0.0054 (measured on tests/library/test_lod.py's bumpy map), and at n = 256 the
shortened ones lower n' to 108 at worst, 220 on average, on a level that should keep 256: store
the map with 16 bits per channel (R16G16B16A16_UNORM), or accept a gloss ceiling of that order.

Provides n, for BRDFs reading the Blinn-Phong exponent (blinn_phong_normalized, lambert+…).
Float64 reference: generator/reference/lod.py (lod_exponent); the energy experiment across MIP
levels: tests/library/test_lod.py.
"""
BRICK = {
    "kind": "packing",
    "fp16": "unsafe: half resolves 1 - |Na| in steps of 2^-11 near 1 (a unit texel shades n = 256 as about 227), and n_lod * sigma^2 overflows 65504 for normals that cancel (n' = 0)",
    "cite": "Toksvig 2005, Mipmapping Normal Maps (JGT 10(3)): n' = |Na| n / (|Na| + n (1 - |Na|)); Hoffman & Baker 2006, Level of Detail: n about 30 % lower per MIP level",
    "params": {
        "mip_reduction": {"type": "float", "range": [0.0, 0.9], "default": 0.0, "doc": "exponent reduction per MIP level, n (1 - r)^lod (0: off; the course's 0.3); below 1 so that (1 - r)^lod > 0"},
        "lod": {"type": "float", "range": [0.0, 16.0], "default": 0.0, "doc": "the MIP level the reduction assumes (explicit: no LOD query in the brick language); 16 levels: a 65536² map"},
        "toksvig_weight": {"type": "float", "range": [0.0, 1.0], "default": 1.0, "doc": "scale of Toksvig's variance (1: Toksvig 2005; 0: off, the course's reduction alone)"},
    },
    "textures": {"normal_map": {"srgb": False, "holds": "normal", "keep_length": True,
                                "doc": "linear RGB: tangent-space normal as (t + 1) / 2, MIP-mapped with a box filter, not renormalized"}},
    "slots": {"normal": {"kind": "normal", "default": "normal_map"}},
}

# |N_a| is clamped to [1e-4, 1]. Above 1: 8-bit quantization and bilinear weights give texels of unit
# normals slightly longer; σ² < 0 would sharpen the lobe, and for n > 1/|σ²| flip n' negative. At 1e-4:
# normals that cancel out (|N_a| = 0) give σ² = 1e4 instead of 1/0, n' ≈ 1e-4 > 0 (pow(0, 0) is undefined).
NA_MIN = 0.0001


def normal_variance(uv: vec2, normal_map: texture2d) -> float:
    t = sample(normal_map, uv).xyz * 2.0 - vec3(1.0)
    na = clamp(length(t), NA_MIN, 1.0)
    return (1.0 - na) / na


def get_n(uv: vec2, normal_map: texture2d, n: float, mip_reduction: float, lod: float, toksvig_weight: float) -> float:
    n_lod = n * pow(1.0 - mip_reduction, lod)
    return n_lod / (1.0 + n_lod * toksvig_weight * normal_variance(uv, normal_map))
