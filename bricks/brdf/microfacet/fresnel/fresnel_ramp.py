"""Fresnel ramp: R_F(α_h) read from a baked ramp per f0 (Hoffman & Baker 2006, "Fresnel Ramps").

Hoffman & Baker 2006: "R_F(α_h) can be stored in a 1D texture or ramp — computed from material
properties, or painted by an artist to achieve interesting visual effects — can be combined with many
BRDF models". A ramp computed from material properties depends on the material, and here f0 is a
shading parameter, so the table is a stack of 1D ramps, one per f0: x = 1 − cos α_h = 1 − v·h, y = √f0
(generator/reference/tables_painted.py, table `fresnel_ramp`), and each channel reads the ramp of its
own f0 (three taps; the red tap returns red, and so on). Computed (no image): the exact unpolarized
dielectric Fresnel at η = (1 + √f0)/(1 − √f0) (Cook & Torrance 1982; what `dielectric_exact`
computes in ALU), the reference it is measured against. An engine's painted ramp (tables_painted.
bake_painted; example: bricks/brdf/painted/fresnel_ramp.png, gold's exact conductor Fresnel) replaces
it: a one-row ramp is the same for every f0, its RGB R_F directly.

Table: 64 × 32 fp16. √f0 spends the rows on the dielectrics' small f0; the error the table adds to the
exact Fresnel is largest at grazing v·h for f0 → 0, where F climbs from f0 to 1 within a few texels,
and is what `tolerance` covers: measured in the microfacet host (GGX, Smith) 4.5e-3 hemisphere max
relative error in NumPy, GLSL, HLSL and WGSL on lavapipe (float32), 4.6e-3 on the stress set.
"""
BRICK = {
    "kind": "fresnel",
    "cite": "Hoffman & Baker 2006, Fresnel ramps; Cook & Torrance 1982 (exact dielectric Fresnel)",
    "textures": {"fresnel_tex": {"table": "fresnel_ramp", "size": [64, 32], "format": "fp16",
                                 "doc": "R_F at x = 1 − cos α_h, y = √f0"}},
    "tolerance": 0.01,
}


def fresnel(f0: vec3, VdotH: float, fresnel_tex: texture2d) -> vec3:
    # texel centres: x (W - 1)/W + 0.5/W for W = 64 (1 - v.h) and H = 32 (sqrt f0)
    u = clamp(1.0 - VdotH, 0.0, 1.0) * 0.984375 + 0.0078125
    s = sqrt(clamp(f0, 0.0, 1.0)) * 0.96875 + vec3(0.015625)
    r = sample_level(fresnel_tex, vec2(u, s.x), 0.0).x
    g = sample_level(fresnel_tex, vec2(u, s.y), 0.0).y
    b = sample_level(fresnel_tex, vec2(u, s.z), 0.0).z
    return vec3(r, g, b)
