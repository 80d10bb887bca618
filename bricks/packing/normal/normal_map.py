"""Tangent-space normal map: N' = normalize(t.x T + t.y B + t.z N), t = 2 texel - 1.

Blinn 1978 (bump mapping); Peercy, Airey & Cabral 1997 (tangent-space normal maps).
"""
BRICK = {
    "kind": "normal",
    "cite": "Blinn 1978; Peercy et al. 1997 tangent-space normal maps",
    "textures": {"normal_map": {"srgb": False, "doc": "tangent-space normal, RGB = (t + 1) / 2"}},
}


def normal(N: vec3, T: vec3, B: vec3, uv: vec2, normal_map: texture2d) -> vec3:
    t = sample(normal_map, uv).xyz * 2.0 - vec3(1.0)
    return normalize(t.x * T + t.y * B + t.z * N)
