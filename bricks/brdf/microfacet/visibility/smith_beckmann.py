"""Exact separable Smith masking-shadowing for Beckmann, as a visibility term.

G = G1(l) G1(v) (Walter et al. 2007 eq. 23), G1 = 1 / (1 + Lambda), Lambda = (exp(-a^2) / (a sqrt(pi))
- erfc(a)) / 2, a = 1 / (alpha tan theta) (Walter et al. 2007 eq. 27; Heitz 2014 eq. 83), alpha the
Beckmann RMS slope m.

The brick language has no erf. erfc(a) = P(t) exp(-a^2), t = 1 / (1 + 0.3275911 a), P a quintic
(Abramowitz & Stegun 1964, eq. 7.1.26, |error of erfc| <= 1.5e-7 for a >= 0), which turns Lambda into
(cos theta) Lambda = exp(-a^2) (alpha sin theta / sqrt(pi) - cos theta P(t)) / 2
with no division by a, and the visibility term into (the cosines of G / (4 (n.l)(n.v)) cancel):
V = 1 / (4 (n.l + (n.l) Lambda(l)) (n.v + (n.v) Lambda(v))),
finite at n.l = 0 (n.l Lambda -> alpha / (2 sqrt(pi))). The fit's error bounds (cos) Lambda's absolute
error by 7.5e-8 cos theta, so G1 has a relative error below 7.5e-8 (measured against the exact erfc
form: V within 1.4e-7 in float64, 4.2e-7 in float32; tests/library/test_library_fillers.py), far below
Walter et al.'s own rational fit of G1 (eq. 27's (3.535 a + 2.181 a^2) / (1 + 2.276 a + 2.577 a^2),
0.35 %: ACCURACY-FACTS, Mitsuba's).
a >= 10 (Lambda < 1e-44) is evaluated at 10: Lambda underflows there in float32 either way.
"""
BRICK = {
    "kind": "visibility",
    "cite": "Walter et al. 2007 eq. 23 and eq. 27; Abramowitz & Stegun 1964 eq. 7.1.26 (erfc)",
}

# alpha is floored at 1e-4 (as the NDFs): at alpha = 0 and n.l = 0 the first factor is 0.
# Cost: alpha < 1e-4 masks as 1e-4; V <= 1/(4 * 2.8e-5 * 1e-4).
ALPHA_MIN = 0.0001
# alpha sin theta is floored at 1e-30 in a = cos / (alpha sin): it is 0 only at cos = 1 (no masking,
# a = inf). Cost: none (a is then capped at A_MAX, where Lambda is 0 in float32).
AS_MIN = 1e-30
A_MAX = 10.0
INV_SQRT_PI = 0.5641895835477563


def cos_lambda(c: float, alpha: float) -> float:
    s = sqrt(max(1.0 - c * c, 0.0))
    a_s = alpha * s
    a = min(c / max(a_s, AS_MIN), A_MAX)
    t = 1.0 / (1.0 + 0.3275911 * a)
    p = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))))
    return 0.5 * exp(-a * a) * (a_s * INV_SQRT_PI - c * p)


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    a = max(alpha, ALPHA_MIN)
    gl = NdotL + cos_lambda(NdotL, a)
    gv = NdotV + cos_lambda(NdotV, a)
    return 0.25 / (gl * gv)
