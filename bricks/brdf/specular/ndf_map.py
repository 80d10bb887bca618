"""NDF map (isotropic): f_r = K_N R_F(0) p(θ_h), p painted as a 1D texture (Hoffman & Baker 2006).

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", slides "NDF Maps":
f_r(ω_i, ω_e) = ρ_d/π + K_N R_F(0) p(ω_h) — "a generalization of Blinn-Phong to a general NDF";
"for isotropic BRDFs, NDF map is one-dimensional: p(θ_h)"; "K_N computed automatically in tools".
This brick is the specular term; pair it with a diffuse term (`lambert`) for the whole BRDF.

The generator bakes K_N p(θ_h) (generator/reference/tables_painted.py, table `ndf_map`): the painted
profile (the shipped example bricks/brdf/painted/ndf_map.png, or an engine's own image through
tables_painted.bake_painted) scaled to D/4 with ∫ D cos θ_h dω_h = 1 — the microfacet normalization
with the implicit visibility G = n·l n·v, so f = D R_F(0) / 4: reciprocal (a function of h only) and,
measured, directional albedo ≤ R_F(0) (tests/library/test_painted.py). fp16: NDFs are HDR, and K_N p needs no
constant in the shader. A coloured map is one NDF per channel, each normalized.

Table: 64 × 1 fp16, the painting's own axis and size: u = √(1 − cos θ_h) (the profile is painted over
u), computed as √(sin²θ_h / (1 + cos θ_h)) from NxH2 (no cancellation at the peak, where 1 − n·h is
rounding in float32); u ≈ θ_h/√2 near the peak, so the texels spread evenly in angle without an acos.
The reference is the continuous painting (the image linearly interpolated over u) normalized in
float64, so the table adds fp16 rounding and the filter's precision, which `tolerance` covers:
measured 1.4e-3 hemisphere max relative error in NumPy, GLSL, HLSL and WGSL on lavapipe (float32).
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, NDF maps (f_r = ρ_d/π + K_N R_F(0) p(ω_h)); Walter et al. 2007 eq. 4 (normalization)",
    "params": {
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_F(0), Fresnel reflectance at normal incidence"},
    },
    "textures": {"ndf_tex": {"table": "ndf_map", "size": [64, 1], "format": "fp16",
                             "doc": "K_N p(θ_h) = D/4 at u = √(1 − n·h)"}},
    "tolerance": 0.005,
    "needs": ["NdotH", "NxH2"],
}


def specular(NdotH: float, NxH2: float, f0: vec3, ndf_tex: texture2d) -> vec3:
    # u = sqrt(1 - cos θ_h) without cancellation; NxH2 = 1, NdotH = 0 past the horizon: u = 1 (θ_h = 90°)
    u = sqrt(NxH2 / (1.0 + NdotH))
    # table texel centres: u (W - 1)/W + 0.5/W for W = 64
    k = sample_level(ndf_tex, vec2(u * 0.984375 + 0.0078125, 0.5), 0.0).xyz
    return f0 * k
