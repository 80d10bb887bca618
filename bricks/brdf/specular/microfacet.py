"""Microfacet specular: f_r = F(v.h) * D(n.h) * G(l, v) / (4 (n.l)(n.v)).

Cook & Torrance 1982; the factored form of RTR3 §7.6.1 eq. 7.51
(f = F D G / (4 cos theta_i cos theta_o)), with the visibility term
V = G / (4 (n.l)(n.v)) supplied by the `vis` slot, so that a filler can fold
the cosines into its own expression (RTR3 §7.6.1, "visibility term").
Slots: ndf (D(n.h, |n x h|^2, alpha), normalized so that the integral of D cos theta_h is 1),
fresnel (F(f0, v.h)), vis (V).
"""
BRICK = {
    "kind": "specular",
    "cite": "Cook & Torrance 1982; RTR3 eq. 7.51 with visibility term V = G/(4 n.l n.v)",
    "params": {
        "alpha": {"type": "float", "range": [0.0, 1.0], "default": 0.3, "doc": "roughness: GGX alpha, Beckmann RMS slope m"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04], "doc": "Fresnel reflectance at normal incidence"},
    },
    "slots": {
        "ndf": {"kind": "ndf", "default": "ggx"},
        "fresnel": {"kind": "fresnel", "default": "schlick"},
        "vis": {"kind": "visibility", "default": "smith_schlick"},
    },
}


def specular(NdotL: float, NdotV: float, NdotH: float, NxH2: float, VdotH: float, alpha: float,
             f0: vec3) -> vec3:
    D = ndf(NdotH, NxH2, alpha)
    Vis = vis(NdotL, NdotV, NdotH, VdotH, alpha)
    return fresnel(f0, VdotH) * (D * Vis)


# Sampling (the contract: library/kinds.py): the NDF filler draws the half vector h (its sample_h; GGX by
# visible normals, Heitz 2018; Beckmann and Blinn-Phong by D cos theta_h, Walter et al. 2007 eqs. 28-30) and
# l = reflect(-v, h); the density of l is the density of h over 4 (v.h), the Jacobian of the reflection
# (Walter et al. 2007 eq. 14). An NDF filler without sample_h makes this BRDF fall back to cosine-weighted
# sampling (link/sampling.py says so).
def sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, alpha: float) -> vec3:
    return reflect(-V, ndf_sample_h(u, V, N, T, B, alpha))


def pdf(L: vec3, V: vec3, N: vec3, T: vec3, B: vec3, alpha: float) -> float:
    S = L + V
    s2 = dot(S, S)
    H = S * rsqrt(max(s2, 1e-30))
    vh = dot(V, H)
    ok = s2 > 0.0 and vh > 0.0 and dot(N, L) > 0.0
    return ndf_pdf_h(H, V, N, T, B, alpha) / (4.0 * vh) if ok else 0.0
