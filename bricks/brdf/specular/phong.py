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
    "reciprocal": "no: the 1/cos theta_i of the original Phong written as a BRDF reads n.l alone (Hoffman & Baker 2006; phong_reciprocal removes it)",
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


# Sampling (the contract: library/kinds.py): the lobe (r.v)^n about the mirror direction r of v, by the
# course's cos^alpha sampler (Bikker 2017, "Fixing Phong": z = xi^(1/(alpha+1)), phi = 2 pi xi'; Lafortune &
# Willems 1994), whose density is (n + 1)/(2 pi) (r.l)^n per unit solid angle over the sphere. The course's
# (alpha + 2)/(2 pi) cos^alpha is the BRDF's normalization, not this sampler's density (the test of a wrong
# pdf uses it). The part of the lobe below the horizon is returned as drawn (the caller scores it 0): pdf
# integrates to 1 minus that mass.
def lobe_frame(a: vec3, x: float, y: float, z: float) -> vec3:
    # (x, y, z) in an orthonormal frame about the unit axis a, with no branch on a reference axis (Duff et al.
    # 2017, "Building an Orthonormal Basis, Revisited", listing 3)
    s = 1.0 if a.z >= 0.0 else -1.0
    k = -1.0 / (s + a.z)
    b = a.x * a.y * k
    t = vec3(1.0 + s * a.x * a.x * k, s * b, -s * a.x)
    w = vec3(b, s + a.y * a.y * k, -a.y)
    return t * x + w * y + a * z


def sample(u: vec2, V: vec3, N: vec3, n: float) -> vec3:
    c = pow(u.x, 1.0 / (n + 1.0))
    s = sqrt(max(1.0 - c * c, 0.0))
    phi = TWO_PI * u.y
    return lobe_frame(reflect(-V, N), s * cos(phi), s * sin(phi), c)


def pdf(L: vec3, V: vec3, N: vec3, n: float) -> float:
    c = dot(reflect(-V, N), L)
    return (n + 1.0) * INV_TWO_PI * pow(c, n) if c > 0.0 and dot(N, L) > 0.0 else 0.0
