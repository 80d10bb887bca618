"""Normalized Blinn-Phong specular: f_r = (n + 4) / (8 pi) * R_F(0) * (cos theta_h)^n.

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", the
Blinn-Phong BRDF "f_r = rho_d/pi + (n+4)/(8 pi) R_F(0) (cos theta_h)^n".
Its directional albedo at normal incidence is (n + 2^(-n/2)) / (n + 2) times
R_F(0) (ACCURACY-FACTS §4.3), slightly below 1.

fp16: about 10 % hemisphere error at the default n (x^n multiplies half's rounding by n);
n = 1e5 is inf in half. Keep n <= 1e4 in fp16 permutations.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, normalized Blinn-Phong: (n+4)/(8 pi) R_F(0) cos^n(theta_h)",
    "params": {
        "n": {"type": "float", "range": [1.0, 100000.0], "default": 64.0, "doc": "Blinn-Phong cosine power"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04], "doc": "R_F(0), Fresnel reflectance at normal incidence"},
    },
    "needs": ["NdotH"],
}


def specular(NdotH: float, n: float, f0: vec3) -> vec3:
    return f0 * ((n + 4.0) / (8.0 * PI) * pow(NdotH, n))


# Sampling (the contract: library/kinds.py): h drawn proportional to D(h) cos theta_h for the normalized
# Blinn-Phong distribution D = (n + 2)/(2 pi) (n.h)^n, i.e. the course's cos^alpha sampler with alpha = n + 1
# (Bikker 2017; cos theta_h = xi^(1/(n+2))), density (n + 2)/(2 pi) (n.h)^(n+1) per unit solid angle of h;
# l = reflect(-v, h), whose density is that over 4 (v.h) (Walter et al. 2007 eq. 14; Torrance & Sparrow 1967).
def sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, n: float) -> vec3:
    c = pow(u.x, 1.0 / (n + 2.0))
    s = sqrt(max(1.0 - c * c, 0.0))
    phi = TWO_PI * u.y
    H = T * (s * cos(phi)) + B * (s * sin(phi)) + N * c
    return reflect(-V, H)


def pdf(L: vec3, V: vec3, N: vec3, n: float) -> float:
    S = L + V
    s2 = dot(S, S)
    H = S * rsqrt(max(s2, 1e-30))
    c = dot(N, H)
    vh = dot(V, H)
    ok = s2 > 0.0 and c > 0.0 and vh > 0.0 and dot(N, L) > 0.0
    return (n + 2.0) * INV_TWO_PI * pow(c, n + 1.0) / (4.0 * vh) if ok else 0.0
