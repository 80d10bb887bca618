"""Oren-Nayar diffuse, factored: the qualitative model with sin α tan β read from a table.

f_r = ρ_d/π (C_A + C_B max(0, cos φ) sin α tan β)   (Oren & Nayar 1994, eq. 30; C_A, C_B as in
`oren_nayar`, the course's C_A sign corrected), α = max(θ_i, θ_r), β = min(θ_i, θ_r).

Hoffman & Baker 2006 list "texture evaluation — factor into textures, use as lookup table" and "a
combination of the 2" among the implementation trade-offs; the classic factored Oren-Nayar reads
sin α tan β from a 2D table indexed by (n·l, n·v). That product diverges where both directions graze
(tan β → ∞ as β → 90°), and a filtered table of it cannot follow a 1/cos pole: measured against the
exact term, a 256 × 256 fp32 table of sin α tan β is still 7.9× off near n·l, n·v → 0 (2 % at
n·l, n·v ≥ 0.1). So the table holds the bounded factor sin α tan β · cos β = sin θ_i sin θ_r
(`oren_nayar_sin_sin`, generator/reference/tables_factored.py), and cos β = max(n·l, n·v) divides in
ALU — the notes' "factor some sub-expressions into textures, evaluate others with ALU".

Table: 64 × 64, unorm8 — chosen by measured error (benchmarks/results/tables.md): the values are in
[0, 1]; the BRDF's hemisphere error is dominated by the bilinear filter of sin θ's square-root
shape near grazing, not by the 8-bit step (1/510).
cos φ is the angle between the tangent-plane projections of l and v, normalized (each floored at
|·|² ≥ 1e-30: at normal incidence the projection is 0 and so is the term's weight sin θ).
A view below the horizon is shaded at the clamped n·v (its projection keeps its direction).
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Oren & Nayar 1994 eq. 30 (qualitative model), factored as in Hoffman & Baker 2006 (BRDF costs, factored forms)",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "sigma": {"type": "float", "range": [0.0, 1.57], "default": 0.3,
                  "doc": "Oren-Nayar roughness: standard deviation of the facet slope angle (radians)"},
    },
    "textures": {"on_sin_sin": {"table": "oren_nayar_sin_sin", "size": [64, 64], "format": "unorm8",
                                "doc": "sin θ_i sin θ_r at (n·l, n·v)"}},
    "tolerance": 0.02,
    "fp16": "unsafe: the 1e-30 floors of the projections' lengths are 0 in float16, so at normal incidence cos φ is 0 · inf (NaN)",
    "needs": ["L", "N", "NdotL", "NdotV", "V"],
}


def diffuse(L: vec3, V: vec3, N: vec3, NdotL: float, NdotV: float, rho_d: vec3, sigma: float,
            on_sin_sin: texture2d) -> vec3:
    s2 = sigma * sigma
    C_A = 1.0 - s2 / (2.0 * s2 + 0.66)
    C_B = 0.45 * s2 / (s2 + 0.09)
    l_p = L - N * NdotL
    v_p = V - N * dot(N, V)
    # cos(phi) of the normalized projections (floors: a zero projection has zero weight sin(theta)).
    cos_phi = dot(l_p, v_p) * rsqrt(max(dot(l_p, l_p), 1e-30) * max(dot(v_p, v_p), 1e-30))
    # table texel centres: u = x (W - 1)/W + 0.5/W for W = 64
    uv = vec2(NdotL, NdotV) * 0.984375 + vec2(0.0078125)
    sin_sin = sample_level(on_sin_sin, uv, 0.0).x
    retro = max(cos_phi, 0.0) * sin_sin / max(NdotL, NdotV)
    return rho_d * (INV_PI * (C_A + C_B * retro))
