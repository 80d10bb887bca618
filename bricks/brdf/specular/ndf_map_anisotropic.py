"""NDF map (anisotropic): f_r = K_N R_F(0) p(ω_h), p painted over the tangent-plane projection of h.

Hoffman & Baker 2006, slides "NDF Maps": the NDF "can be painted into a 2D texture"; "being able to
effectively paint the highlight gives the artist full control over surface smoothness and anisotropy".
The 2D parameterization chosen here is the orthographic view of the hemisphere of normals from above:
x = h·t, y = h·b in [−1, 1] (the painted image is what the highlight's facets look like seen along n),
read with no trigonometry (φ_h would cost an atan2). Its area element dx dy = cos θ_h dω_h makes the
microfacet normalization ∫ D cos θ_h dω_h = ∫∫_disk D dx dy = 1 a plain area integral, which the
generator computes from the painting (generator/reference/tables_painted.py, table
`ndf_map_anisotropic`); the table holds K_N p = D/4 (implicit visibility G = n·l n·v, as `ndf_map`),
fp16. Reciprocal: a function of h only.

Table: 64 × 64 fp16 over (h·t, h·b), the shipped example's own grid (bricks/brdf/painted/
ndf_map_anisotropic.png): the baked texels are the painting's pixels times K_N, so the table adds only
fp16 rounding and the filter's precision to the continuous (bilinearly interpolated) painting that
the reference evaluates. Texels outside the unit disk keep the painted values (the filter sees a
continuous function at the rim) and carry no weight in the normalization. Measured: 6.7e-4 hemisphere
max relative error in NumPy, GLSL, HLSL and WGSL on lavapipe (float32); `tolerance` 2e-3.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, NDF maps (2D, anisotropic); Walter et al. 2007 eq. 4 (normalization)",
    "params": {
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_F(0), Fresnel reflectance at normal incidence"},
    },
    "textures": {"ndf_aniso_tex": {"table": "ndf_map_anisotropic", "size": [64, 64], "format": "fp16",
                             "doc": "K_N p = D/4 over (h·t, h·b) ∈ [−1, 1]²"}},
    "tolerance": 0.002,
    "needs": ["HdotT", "HdotB"],
}


def specular(HdotT: float, HdotB: float, f0: vec3, ndf_aniso_tex: texture2d) -> vec3:
    # (h.t, h.b) in [-1, 1] to [0, 1], then to texel centres: x (W - 1)/W + 0.5/W for W = H = 64
    uv = vec2(HdotT, HdotB) * 0.4921875 + vec2(0.5)
    k = sample_level(ndf_aniso_tex, uv, 0.0).xyz
    return f0 * k
