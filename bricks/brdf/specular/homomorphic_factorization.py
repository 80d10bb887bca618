"""Homomorphic factorization: f_r ≈ p(ω_i) q(ω_h) p(ω_o), three cube-map look-ups.

McCool, Ang & Ahmad 2001, "Homomorphic Factorization of BRDFs for High-Performance Rendering";
Hoffman & Baker 2006 ("Measured BRDFs - Factorization", "Implementation of Factorization":
C = texCUBE(P, V) · texCUBE(Q, H) · texCUBE(P, L)). The factors are computed by the generator
(generator/reference/tables_homomorphic.py): a log-space least-squares fit, log f ≈ log p(l) +
log q(h) + log p(v), over the texels of P and Q with a smoothness term, of f itself (not f·cos θ_i)
sampled densely on the hemisphere. The directions are in the local frame (t, b, n): the brick reads
the tangent frame, and one p serves l and v (the BRDF is reciprocal).

The BRDF factored (this brick's reference, generator/reference/specular.py HOMOMORPHIC_TARGET):
Ashikhmin & Shirley 2000 eq. 4 with Schlick's Fresnel at n_u = 4, n_v = 16, f0 = (0.95, 0.64, 0.54)
(copper-like, so the factors are RGB) — the course's anisotropic model. Three factors cannot hold
its 1/((k·h) max(n·l, n·v)) and F(k·h), which depend on l and v jointly: the fit's error is large
where f is small or both directions graze (the declared tolerance is the measured hemisphere max
relative error, rounded up). Measured (float32, accuracy's hemisphere, 12⁴ samples): max relative
35.9 (REL_FLOOR 1e-6), RMS relative 0.72, median 0.24; energy-weighted (cos θ_i cos θ_o) relative
L2 0.42 / 0.49 / 0.52 (R, G, B); directional albedo 9 % low at n·v = 1, 16 % high at n·v = 0.5,
8–15 % low at n·v = 0.1. fp16 and fp32 tables measure the same (to 3 digits).

Tables: 16 × 16 per face, fp16 — the solve is a dense normal-equation system of 2 · 6 · 16² unknowns
(seconds); q spans ~1e-8 … 1 sr⁻¹, beyond unorm8's range and step.
A view below the horizon reads n·v clamped to 1e-4 (the horizon texel of its azimuth); the
undefined h of l = −v (h = 0) reads the normal's texel (n·h floored at 1e-4) instead of a
zero vector, which has no cube face.
"""
BRICK = {
    "kind": "specular",
    "cite": "McCool, Ang & Ahmad 2001 (homomorphic factorization); Hoffman & Baker 2006 (Implementation of Factorization)",
    "textures": {
        "hf_p": {"table": "homomorphic_p", "size": [16, 16], "format": "fp16",
                 "doc": "p(ω), ω = l or v in the (t, b, n) frame (RGB, p(n) = 1)"},
        "hf_q": {"table": "homomorphic_q", "size": [16, 16], "format": "fp16",
                 "doc": "q(ω_h), h in the (t, b, n) frame (RGB, 1/sr)"},
    },
    "tolerance": 36.0,
    "needs": ["NdotL", "NdotV", "NdotH", "LdotT", "LdotB", "VdotT", "VdotB", "HdotT", "HdotB"],
}


def specular(NdotL: float, NdotV: float, NdotH: float, LdotT: float, LdotB: float, VdotT: float,
             VdotB: float, HdotT: float, HdotB: float, hf_p: texturecube, hf_q: texturecube) -> vec3:
    l = vec3(LdotT, LdotB, NdotL)
    v = vec3(VdotT, VdotB, NdotV)
    h = vec3(HdotT, HdotB, max(NdotH, 0.0001))
    return sample_level(hf_p, l, 0.0).xyz * sample_level(hf_q, h, 0.0).xyz * sample_level(hf_p, v, 0.0).xyz
