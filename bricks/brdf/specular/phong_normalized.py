"""Normalized Phong specular: f_r = (n + 2) / (2 pi) * R_F(0) * (cos alpha_r)^n.

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", normalized
Phong specular term, (n+2)/2pi normalization; alpha_r is the angle between
the view vector and the mirror reflection of L about N.
Directional albedo at normal incidence is R_F(0) (ACCURACY-FACTS §4.2).

fp16: about 10 % hemisphere error at the default n (x^n multiplies half's rounding by n);
n = 1e5 is inf in half. Keep n <= 1e4 in fp16 permutations.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, normalized Phong: (n+2)/(2 pi) R_F(0) cos^n(alpha_r)",
    "params": {
        "n": {"type": "float", "range": [1.0, 100000.0], "default": 32.0, "doc": "Phong cosine power"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04], "doc": "R_F(0), Fresnel reflectance at normal incidence"},
    },
    "needs": ["RdotV"],
}


def specular(RdotV: float, n: float, f0: vec3) -> vec3:
    # RdotV arrives clamped to [0, 1]: pow of a negative base is undefined, and a
    # dot slightly above 1 (fp32 rounding) would push the lobe above its peak.
    return f0 * ((n + 2.0) * INV_TWO_PI * pow(RdotV, n))
