"""Original Phong specular as a BRDF: f_r = k_s (cos alpha_r)^n / (pi cos theta_i).

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", slide "Phong
- Written as a BRDF": the lighting equation L_e = i_l (k_d cos theta_l +
k_s (cos alpha_r)^n) read as the game point-light equation L_e = pi f_r i_l cos theta_l
gives f_r = k_d/pi + k_s (cos alpha_r)^n / (pi cos theta_i); this brick is its specular
term, the first of the course's three steps (its two plausibility steps are the bricks
`phong_reciprocal`, the 1/cos theta_i removed, and `phong_normalized`).
alpha_r is the angle between v and the mirror direction of l about n (RdotV).

It is NOT reciprocal (ACCURACY-FACTS §4.6: max relative asymmetry 3.9e3), and its
directional albedo over the outgoing direction, 2 k_s/(n+2) at normal incidence, grows like
1/cos theta_i: it "goes to infinity at grazing angles" (the course). That is the model.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, Phong written as a BRDF: k_s (cos alpha_r)^n / (pi cos theta_i)",
    "params": {
        "n": {"type": "float", "range": [1.0, 100000.0], "default": 32.0, "doc": "Phong cosine power"},
        "k_s": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5],
                "doc": "specular coefficient k_s of the Phong lighting equation (not a reflectance)"},
    },
    "needs": ["NdotL", "RdotV"],
}

# n.l is floored at 1e-30 before the division: the glue calls a term only for n.l > 0, but a
# float32 n.l of 1e-38 (or a denormal) would make 1/(pi n.l) overflow to inf. Above the floor
# f_r <= k_s / (pi 1e-30) = 3.2e29, finite in float32, and the light loop's f_r cos theta_l stays
# k_s (cos alpha_r)^n / pi. Cost: none measurable (only n.l < 1e-30 is changed).
NL_MIN = 1e-30


def specular(NdotL: float, RdotV: float, n: float, k_s: vec3) -> vec3:
    # RdotV arrives clamped to [0, 1] (pow of a negative base is undefined).
    return k_s * (pow(RdotV, n) * INV_PI / max(NdotL, NL_MIN))
