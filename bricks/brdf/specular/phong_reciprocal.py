"""Phong specular with the 1/cos theta_i removed: f_r = (k_s / pi) (cos alpha_r)^n.

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", slide "Phong -
First step in making the Phong specular term physically plausible ... remove the cosine
factor": f_rs = (k_s / pi) (cos alpha_r)^n, equivalently the lighting equation with the
cosine factor included, L_e = i_l (k_d cos theta_l + k_s (cos alpha_r)^n cos theta_l).
The second step, normalization by max R_s = R_s(0) = 2 k_s/(n+2) and k_s := R_F(0), is the
brick `phong_normalized`; the original form is `phong`.

Reciprocal (r.v is symmetric in l and v). Directional albedo at normal incidence is
R_s(0) = 2 k_s / (n+2) (the course), its maximum over the angle of incidence.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, Phong with the cosine factor removed: (k_s / pi) (cos alpha_r)^n",
    "params": {
        "n": {"type": "float", "range": [1.0, 100000.0], "default": 32.0, "doc": "Phong cosine power"},
        "k_s": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5],
                "doc": "specular coefficient k_s of the Phong lighting equation (not a reflectance)"},
    },
    "needs": ["RdotV"],
}


def specular(RdotV: float, n: float, k_s: vec3) -> vec3:
    # RdotV arrives clamped to [0, 1] (pow of a negative base is undefined).
    return k_s * (INV_PI * pow(RdotV, n))
