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
