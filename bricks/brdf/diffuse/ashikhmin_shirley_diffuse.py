"""Ashikhmin-Shirley diffuse: f_r = 28 rho_d/(23 pi) (1 - R_s)(1 - (1 - n.l/2)^5)(1 - (1 - n.v/2)^5).

Ashikhmin & Shirley 2000, "An Anisotropic Phong BRDF Model", eq. 5 (the diffuse term of the
coupled model; R_s = f0, the specular reflectance at normal incidence). The 28/23 makes the
directional albedo closed-form: E(theta) = rho_d (1 - f0)(1 - (1 - cos theta/2)^5)
(ACCURACY-FACTS §4.9: 0.968750, 0.887108, 0.365002 at 0°, 45°, 80° for rho_d = 1, f0 = 0).
Reciprocal. The fifth powers are expanded, 1 - (1 - y)^5 = y (5 - 10y + 10y^2 - 5y^3 + y^4) with
y = cos/2, so they keep their relative digits at grazing (the direct form loses them below
cos = 1e-3 in float32). No guard needed: every factor is a polynomial of bounded cosines.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Ashikhmin & Shirley 2000 eq. 5",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_s, the specular reflectance at normal incidence"},
    },
    "needs": ["NdotL", "NdotV"],
}


def one_minus_pow5_complement(x: float) -> float:
    # 1 - (1 - x)^5, expanded (Horner): no cancellation at small x
    return x * (5.0 + x * (-10.0 + x * (10.0 + x * (-5.0 + x))))


def diffuse(NdotL: float, NdotV: float, rho_d: vec3, f0: vec3) -> vec3:
    k = one_minus_pow5_complement(0.5 * NdotL) * one_minus_pow5_complement(0.5 * NdotV)
    return rho_d * (vec3(1.0) - f0) * (28.0 / (23.0 * PI) * k)
