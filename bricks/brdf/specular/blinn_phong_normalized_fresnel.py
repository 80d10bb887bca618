"""Normalized Blinn-Phong with Fresnel: f_r = (n + 4) / (8 pi) * R_F(alpha_h) * (cos theta_h)^n.

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", slide "Blinn-Phong -
As a microfacet BRDF, Blinn-Phong can be easily extended with full Fresnel reflectance":
R_F(0) of `blinn_phong_normalized` replaced by R_F(alpha_h), alpha_h the angle between
l and h, here with Schlick's approximation R_F(alpha_h) = R_F(0) + (1 - R_F(0)) (1 - l.h)^5
(Schlick 1994 eq. 15; RTR3 eq. 7.33). A brick of its own, not an option of
`blinn_phong_normalized`, so that brick's generated code (and goldens) stay as they are.
Reciprocal (l.h = v.h). Equals `blinn_phong_normalized` where l.h = 1 and for f0 = 1.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, normalized Blinn-Phong with R_F(alpha_h); Schlick 1994 eq. 15",
    "params": {
        "n": {"type": "float", "range": [1.0, 100000.0], "default": 64.0, "doc": "Blinn-Phong cosine power"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04], "doc": "R_F(0), Fresnel reflectance at normal incidence"},
    },
    "needs": ["NdotH", "LdotH"],
}


def specular(NdotH: float, LdotH: float, n: float, f0: vec3) -> vec3:
    # LdotH arrives clamped to [0, 1]; the fifth power is multiplied out (pow(0, 5) through
    # exp2/log2 is undefined in GLSL at l.h = 1).
    c = 1.0 - LdotH
    c2 = c * c
    fresnel = f0 + (vec3(1.0) - f0) * (c2 * c2 * c)
    return fresnel * ((n + 4.0) / (8.0 * PI) * pow(NdotH, n))


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
