"""Tangent-space normal map: N' = normalize(t.x T + t.y B + t.z N), t = 2 texel - 1.

Blinn 1978 (bump mapping); Peercy, Airey & Cabral 1997 (tangent-space normal maps).
"""
BRICK = {
    "kind": "normal",
    "cite": "Blinn 1978; Peercy et al. 1997 tangent-space normal maps",
    "textures": {"normal_map": {"srgb": False, "holds": "normal", "doc": "tangent-space normal, RGB = (t + 1) / 2"}},
}


def normal(N: vec3, T: vec3, B: vec3, uv: vec2, normal_map: texture2d) -> vec3:
    t = sample(normal_map, uv).xyz * 2.0 - vec3(1.0)
    return normalize(t.x * T + t.y * B + t.z * N)


def tangent(Np: vec3, T: vec3) -> vec3:
    # The shading tangent for BRDFs that read the tangent frame: the interpolated T made orthogonal to the
    # perturbed normal N' by Gram-Schmidt (Hoffman & Baker 2006, anisotropic BRDFs with normal maps: a frame
    # that is not orthonormal "yields visually poor results"); the glue sets B' = N' x T'. The floor 1e-6 is
    # representable in half and changes T' only where T is within 0.06 degrees of N' (T' = 0 there, not NaN).
    t = T - dot(T, Np) * Np
    return t * rsqrt(max(dot(t, t), 0.000001))
