"""Anisotropic Ward specular: f_r = R_F(0) exp(-((h.t/m_u)^2 + (h.b/m_v)^2) / cos^2 theta_h) / (4 pi m_u m_v cos theta_i cos theta_e).

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", slides "Ward -
Anisotropic": the course prints two formulations, exp{tan^2 theta_h (cos^2 phi_h / m_u +
sin^2 phi_h / m_v)} and the "more implementation-friendly" exp{((cos alpha_u / m_u)^2 +
(cos alpha_v / m_v)^2) / cos^2 theta_h}, alpha_u, alpha_v the angles between h and t, b.
Both as printed in the seed text lack the minus sign of the exponent, and the first divides
by m_u, m_v where Ward 1992 eq. 5a has m_u^2, m_v^2 (cos alpha_u = sin theta_h cos phi_h,
so with the sign and the squares restored the two agree: tests/library/test_library_specular.py).
This brick uses the second (h.t, h.b, n.h: no angle, no tan). Normalization
1/(cos theta_i cos theta_e) as in the course's isotropic Ward (see ward_isotropic.py).
Specular albedo R_F(0) (`f0`, Ward's rho_s). Reciprocal. With m_u = m_v = m it equals
`ward_isotropic`. Reads the tangent frame (HdotT, HdotB).
"""
BRICK = {
    "kind": "specular",
    "cite": "Ward 1992 eq. 5a; Hoffman & Baker 2006, anisotropic Ward (dot-product form)",
    "params": {
        "m_u": {"type": "float", "range": [0.0, 1.0], "default": 0.1, "doc": "Ward RMS slope along the tangent t"},
        "m_v": {"type": "float", "range": [0.0, 1.0], "default": 0.3, "doc": "Ward RMS slope along the bitangent b"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_F(0), the specular albedo (Ward's rho_s)"},
    },
    "needs": ["NdotL", "NdotV", "NdotH", "HdotT", "HdotB"],
}

# m_u, m_v are floored at 1e-4 (the NDFs' roughness floor): 0 is a Dirac peak.
# Cost: a slope below 1e-4 renders as 1e-4.
M_MIN = 0.0001


def specular(NdotL: float, NdotV: float, NdotH: float, HdotT: float, HdotB: float, m_u: float,
             m_v: float, f0: vec3) -> vec3:
    mu = max(m_u, M_MIN)
    mv = max(m_v, M_MIN)
    x = HdotT / mu
    y = HdotB / mv
    # The exponent's denominator cos^2 theta_h is floored at 1e-30 and the exponent capped at
    # 1000 (exp(-1000) = 0 in float32 and float64), so no inf reaches exp; h.n = 0 (and the undefined h of
    # l = -v, h = 0, where h.t = h.b = 0 too) is the limit tan theta_h = inf: exp = 0.
    q = min((x * x + y * y) / max(NdotH * NdotH, 1e-30), 1000.0)
    e = exp(-q) if NdotH > 0.0 else 0.0
    # 4 pi m_u m_v n.l n.v floored at 1e-30 (as ward_isotropic): f_r <= 1e30, never inf.
    return f0 * (e / max(4.0 * PI * mu * mv * NdotL * NdotV, 1e-30))


# Sampling (the contract: library/kinds.py): Walter 2005, "Notes on the Ward BRDF" (Cornell PCG-05-06), the
# corrected sampling of Ward 1992 §4: h by the elliptical Gaussian of slopes, phi_h = atan(m_v/m_u tan 2 pi xi'),
# tan^2 theta_h = -log(xi) / (cos^2 phi_h / m_u^2 + sin^2 phi_h / m_v^2) (eqs. 6-7), drawn here through the
# slopes, (h_t/h_n / m_u, h_b/h_n / m_v) = sqrt(-log(1 - xi)) (cos 2 pi xi', sin 2 pi xi'), the same
# distribution without the quadrant bookkeeping of the atan; l = reflect(-v, h), density (eq. 9)
# p(l) = exp(-tan^2 theta_h (cos^2 phi_h/m_u^2 + sin^2 phi_h/m_v^2)) / (4 pi m_u m_v (h.l) cos^3 theta_h).
def ward_sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, mu: float, mv: float) -> vec3:
    r = sqrt(-log(max(1.0 - u.x, 1e-30)))
    phi = TWO_PI * u.y
    H = normalize(T * (mu * r * cos(phi)) + B * (mv * r * sin(phi)) + N)
    return reflect(-V, H)


def ward_pdf(L: vec3, V: vec3, N: vec3, T: vec3, B: vec3, mu: float, mv: float) -> float:
    S = L + V
    s2 = dot(S, S)
    H = S * rsqrt(max(s2, 1e-30))
    c = dot(N, H)
    vh = dot(V, H)
    x = dot(H, T) / mu
    y = dot(H, B) / mv
    c2 = max(c * c, 1e-30)
    ok = s2 > 0.0 and c > 0.0 and vh > 0.0 and dot(N, L) > 0.0
    return exp(-min((x * x + y * y) / c2, 1000.0)) / (4.0 * PI * mu * mv * vh * c2 * c) if ok else 0.0


def sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, m_u: float, m_v: float) -> vec3:
    return ward_sample(u, V, N, T, B, max(m_u, M_MIN), max(m_v, M_MIN))


def pdf(L: vec3, V: vec3, N: vec3, T: vec3, B: vec3, m_u: float, m_v: float) -> float:
    return ward_pdf(L, V, N, T, B, max(m_u, M_MIN), max(m_v, M_MIN))
