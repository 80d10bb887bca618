"""Exact height-correlated Smith masking-shadowing for GGX, as a visibility term.

G = 1 / (1 + Lambda(l) + Lambda(v)) (Heitz 2014 eq. 99), Lambda = (-1 + sqrt(1 + alpha^2 tan^2 theta))
/ 2 (Heitz 2014 eq. 86). Divided by 4 (n.l)(n.v):
V = 0.5 / ((n.l) sqrt((n.v)^2 (1 - alpha^2) + alpha^2) + (n.v) sqrt((n.l)^2 (1 - alpha^2) + alpha^2))
(ACCURACY-FACTS §4.11; Filament's V_SmithGGXCorrelated; no tan, no division by a cosine).
At n.l = n.v = 1 it is 1/4; at alpha = 1, 1 / (2 (n.l + n.v)).
alpha is the GGX roughness of the host (with an anisotropic NDF: see ggx_anisotropic.py).
"""
BRICK = {
    "kind": "visibility",
    "cite": "Heitz 2014 eq. 99 with eq. 86",
}

# alpha is floored at 1e-4 (as the NDFs): at alpha = 0 and n.l = 0 the denominator is 0.
# Cost: alpha < 1e-4 masks as 1e-4; V <= 0.5 / (1e-4 * 1e-4) = 5e7.
ALPHA_MIN = 0.0001


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    a = max(alpha, ALPHA_MIN)
    a2 = a * a
    lv = NdotL * sqrt(NdotV * NdotV * (1.0 - a2) + a2)
    ll = NdotV * sqrt(NdotL * NdotL * (1.0 - a2) + a2)
    return 0.5 / (lv + ll)
