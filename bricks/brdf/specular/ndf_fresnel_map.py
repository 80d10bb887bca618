"""NDF + Fresnel texture: f_r = R_F(0) K T(θ_h, α_h), T painted over θ_h × α_h (Hoffman & Baker 2006).

Hoffman & Baker 2006, slide "NDF + Fresnel Texture": "a 2D texture mapped by θ_h on one axis and α_h
on the other allows hand-painting both arbitrary 1D NDFs and Fresnel functions, as well as
interactions between the two. Texture still needs to be processed for normalization." θ_h is the
angle between h and n, α_h the angle between h and l (= v), as the notes define them.

Normalization (generator/reference/tables_painted.py, table `ndf_fresnel_map`): the row α_h = 0
(normal incidence) is the NDF, K = 1/(4 ∫ T(θ_h, 0) cos θ_h dω_h) as `ndf_map`'s K_N, so at α_h = 0 this
is `ndf_map` exactly, f = R_F(0) D/4; the other rows paint R_F(α_h)/R_F(0) and how the lobe changes with
α_h (their brightness relative to row 0). The table holds K T (fp16, HDR). Reciprocal: θ_h and
α_h are symmetric in l and v. Energy: bounded by R_F(0) times the brightest row's gain, which the
artist paints (the notes: Fresnel on a normalized lobe is "no longer energy conserving" anyway).

Table: 64 × 32 fp16, the painting's own axes and size: x: u = √(1 − cos θ_h) (from NxH2, as
`ndf_map`), y: 1 − cos α_h = 1 − l·h (row 0: normal incidence; fine steps in angle at grazing, where
Fresnel changes). The reference is the continuous painting (bilinear on those axes;
bricks/brdf/painted/ndf_fresnel_map.png) normalized in float64, so the table adds fp16 rounding and the
filter's precision, which `tolerance` covers (measured: 6.6e-4 hemisphere max relative error in NumPy,
GLSL, HLSL and WGSL on lavapipe, float32).
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, NDF + Fresnel texture; Walter et al. 2007 eq. 4 (normalization)",
    "params": {
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_F(0), Fresnel reflectance at normal incidence (scales the painted table)"},
    },
    "textures": {"ndf_fresnel_tex": {"table": "ndf_fresnel_map", "size": [64, 32], "format": "fp16",
                                     "doc": "K T(θ_h, α_h) at u = √(1 − n·h), v = 1 − l·h"}},
    "tolerance": 0.002,
    "needs": ["NdotH", "NxH2", "LdotH"],
}


def specular(NdotH: float, NxH2: float, LdotH: float, f0: vec3, ndf_fresnel_tex: texture2d) -> vec3:
    u = sqrt(NxH2 / (1.0 + NdotH))
    # texel centres: x (W - 1)/W + 0.5/W for W = 64 (u) and H = 32 (1 - l.h)
    uv = vec2(u * 0.984375 + 0.0078125, (1.0 - LdotH) * 0.96875 + 0.015625)
    k = sample_level(ndf_fresnel_tex, uv, 0.0).xyz
    return f0 * k
