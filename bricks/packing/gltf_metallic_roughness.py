"""glTF 2.0 metallic-roughness: base color and ORM textures converted to rho_d, f0 and alpha.

glTF 2.0 specification, 3.9.2 "Metallic-Roughness Material" and Appendix B "BRDF
Implementation" (B.3.5, the metal/dielectric mix and its approximation):
    base      = baseColorFactor · baseColorTexture.rgb           (sRGB texture, decoded)
    metallic  = metallicFactor · metallicRoughnessTexture.b
    roughness = roughnessFactor · metallicRoughnessTexture.g
    c_diff = lerp(base, black, metallic) = base · (1 − metallic)      → rho_d
    f0     = lerp(0.04, base, metallic)                                → f0
    α      = roughness²                                                → alpha
so a textured GGX metal is lambert+microfacet(ndf=ggx, …) with this packing (metallic 1:
rho_d = 0, f0 = base). The diffuse term's (1 − F) weight of Appendix B belongs to the BRDF,
not to the packing, and lambert does not apply it.

Textures (an ORM texture, as glTF exporters pack occlusion with metallic-roughness):
  base_color_map  sRGB; RGB base color; A (coverage) not read;
  orm_map         linear; R occlusion, not read: glTF 2.0 3.9.3 applies it to indirect light
                  only, and this light loop has only direct lights; G roughness; B metallic.
Factors are this packing's parameters (base_color, metallic, roughness), defaults 1 as in glTF.
Provides rho_d, f0 and alpha: it fits diffuse+microfacet BRDFs (lambert+microfacet(…)); for a
specular-only microfacet(…) use `f0_roughness_texture`. No guards here: the NDFs floor α
at 1e-4 themselves (docs/design/accuracy.md, "Roughness").
"""
BRICK = {
    "kind": "packing",
    "cite": "glTF 2.0 spec 3.9.2 and Appendix B: c_diff = base (1 - metallic), f0 = mix(0.04, base, metallic), alpha = roughness^2",
    "params": {
        "base_color": {"type": "vec3", "range": [0.0, 1.0], "default": [1.0, 1.0, 1.0], "doc": "baseColorFactor (rgb)"},
        "metallic": {"type": "float", "range": [0.0, 1.0], "default": 1.0, "doc": "metallicFactor"},
        "roughness": {"type": "float", "range": [0.0, 1.0], "default": 1.0, "doc": "roughnessFactor (perceptual roughness; alpha = roughness^2)"},
    },
    "textures": {"base_color_map": {"srgb": True, "doc": "sRGB RGB: base color; A not read"},
                 "orm_map": {"srgb": False, "doc": "linear; R: occlusion (not read, indirect light only); G: roughness; B: metallic"}},
    "slots": {"normal": {"kind": "normal", "default": "vertex"}, "uv": {"kind": "uv", "optional": True}},
}


def base(uv: vec2, base_color_map: texture2d, base_color: vec3) -> vec3:
    return base_color * sample(base_color_map, uv).xyz


def get_rho_d(uv: vec2, base_color_map: texture2d, base_color: vec3, orm_map: texture2d, metallic: float) -> vec3:
    m = metallic * sample(orm_map, uv).z
    return base(uv, base_color_map, base_color) * (1.0 - m)


def get_f0(uv: vec2, base_color_map: texture2d, base_color: vec3, orm_map: texture2d, metallic: float) -> vec3:
    m = metallic * sample(orm_map, uv).z
    return mix(vec3(0.04), base(uv, base_color_map, base_color), m)


def get_alpha(uv: vec2, orm_map: texture2d, roughness: float) -> float:
    r = roughness * sample(orm_map, uv).y
    return r * r
