"""Anisotropic Beckmann normal distribution.

D = exp(-tan^2 theta_h (cos^2 phi_h / alpha_u^2 + sin^2 phi_h / alpha_v^2)) / (pi alpha_u alpha_v cos^4 theta_h)
(Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
eq. 82; the elliptical Gaussian of slopes of Ward 1992 eq. 5a, normalized as a microfacet
NDF); alpha_u, alpha_v are the RMS slopes along T and B. tan^2 theta_h = sin^2 / cos^2 with
sin^2 theta_h = |n x h|^2 from the glue (NxH2), as beckmann.py, so it stays exact in float32
as alpha -> 0; cos^2 phi_h = (h.t)^2 / ((h.t)^2 + (h.b)^2). With alpha_u = alpha_v = alpha it
is beckmann.py's D exactly.

The microfacet host passes its own `alpha` to the visibility slot: an isotropic Smith term
sees that alpha, not (alpha_u, alpha_v) (see ggx_anisotropic.py).
Measured in float32 against the float64 reference (`shadermatrix accuracy`, every target): 8.5e-6 max
relative error on the hemisphere, 2.1e-4 on the stress set.
"""
BRICK = {
    "kind": "ndf",
    "fp16": "unsafe: COS2_MIN 1e-8 is 0 in half and c2 * c2 underflows at small n.h, as beckmann's: 0/0 = NaN on the default hemisphere",
    "cite": "Heitz 2014 eq. 82; Ward 1992 eq. 5a; Walter et al. 2007 eq. 25 (isotropic case)",
    "params": {
        "alpha_u": {"type": "float", "range": [0.0, 1.0], "default": 0.2,
                    "doc": "Beckmann RMS slope along the tangent T"},
        "alpha_v": {"type": "float", "range": [0.0, 1.0], "default": 0.4,
                    "doc": "Beckmann RMS slope along the bitangent B"},
    },
}

# alpha_u, alpha_v are floored at 1e-4 (as beckmann.py). Cost: a roughness below 1e-4 renders as 1e-4.
ALPHA_MIN = 0.0001
# cos^2 theta_h is floored at 1e-8 (as beckmann.py): at n.h = 0, D is exp(-huge) / positive = 0
# instead of 0/0. Cost: none; D has underflowed to 0 long before (ACCURACY-FACTS pitfall 9).
COS2_MIN = 1e-8
# (h.t)^2 + (h.b)^2 is floored at 1e-30 before dividing by it: 0 at h = n (where NxH2 = 0) and at
# h = 0 (l = -v). Cost: where the tangent component of h vanishes, phi_h is taken as 0
# (e = 1/alpha_u^2), as in the reference; at h = n the value does not depend on it.
TB2_MIN = 1e-30


def ndf(NdotH: float, NxH2: float, HdotT: float, HdotB: float, alpha_u: float, alpha_v: float) -> float:
    au = max(alpha_u, ALPHA_MIN)
    av = max(alpha_v, ALPHA_MIN)
    t2 = HdotT * HdotT
    b2 = HdotB * HdotB
    tb2 = t2 + b2
    e = (t2 / (au * au) + b2 / (av * av)) / tb2 if tb2 > TB2_MIN else 1.0 / (au * au)
    c2 = max(NdotH * NdotH, COS2_MIN)
    return exp(-NxH2 * e / c2) / (PI * au * av * c2 * c2)


# Sampling (the contract: library/kinds.py): h drawn proportional to D(h) cos theta_h (Walter et al. 2007
# eqs. 28-29; the anisotropic case as Walter 2005, "Notes on the Ward BRDF", eqs. 6-7), through the slopes:
# the Beckmann slope density is the Gaussian exp(-(x^2/ax^2 + y^2/ay^2)) / (pi ax ay), so
# (x/ax, y/ay) = sqrt(-log(1 - xi)) (cos 2 pi xi', sin 2 pi xi') and h = normalize(-x, -y, 1); the density
# per unit solid angle of h is D(h) cos theta_h = exp(-tan^2 theta_h (cos^2 phi/ax^2 + sin^2 phi/ay^2)) /
# (pi ax ay cos^3 theta_h). Not by visible normals: the mass the host's reflection sends below the horizon
# is lost (the caller scores it 0) and the estimator's weight carries G.
def slope_sample(u: vec2, N: vec3, T: vec3, B: vec3, ax: float, ay: float) -> vec3:
    r = sqrt(-log(max(1.0 - u.x, 1e-30)))
    phi = TWO_PI * u.y
    return normalize(T * (-ax * r * cos(phi)) + B * (-ay * r * sin(phi)) + N)


def slope_pdf(H: vec3, N: vec3, T: vec3, B: vec3, ax: float, ay: float) -> float:
    c = dot(N, H)
    x = dot(H, T) / ax
    y = dot(H, B) / ay
    c2 = max(c * c, COS2_MIN)
    return exp(-min((x * x + y * y) / c2, 1000.0)) / (PI * ax * ay * c2 * c) if c > 0.0 else 0.0


def sample_h(u: vec2, N: vec3, T: vec3, B: vec3, alpha_u: float, alpha_v: float) -> vec3:
    return slope_sample(u, N, T, B, max(alpha_u, ALPHA_MIN), max(alpha_v, ALPHA_MIN))


def pdf_h(H: vec3, N: vec3, T: vec3, B: vec3, alpha_u: float, alpha_v: float) -> float:
    return slope_pdf(H, N, T, B, max(alpha_u, ALPHA_MIN), max(alpha_v, ALPHA_MIN))
