"""Exact separable Smith masking-shadowing for GGX, as a visibility term.

G = G1(l) G1(v) (Walter et al. 2007 eq. 23; Heitz 2014 eq. 98), G1(x) = 2 / (1 + sqrt(1 + alpha^2
tan^2 theta_x)) (Walter et al. 2007 eq. 34), i.e. G1 = 2 (n.x) / (n.x + sqrt(alpha^2 + (1 - alpha^2)
(n.x)^2)). Divided by 4 (n.l)(n.v), the cosines cancel (no tan, no division by a cosine;
ACCURACY-FACTS pitfall 7):
V = 1 / ((n.l + sqrt(alpha^2 + (1 - alpha^2)(n.l)^2)) (n.v + sqrt(alpha^2 + (1 - alpha^2)(n.v)^2))).
alpha is the GGX roughness of the host (with an anisotropic NDF: see ggx_anisotropic.py).
"""
BRICK = {
    "kind": "visibility",
    "cite": "Walter et al. 2007 eq. 23 and eq. 34; Heitz 2014 eq. 98",
}

# alpha is floored at 1e-4 (as the NDFs): at alpha = 0 and n.l = 0 both factors of the first
# bracket vanish (V = 1/0). Cost: alpha < 1e-4 masks as 1e-4; V <= 1/(1e-4 * 2e-4) = 5e7.
ALPHA_MIN = 0.0001


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    a = max(alpha, ALPHA_MIN)
    a2 = a * a
    gl = NdotL + sqrt(a2 + (1.0 - a2) * (NdotL * NdotL))
    gv = NdotV + sqrt(a2 + (1.0 - a2) * (NdotV * NdotV))
    return 1.0 / (gl * gv)
