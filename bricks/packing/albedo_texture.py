"""Albedo texture packing: rho_d from an sRGB texture (times the constant rho_d), optional normal map.

Hoffman & Baker 2006, "shift-variant" BRDFs: the diffuse albedo varies over the
surface through a texture. The texture view is sRGB, so sampling returns linear
values (the hardware decodes); the constant rho_d scales it (as glTF's baseColorFactor).
"""
BRICK = {
    "kind": "packing",
    "cite": "Hoffman & Baker 2006, shift-variant BRDFs (texture-mapped rho_d)",
    "textures": {"albedo_map": {"srgb": True, "doc": "diffuse albedo, sRGB-encoded RGB"}},
    "slots": {"normal": {"kind": "normal", "default": "vertex"}, "uv": {"kind": "uv", "optional": True}},
}


def get_rho_d(uv: vec2, albedo_map: texture2d, rho_d: vec3) -> vec3:
    return rho_d * sample(albedo_map, uv).xyz
