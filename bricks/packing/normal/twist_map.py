"""Twist map without a normal map: N' = the vertex normal, T' from a two-channel texture by Gram-Schmidt against N'.

Hoffman & Baker 2006, "Anisotropic BRDF with Normal and Twist Maps" ("Optionally T read from
twist map"), for anisotropic surfaces whose grain turns over the surface without bumps (radially
brushed metal, hair cards). Texture `twist_map`, linear: R, G = (w + 1)/2, w the twist direction in
the tangent plane, d = w.x T + w.y B (w = (1, 0) keeps the vertex tangent). The interpolated N and
T of a triangle are not orthogonal in general, so the notes' Gram-Schmidt step still applies:
T' = normalize(d − (d·N) N); the glue sets B' = N × T' (link/glue.py shading_tangent).

A direction rather than an angle, for filtering; w and −w are the same twist to the anisotropic
models (see `normal_twist_map`, which packs the same two channels beside a normal map). With an
isotropic BRDF the twist is not read and the texture is not declared.

Guards: |d|² < 1e-4 (mid-grey, unpainted texel) keeps the vertex tangent; the squared Gram-Schmidt
length is floored at 1e-6 before rsqrt (T' = 0, not NaN, when d ∥ N; representable in half, so fp16
keeps the guard; it changes T' only where d is within 0.06° of N for a unit twist). Both as in
`normal_twist_map`.

Cost (`shadermatrix costs`, spirv-opt -O, anisotropic GGX microfacet with one point light): tex 1,
ALU 86, transc. 8 against `vertex_tangent`'s tex 0, ALU 71, transc. 7.
"""
BRICK = {
    "kind": "normal",
    "cite": "Hoffman & Baker 2006, Anisotropic BRDF with Normal and Twist Maps (T from a twist map, "
            "Gram-Schmidt against N)",
    "textures": {"twist_map": {"srgb": False, "doc": "linear; RG: twist direction in the tangent plane as "
                                                     "(w + 1) / 2; BA not read"}},
}


def normal(N: vec3) -> vec3:
    return N


def tangent(Np: vec3, T: vec3, B: vec3, uv: vec2, twist_map: texture2d) -> vec3:
    w = sample(twist_map, uv).xy * 2.0 - vec2(1.0)
    d = w.x * T + w.y * B
    if dot(d, d) < 0.0001:  # |w| < 0.01: no twist painted (mid-grey), keep the vertex tangent
        d = T
    # Gram-Schmidt against the shading normal; the floor 1e-6 (representable in half) keeps d ∥ N finite
    # (T' = 0) and changes T' only where |t| < 1e-3 (d within 0.06 degrees of N for a unit twist)
    t = d - dot(d, Np) * Np
    return t * rsqrt(max(dot(t, t), 0.000001))
