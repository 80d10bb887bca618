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
