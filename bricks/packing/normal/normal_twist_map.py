"""Normal and twist map in one RGBA texture: N' from RG (z reconstructed), T' from BA by Gram-Schmidt against N'.

Hoffman & Baker 2006, "Anisotropic BRDF with Normal Map": "Normal map permutes N; T and B are
orthogonalized to new N" — the notes' shader `T = normalize(T - dot(N,T)*N)`, `B = cross(N,T)` —
and "Anisotropic BRDF with Normal and Twist Maps": a twist map gives T per texel ("Optionally T read
from twist map"); "Naively stored, color + normal + twist will be 12 bytes per texel". Here normal
and twist share one 4-byte texel, as the course packs normal xy with other data ("store normals as
only x and y"):

  R, G  tangent-space normal t.xy as (t + 1)/2; t.z = sqrt(1 − t.x² − t.y²) (ATI 2005, 3Dc), then
        N' = normalize(t.x T + t.y B + t.z N) (Peercy, Airey & Cabral 1997), as `normal_map_xy`;
  B, A  twist direction w in the unperturbed tangent plane as (w + 1)/2: d = w.x T + w.y B
        (w = (1, 0) keeps the vertex tangent; (cos φ, sin φ) turns it by φ toward B). The notes'
        3-vector twist (T already orthogonal to N', "no longer need to orthogonalize") costs a third
        channel; two channels need the Gram-Schmidt step of the notes' shader:
        T' = normalize(d − (d·N') N'). The glue then sets B' = N' × T' (link/glue.py shading_tangent).

A direction (not an angle) is stored so that bilinear filtering and MIP averaging of neighbouring
texels give a direction between them (an angle wraps at 2π). The anisotropic models read T only
through squares or through products symmetric under T → −T (Ward 1992 eq. 5a, Ashikhmin & Shirley
2000 eq. 4, Banks 1994), so w and −w are the same twist: an author keeps neighbouring texels in one
half-plane so that filtering does not cancel them.

Isotropic BRDFs: `tangent` is called only when the BRDF reads the tangent frame (T, B, HdotT, …);
otherwise the twist channels are not read and the permutation equals `normal_map_xy`'s (docs/design/library.md
"Tangent frame").

Guards (`tangent`):
- |d|² < 1e-4 (|w| < 0.01) means "no direction" — the mid-grey texel 0.5 of an unpainted map (8-bit
  code 128 gives |w| = 0.0039), or filtering across opposite directions — and the vertex tangent T
  is used, so such texels shade as without a twist instead of with an arbitrary tangent. A painted
  8-bit unit direction has |w| ≥ 0.99, far above the threshold.
- The squared length of t = d − (d·N') N' is floored at 1e-6 before rsqrt, as `normal_map` and
  `normal_map_xy` floor theirs: 1e-6 is representable in half (the subnormal 17 · 2^-24 ≈ 1.01e-6;
  1e-30 was 0 there), so the guard holds in fp16 too. The floor changes T' only where |t| < 1e-3,
  i.e. where d lies within 0.06° of N' for a painted unit twist (|w| ≥ 0.99); T' is there t · 1000,
  shorter than unit, and 0 when d is parallel to N' (a normal tilted 90° toward the twist) instead
  of NaN: the anisotropic terms see H·T' = H·B' = 0 and stay finite.
Normal guard: 1 − |t.xy|² floored at 0, as `normal_map_xy` (filtering gives |t.xy| slightly > 1).

Cost (`shadermatrix costs`, spirv-opt -O, Ward with one point light, the same in GLSL, HLSL and WGSL):
tex 2, ALU 68, transc. 9 against `normal_map_xy`'s tex 1, ALU 53, transc. 8: the Gram-Schmidt step and
B' = N' × T' cost 15 ALU and one rsqrt; `normal` and `tangent` each sample the one texel and
spirv-opt does not merge the two samples (one texture, one binding, two sample instructions).
"""
BRICK = {
    "kind": "normal",
    "cite": "Hoffman & Baker 2006, Anisotropic BRDF with Normal and Twist Maps (Gram-Schmidt T against the "
            "perturbed N); ATI 2005 3Dc (xy normals); Peercy et al. 1997 tangent-space normal maps",
    "textures": {"normal_map": {"srgb": False, "holds": "normal_xy", "doc": "linear RGBA; RG: normal xy as (t + 1) / 2, z reconstructed; "
                                                      "BA: twist direction in the tangent plane as (w + 1) / 2"}},
}


def normal(N: vec3, T: vec3, B: vec3, uv: vec2, normal_map: texture2d) -> vec3:
    t = sample(normal_map, uv).xy * 2.0 - vec2(1.0)
    # floored at 0: |t.xy| > 1 after filtering/quantization gives z = 0, not NaN
    z = sqrt(max(1.0 - dot(t, t), 0.0))
    return normalize(t.x * T + t.y * B + z * N)


def tangent(Np: vec3, T: vec3, B: vec3, uv: vec2, normal_map: texture2d) -> vec3:
    w = sample(normal_map, uv).zw * 2.0 - vec2(1.0)
    d = w.x * T + w.y * B
    if dot(d, d) < 0.0001:  # |w| < 0.01: no twist painted (mid-grey), keep the vertex tangent
        d = T
    # Gram-Schmidt against the perturbed normal; the floor 1e-6 (representable in half) keeps d ∥ N' finite
    # (T' = 0) and changes T' only where |t| < 1e-3 (d within 0.06 degrees of N' for a unit twist)
    t = d - dot(d, Np) * Np
    return t * rsqrt(max(dot(t, t), 0.000001))
