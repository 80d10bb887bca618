"""The course's shift-variant pixel shader: Kd from a diffuse map, Ks RGB and exponent n from a specular map.

Hoffman & Baker 2006, "Pixel Shader (Shift-Variant BRDF)":
    float4 spec = tex2d(specMap, uv); float n = spec.w; float3 Ks = spec.rgb;
    float3 Kd = tex2d(diffMap, uv);
with Kd = rho_d and Ks = R_F(0) = f0 of the normalized Blinn-Phong. Two textures:

  albedo_map    sRGB, RGB = rho_d (times the material's constant rho_d, as `albedo_texture`);
  specular_map  sRGB, RGB = f0 (times the material's constant f0): "gamma space useful for
                textures containing non-radiance values such as ρ_d and R_F(0)" (the notes);
                A = exponent p, linear (sRGB formats decode RGB only): n = n_max^p.

The course reads n = spec.w directly, an exponent in [0, 1]; here p maps to [1, n_max]
(n_max = 8192, Lazarov 2011, as `normal_power_gloss`), so 8 bits span the useful exponents.
Provides rho_d, f0 and n: it fits diffuse+specular BRDFs reading all three
(lambert+blinn_phong_normalized, the course's BlinnPhong(L, V, N, Kd, Ks, n)). No guards.
"""
BRICK = {
    "kind": "packing",
    "cite": "Hoffman & Baker 2006, Pixel Shader (Shift-Variant BRDF): specMap rgb = Ks, w = n; diffMap = Kd",
    "params": {"n_max": {"type": "float", "range": [1.0, 10000.0], "default": 8192.0, "doc": "the exponent at A = 1 (n = n_max^A)"}},
    "textures": {"albedo_map": {"srgb": True, "doc": "sRGB RGB: diffuse albedo rho_d"},
                 "specular_map": {"srgb": True, "doc": "sRGB RGB: specular color f0 = R_F(0); A (linear): exponent p, n = n_max^p"}},
    "slots": {"normal": {"kind": "normal", "default": "vertex"}},
}


def get_rho_d(uv: vec2, albedo_map: texture2d, rho_d: vec3) -> vec3:
    return rho_d * sample(albedo_map, uv).xyz


def get_f0(uv: vec2, specular_map: texture2d, f0: vec3) -> vec3:
    return f0 * sample(specular_map, uv).xyz


def get_n(uv: vec2, specular_map: texture2d, n_max: float) -> float:
    return pow(n_max, sample(specular_map, uv).w)
