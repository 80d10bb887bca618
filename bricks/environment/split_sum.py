"""Image-based lighting by the split sum: SH9 irradiance for the diffuse term, a prefiltered radiance cube times
the AmbientBRDF table for the specular term.

L_o = intensity · (L_d + L_s), with n the shading normal, v the unit view vector, r = reflect(−v, n):

- Diffuse (Ramamoorthi & Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps",
  eqs. 3, 8, 12): E(n) = Σ_lm Â_l L_lm Y_lm(n), Â_0 = π, Â_1 = 2π/3, Â_2 = π/4, the nine L_lm (RGB) the
  parameters sh0 … sh8 in the order Y_00, Y_1−1, Y_10, Y_11, Y_2−2, Y_2−1, Y_20, Y_21, Y_22 (their x, y, z
  = our x, z, y: their z is the world's +Y). The parameters are the projected L_lm themselves, **Â not
  folded in**: the brick multiplies by Â_l and the basis constants (0.282095, 0.488603, 1.092548, 0.315392,
  0.546274), so eval/ibl_env.sh9's coefficients are uploaded as they are. E is floored at 0 (l ≤ 2 rings
  below zero on the side turned away from a small bright source). L_d = kd · B · E/π, with B the table's
  diffuse channel (Gotanda 2014 eq. 4's directional albedo for gotanda_fitted, 1 for Lambert, 0 with no
  diffuse term) and kd what the glue passes: ρ_d (1 − f0) for Gotanda's diffuse (his footnote 4), ρ_d for
  Lambert, 0 without a diffuse term.
- Specular (Karis 2013, "Real Shading in Unreal Engine 4", the split sum; Gotanda 2014, the AmbientBRDF
  table): L_s = C(r, lod) · (f0 · R + G), C the GGX-prefiltered radiance cube (n = v = r) whose level k of
  L = radiance_levels holds α = (k/(L − 1))², read at lod = √α (L − 1), and (R, G) the scale and bias of f0
  of the microfacet term's directional albedo from the table at (n·v, √α).

The table is 32 × 32 texels with its nodes at the texel centres (x_i = i/31: eval/ibl_tables.py, the
reference/tables.py convention), so it is read at u = x · 31/32 + 1/64, bilinear, clamp to edge; n·v is
floored at 1e-4 as the shading policy does and α clamped to [0, 1]. The known error of the split sum (the
lobe is not stretched at grazing views) and of SH9 (a sun rings) is measured in docs/design/ibl.md.

fp16: guarded — every product is of values below the fp16 range for radiance under 65504 (the cube is fp16).
"""
BRICK = {
    "kind": "environment",
    "cite": "Karis 2013 (split sum); Gotanda 2014 (AmbientBRDF, eq. 4); Ramamoorthi & Hanrahan 2001 eqs. 3, 8, 12 (SH9)",
    "params": {
        "sh0": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_00 of the environment's radiance (RGB; Â not folded)"},
        "sh1": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_1-1"},
        "sh2": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_10"},
        "sh3": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_11"},
        "sh4": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_2-2"},
        "sh5": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_2-1"},
        "sh6": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_20"},
        "sh7": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_21"},
        "sh8": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 0.0, 0.0], "doc": "SH9 L_22"},
        "intensity": {"type": "float", "range": [0.0, 1000000.0], "default": 1.0, "doc": "scales the environment's radiance"},
        "radiance_levels": {"type": "float", "range": [1.0, 16.0], "default": 7.0, "doc": "mip levels of the radiance cube (level k holds alpha = (k/(levels-1))^2)"},
    },
    "textures": {
        "radiance": {"holds": "data", "doc": "the GGX-prefiltered radiance cube with its roughness mip chain (linear, fp16)"},
        "ambient_brdf": {"holds": "data", "doc": "the BRDF's AmbientBRDF table over (n.v, sqrt(alpha)): R scale, G bias of f0, B diffuse"},
    },
    "fp16": "guarded: radiance below 65504 (an fp16 cube), E floored at 0",
}


def ambient(N: vec3, V: vec3, kd: vec3, f0: vec3, alpha: float, sh0: vec3, sh1: vec3, sh2: vec3, sh3: vec3,
            sh4: vec3, sh5: vec3, sh6: vec3, sh7: vec3, sh8: vec3, intensity: float, radiance_levels: float,
            radiance: texturecube, ambient_brdf: texture2d) -> vec3:
    nv = clamp(dot(N, V), 0.0001, 1.0)
    a = clamp(alpha, 0.0, 1.0)
    # E(n) = sum of A_l L_lm Y_lm(n): the basis constants times A_l (pi, 2 pi / 3, pi / 4), multiplied out
    e = (sh0 * 0.886227
         + (sh1 * N.z + sh2 * N.y + sh3 * N.x) * 1.023327
         + (sh4 * (N.x * N.z) + sh5 * (N.z * N.y) + sh7 * (N.x * N.y)) * 0.858086
         + sh6 * ((3.0 * N.y * N.y - 1.0) * 0.247708)
         + sh8 * ((N.x * N.x - N.z * N.z) * 0.429043))
    irradiance = max(e, vec3(0.0))
    t = sample_level(ambient_brdf, vec2(nv, sqrt(a)) * 0.96875 + vec2(0.015625), 0.0)
    r = reflect(-V, N)
    c = sample_level(radiance, r, sqrt(a) * (radiance_levels - 1.0)).xyz
    return (kd * (t.z * INV_PI) * irradiance + c * (f0 * t.x + vec3(t.y))) * intensity
