"""Two-channel tangent-space normal map: t.xy = 2 texel.xy − 1, t.z = sqrt(1 − t.x² − t.y²) reconstructed.

Hoffman & Baker 2006, "Texture Management": "store normals as only x and y" (the other
two channels hold other data, or the format has two: BC5 / 3Dc, RG8); a unit tangent-space
normal with z ≥ 0 is determined by x and y (ATI 2005, "3Dc white paper"). Then
N' = normalize(t.x T + t.y B + t.z N) as `normal_map` (Peercy, Airey & Cabral 1997).

Texture `normal_map`, linear (not sRGB): R = (t.x + 1)/2, G = (t.y + 1)/2; B and A are not
read here (the packed `normal_power_gloss` packing keeps specular power and gloss there,
in the same texture: one binding, as both bricks name it `normal_map`).

Guard: 1 − x² − y² is floored at 0: filtering and 8-bit quantization give |t.xy| slightly
above 1 near the tangent plane; z is then 0 (the normal lies in the tangent plane, 1 − |xy|²
would be NaN under sqrt). It changes nothing for |t.xy| ≤ 1. The final normalize keeps N'
unit for an interpolated, not orthonormal, frame, as `normal_map` does.
"""
BRICK = {
    "kind": "normal",
    "cite": "Hoffman & Baker 2006 (normals as x and y only); ATI 2005 3Dc; Peercy et al. 1997 tangent-space normal maps",
    "textures": {"normal_map": {"srgb": False, "holds": "normal_xy", "doc": "linear; RG: tangent-space normal xy as (t + 1) / 2; z reconstructed; BA not read"}},
}


def normal(N: vec3, T: vec3, B: vec3, uv: vec2, normal_map: texture2d) -> vec3:
    t = sample(normal_map, uv).xy * 2.0 - vec2(1.0)
    # floored at 0: |t.xy| > 1 after filtering/quantization gives z = 0, not NaN
    z = sqrt(max(1.0 - dot(t, t), 0.0))
    return normalize(t.x * T + t.y * B + z * N)


def tangent(Np: vec3, T: vec3) -> vec3:
    # The shading tangent for BRDFs that read the tangent frame: the interpolated T made orthogonal to the
    # perturbed normal N' by Gram-Schmidt (Hoffman & Baker 2006, anisotropic BRDFs with normal maps: a frame
    # that is not orthonormal "yields visually poor results"); the glue sets B' = N' x T'. The floor 1e-6 is
    # representable in half and changes T' only where T is within 0.06 degrees of N' (T' = 0 there, not NaN).
    t = T - dot(T, Np) * Np
    return t * rsqrt(max(dot(t, t), 0.000001))
