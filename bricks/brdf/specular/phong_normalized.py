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
