"""Isotropic Ward specular: f_r = R_F(0) exp(-tan^2 theta_h / m^2) / (4 pi m^2 cos theta_i cos theta_e).

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", slide "Ward - Isotropic",
exactly as printed there: the normalization 1/(cos theta_i cos theta_e) is the correction
"discovered since the Ward model was first published in 1992" (Ward 1992 eq. 4 has
1/sqrt(cos theta_i cos theta_e); ACCURACY-FACTS §4.8 and pitfall 6 name the product form
"Ward-Duer", after Duer 2006, "An Improved Normalization for the Ward Reflectance Model":
its f cos theta_l does not vanish at grazing l, tested).
The specular albedo is R_F(0) (`f0`), as the course writes it (Ward's rho_s). Reciprocal.
tan^2 theta_h = sin^2 theta_h / cos^2 theta_h with sin^2 theta_h = |n x h|^2 (NxH2 from the
glue), which keeps its digits near the peak.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, isotropic Ward (Ward 1992 eq. 4 with the 1/(cos cos) normalization)",
    "params": {
        "m": {"type": "float", "range": [0.0, 1.0], "default": 0.2, "doc": "Ward roughness m: RMS surface slope"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_F(0), the specular albedo (Ward's rho_s)"},
    },
    "needs": ["NdotL", "NdotV", "NdotH", "NxH2"],
}

# m is floored at 1e-4 (the NDFs' roughness floor): m = 0 is a Dirac peak, 0/0 at h = n.
# Cost: m < 1e-4 renders as 1e-4.
M_MIN = 0.0001


def specular(NdotL: float, NdotV: float, NdotH: float, NxH2: float, m: float, f0: vec3) -> vec3:
    mm = max(m, M_MIN)
    m2 = mm * mm
    # tan^2 theta_h / m^2 = NxH2 / (m^2 cos^2 theta_h); the denominator is floored at 1e-30
    # (h.n = 0, where NxH2 = 1: exp of -1e30 is 0, the limit) and the exponent capped at 1000
    # (exp(-1000) = 0 in float32 and float64), so no inf reaches exp. Cost: none.
    q = min(NxH2 / max(m2 * NdotH * NdotH, 1e-30), 1000.0)
    # 4 pi m^2 n.l n.v >= 4 pi 1e-8 1e-4 n.l: floored at 1e-30 so that a float32 n.l of 1e-38
    # cannot overflow the quotient (f_r <= 1e30). Cost: only n.l < 8e-19 is changed.
    return f0 * (exp(-q) / max(4.0 * PI * m2 * NdotL * NdotV, 1e-30))


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


def sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, m: float) -> vec3:
    mm = max(m, M_MIN)
    return ward_sample(u, V, N, T, B, mm, mm)


def pdf(L: vec3, V: vec3, N: vec3, T: vec3, B: vec3, m: float) -> float:
    mm = max(m, M_MIN)
    return ward_pdf(L, V, N, T, B, mm, mm)
