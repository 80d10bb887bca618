"""Oren-Nayar with Fresnel (Gotanda 2014 eq. 7 with F_diff of eq. 6): f_r = rho_d/pi (1 - f0) [F_diff A + B b].

Gotanda 2014, "Designing Reflectance Models for New Consoles", eq. 7,
L_r = rho/pi E0 (1 - f0) [F_diff(l, e)(n.l) A + B s min(1, n.l/n.e)], with A, B, s as in eq. 5
(`oren_nayar_improved`: A = 1 - 0.5 sigma^2/(sigma^2 + 0.65), B = 0.45 sigma^2/(sigma^2 + 0.09),
s = e.l - (n.e)(n.l)), and eq. 6 (Shirley et al. 1997 without its 1/pi)
F_diff = 21/20 (1 - f0)(1 - (1 - n.l)^5)(1 - (1 - n.e)^5). As a BRDF (over E0 n.l):
  f_r = max(0, rho_d/pi (1 - f0) [F_diff A + B b]), b = s/max(n.l, n.e) for s >= 0, s otherwise.
Decisions, all as printed unless said:
- (1 - f0) appears twice, outside the bracket and inside F_diff: the A term carries (1 - f0)^2, the
  B term (1 - f0). Kept as printed.
- eq. 7 prints only eq. 5's s >= 0 case (min(1, n.l/n.e)); it is eq. 5 with eq. 6 added ("Then,
  Oren-Nayar with Equation 6 becomes"), so s < 0 takes eq. 5's other case, b = s (read as in
  `oren_nayar_improved`).
- F_diff -> 0 at grazing while B b < 0 on the backward side: the bracket goes negative there
  (e.g. n.l -> 0 with e.l < 0). A radiance cannot be negative: clamped at 0, per channel. Cost:
  the model is black where it would be negative; near that boundary the value is a difference of
  two terms, so its relative error in float32 is unbounded (the absolute error is not).
The fifth powers are expanded, 1 - (1 - x)^5 = x (5 - 10x + 10x^2 - 5x^3 + x^4), so they keep their
relative digits at grazing (1 - (1 - x)^5 loses them for x < 1e-3 in float32).
Reciprocal (symmetric in l and e); sigma = 0, f0 = 0 is 21/20 Lambert with Fresnel.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Gotanda 2014 eqs. 5-7 (improved Oren-Nayar with the diffuse Fresnel of Shirley et al. 1997)",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "sigma": {"type": "float", "range": [0.0, 1.57], "default": 0.3,
                  "doc": "Oren-Nayar roughness: standard deviation of the facet slope angle (radians)"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "Fresnel reflectance at normal incidence"},
    },
    "needs": ["LdotV", "NdotL", "NdotV"],
}


def one_minus_pow5_complement(x: float) -> float:
    # 1 - (1 - x)^5, expanded (Horner): no cancellation at small x
    return x * (5.0 + x * (-10.0 + x * (10.0 + x * (-5.0 + x))))


def diffuse(NdotL: float, NdotV: float, LdotV: float, rho_d: vec3, sigma: float, f0: vec3) -> vec3:
    s2 = sigma * sigma
    A = 1.0 - 0.5 * s2 / (s2 + 0.65)
    B = 0.45 * s2 / (s2 + 0.09)
    s = LdotV - NdotV * NdotL
    b = s / max(NdotL, NdotV) if s >= 0.0 else s
    F_diff = (1.05 * (one_minus_pow5_complement(NdotL) * one_minus_pow5_complement(NdotV))) * (vec3(1.0) - f0)
    bracket = F_diff * A + vec3(B * b)
    return max(rho_d * INV_PI * (vec3(1.0) - f0) * bracket, vec3(0.0))
