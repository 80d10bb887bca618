"""Lambertian diffuse: f_r = rho_d / pi.

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", the diffuse
term of the normalized Phong BRDF (rho_d / pi); RTR3 §7.5.2 eq. 7.36.
Directional albedo equals rho_d at every angle of incidence.

fp16: safe (one product; 1.6e-4 hemisphere error on lavapipe).
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Hoffman & Baker 2006, normalized Phong diffuse term rho_d/pi; RTR3 eq. 7.36",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
    },
    "needs": [],
}


def diffuse(rho_d: vec3) -> vec3:
    return rho_d * INV_PI


# Sampling (the contract: library/kinds.py). Cosine-weighted: the density cos theta / pi is proportional to
# f_r cos theta, so the estimator f cos / pdf = rho_d is exact (zero variance). Malley's method: a uniform
# point of the unit disk, by u = (r^2, phi / 2 pi), lifted to the hemisphere (pbrt-v3 §13.6.3; the course's
# cosine-weighted sampler).
def sample(u: vec2, N: vec3, T: vec3, B: vec3) -> vec3:
    r = sqrt(u.x)
    phi = TWO_PI * u.y
    return T * (r * cos(phi)) + B * (r * sin(phi)) + N * sqrt(max(1.0 - u.x, 0.0))


def pdf(L: vec3, N: vec3) -> float:
    c = dot(N, L)
    return c * INV_PI if c > 0.0 else 0.0
