"""Ashikhmin-Shirley anisotropic specular:
f_r = sqrt((n_u + 1)(n_v + 1)) / (8 pi) (n.h)^e / ((k.h) max(n.l, n.v)) F(k.h),
e = (n_u (h.t)^2 + n_v (h.b)^2) / (1 - (n.h)^2).

Ashikhmin & Shirley 2000, "An Anisotropic Phong BRDF Model", eq. 4 (specular term) with
Schlick's Fresnel F(k.h) = R_s + (1 - R_s)(1 - k.h)^5 (eq. 5; R_s = R_F(0) = `f0`);
Hoffman & Baker 2006 print it twice, with the exponent n_u cos^2 phi_h + n_v sin^2 phi_h
and in the "implementation-friendly" dot-product form used here. The seed text of that
second form divides by 1 + cos^2 theta_h: a typo, the paper's eq. 4 has 1 - (h.n)^2
(= sin^2 theta_h; with it the two forms agree: tests/library/test_library_specular.py).
k is l or v (k.h = l.h = v.h). The normalization sqrt((n_u+1)(n_v+1))/(8 pi) makes the
underlying Phong-type NDF integrate to 1 (ACCURACY-FACTS §4.9). Reciprocal.
The diffuse term of the model (28 rho_d/(23 pi) ...) is not in this brick.
Reads the tangent frame (HdotT, HdotB).
"""
BRICK = {
    "kind": "specular",
    "cite": "Ashikhmin & Shirley 2000 eqs. 4-5; Hoffman & Baker 2006 (dot-product form)",
    "params": {
        "n_u": {"type": "float", "range": [1.0, 100000.0], "default": 100.0, "doc": "Phong exponent along the tangent t"},
        "n_v": {"type": "float", "range": [1.0, 100000.0], "default": 10.0, "doc": "Phong exponent along the bitangent b"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_s = R_F(0), Fresnel reflectance at normal incidence"},
    },
    "needs": ["NdotL", "NdotV", "NdotH", "LdotH", "HdotT", "HdotB"],
}


def specular(NdotL: float, NdotV: float, NdotH: float, LdotH: float, HdotT: float, HdotB: float,
             n_u: float, n_v: float, f0: vec3) -> vec3:
    # The exponent's denominator 1 - (n.h)^2 is written (h.t)^2 + (h.b)^2 (the same for a unit
    # h): it keeps its digits as h -> n, and the exponent stays a weighted mean of n_u and n_v.
    # At h = n exactly it is 0/0 (ACCURACY-FACTS pitfall 14): there e := n_u (pow(1, e) = 1
    # for any e, and pow(0, n_u) = 0 for the undefined h = 0 of l = -v). Cost: none.
    tu = HdotT * HdotT
    tv = HdotB * HdotB
    s2 = tu + tv
    e = (n_u * tu + n_v * tv) / s2 if s2 > 0.0 else n_u
    c = 1.0 - LdotH
    c2 = c * c
    fresnel = f0 + (vec3(1.0) - f0) * (c2 * c2 * c)
    # (k.h) max(n.l, n.v) >= (k.h) 1e-4 is 0 only for l = -v (h = 0, where the numerator is
    # pow(0, n_u) = 0); floored at 1e-30 so that 0/0 is 0. Cost: none (f_r <= 4e3 / 1e-30 is finite).
    d = max(LdotH * max(NdotL, NdotV), 1e-30)
    return fresnel * (sqrt((n_u + 1.0) * (n_v + 1.0)) / (8.0 * PI) * pow(NdotH, e) / d)


# Sampling (the contract: library/kinds.py): Ashikhmin & Shirley 2000 §3, eqs. 9-10: phi_h =
# atan(sqrt((n_u+1)/(n_v+1)) tan(pi xi / 2)) per quadrant, written as atan2(sqrt(n_u+1) sin 2 pi xi,
# sqrt(n_v+1) cos 2 pi xi) (the same map over the four quadrants at once), cos theta_h =
# xi'^(1/(n_u cos^2 phi_h + n_v sin^2 phi_h + 1)); h's density is p_h = sqrt((n_u+1)(n_v+1))/(2 pi)
# (n.h)^(n_u cos^2 phi_h + n_v sin^2 phi_h) (eq. 6) and l = reflect(-v, h) has p_h / (4 (k.h)) (eq. 8).
def sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, n_u: float, n_v: float) -> vec3:
    a = TWO_PI * u.x
    phi = atan2(sqrt(n_u + 1.0) * sin(a), sqrt(n_v + 1.0) * cos(a))
    cp = cos(phi)
    sp = sin(phi)
    c = pow(u.y, 1.0 / (n_u * cp * cp + n_v * sp * sp + 1.0))
    s = sqrt(max(1.0 - c * c, 0.0))
    return reflect(-V, T * (s * cp) + B * (s * sp) + N * c)


def pdf(L: vec3, V: vec3, N: vec3, T: vec3, B: vec3, n_u: float, n_v: float) -> float:
    S = L + V
    s2 = dot(S, S)
    H = S * rsqrt(max(s2, 1e-30))
    c = dot(N, H)
    vh = dot(V, H)
    tu = dot(H, T) * dot(H, T)
    tv = dot(H, B) * dot(H, B)
    # the exponent as the specular term writes it: (h.t)^2 + (h.b)^2 for 1 - (n.h)^2, n_u at h = n
    e = (n_u * tu + n_v * tv) / (tu + tv) if tu + tv > 0.0 else n_u
    ok = s2 > 0.0 and c > 0.0 and vh > 0.0 and dot(N, L) > 0.0
    return sqrt((n_u + 1.0) * (n_v + 1.0)) * INV_TWO_PI * pow(c, e) / (4.0 * vh) if ok else 0.0
