"""Improved Oren-Nayar (Gotanda 2014 eq. 5, from Gotanda 2012): f_r = rho_d/pi (A + B b).

Gotanda 2014, "Designing Reflectance Models for New Consoles", eq. 5, written as radiance
L_r = rho/pi E0 [(n.l) A + B s min(1, n.l/n.e)] for s >= 0, with A = 1 - 0.5 sigma^2/(sigma^2 + 0.65),
B = 0.45 sigma^2/(sigma^2 + 0.09), s = e.l - (n.e)(n.l) (= sin theta_i sin theta_e cos phi: the
qualitative model's cos phi without a tangent frame). As a BRDF, f_r = L_r / (E0 n.l):
  s >= 0:  b = s min(1, n.l/n.e) / n.l = s / max(n.l, n.e)   (= cos phi sin(alpha) tan(beta));
  s < 0:   b = s.
The second case: eq. 5 prints "rho/pi E0 [(n.l)(1 - ...) + (0.45 ...)(e.l - (n.e)(n.l))]", with no n.l
on the B term. Read literally (f_r = rho/pi (A + B s / n.l)) the radiance is negative at grazing
light on the backward side (n.l -> 0, s < 0: L_r -> rho/pi E0 B s); we read it as
rho/pi E0 (n.l)(A + B s), f_r = rho/pi (A + B s), positive (A >= 0.5 > 0.45 >= B |s|),
reciprocal, and what UE4's Diffuse_OrenNayar [Gotanda 2012] computes. sigma in radians;
sigma = 0 is Lambert.

Guard: max(n.l, n.e) >= n.e >= 1e-4 (the shading policy's clamp): no floor of its own.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Gotanda 2014 eq. 5 (improved Oren-Nayar of Gotanda 2012)",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "sigma": {"type": "float", "range": [0.0, 1.57], "default": 0.3,
                  "doc": "Oren-Nayar roughness: standard deviation of the facet slope angle (radians)"},
    },
    "needs": ["LdotV", "NdotL", "NdotV"],
}


def diffuse(NdotL: float, NdotV: float, LdotV: float, rho_d: vec3, sigma: float) -> vec3:
    s2 = sigma * sigma
    A = 1.0 - 0.5 * s2 / (s2 + 0.65)
    B = 0.45 * s2 / (s2 + 0.09)
    s = LdotV - NdotV * NdotL
    b = s / max(NdotL, NdotV) if s >= 0.0 else s
    return rho_d * (INV_PI * (A + B * b))
