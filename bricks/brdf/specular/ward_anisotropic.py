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
