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
