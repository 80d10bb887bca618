"""Exact Fresnel reflectance of a conductor with complex index eta + i k (per RGB channel).

The Fresnel equations for unpolarized light at a complex index (Born & Wolf, Principles of
Optics, §14.2), in the real-arithmetic form of pbrt-v3 §8.2.1 (FrConductor; also Mitsuba's
and MaterialX's, ACCURACY-FACTS §4.12):
  a^2 + b^2 = sqrt((eta^2 - k^2 - sin^2)^2 + 4 eta^2 k^2),  a^2 = (a^2 + b^2 + eta^2 - k^2 - sin^2) / 2,
  R_s = (a^2 + b^2 - 2 a cos + cos^2) / (a^2 + b^2 + 2 a cos + cos^2),
  R_p = R_s (cos^2 (a^2 + b^2) - 2 a cos sin^2 + sin^4) / (cos^2 (a^2 + b^2) + 2 a cos sin^2 + sin^4),
  F = (R_s + R_p) / 2,  cos = v.h.
Numerators and denominators are written as the sums of squares they are, so nothing
cancels: a^2 + b^2 - 2 a c + c^2 = (a - c)^2 + b^2 and c^2 (a^2 + b^2) -+ 2 a c sin^2 + sin^4
= (a c -+ sin^2)^2 + b^2 c^2; a^2 and b^2 = ((a^2 + b^2) - (eta^2 - k^2 - sin^2)) / 2 are taken
from whichever of the two is a sum, the other as 2 eta^2 k^2 over it (their product is
eta^2 k^2), so k -> 0 keeps its digits (k = 0: the dielectric of index eta; ACCURACY-FACTS §4.12),
and eta^2 - k^2 - sin^2 is summed as (eta^2 - k^2 - 1) + cos^2.

Parameters eta, k (vec3) are the conductor's optical constants per RGB channel (default: gold,
eta = (0.143, 0.375, 1.442), k = (3.983, 2.386, 1.603), the RGB reduction of measured Au data
common in renderers' conductor tables; f0 = (0.967, 0.802, 0.324)). The slot contract passes
f0, which this filler ignores: its normal-incidence reflectance is ((eta-1)^2 + k^2) /
((eta+1)^2 + k^2), set by eta and k.
Measured in float32 within the microfacet host: 1.2e-6 on the hemisphere on every target; the
Fresnel factor alone is within 3e-6 of float64 for gold, k = 0 and eta = 1 (tests/library/test_library_fillers.py).
"""
BRICK = {
    "kind": "fresnel",
    "cite": "Born & Wolf §14.2; pbrt-v3 §8.2.1 (FrConductor)",
    "params": {
        "eta": {"type": "vec3", "range": [0.01, 10.0], "default": [0.143119, 0.374957, 1.44248],
                "doc": "real part of the complex refractive index, per RGB channel"},
        "k": {"type": "vec3", "range": [0.0, 20.0], "default": [3.98316, 2.38572, 1.60322],
              "doc": "extinction coefficient (imaginary part of the index), per RGB channel"},
    },
}

# v.h is floored at 1e-9 so that t^2 = (c^2)^2 stays a normal float32 at eta = 1, k = 0 (t = c^2; an
# underflow would make a != c there and F ~ 1 instead of 0). Cost: v.h < 1e-9 (only near l = -v) is
# evaluated at 1e-9, where F differs from F(0) = 1 by O(1e-9).
COS_MIN = 1e-9
# The sums a2 + b2 +- t are floored at 1e-30 before dividing by them: both are 0 only where
# eta^2 k^2 = 0 and the other sum is 0, i.e. k = 0 with t = eta^2 - sin^2 = 0 (grazing at eta = 1).
# Cost: none (the quotient 2 eta^2 k^2 / sum is then 0/1e-30 = 0, its limit).
SUM_MIN = 1e-30
# The two denominators are floored at 1e-30: they vanish only at cos = 0 with a = b = 0, i.e. the
# degenerate index eta = 1, k = 0 at grazing (R_s = 0/0). Cost: F = 0 there instead of 1.
DEN_MIN = 1e-30


def fresnel(f0: vec3, VdotH: float, eta: vec3, k: vec3) -> vec3:
    c = max(VdotH, COS_MIN)
    c2 = c * c
    s2 = max(1.0 - c2, 0.0)
    e2 = eta * eta
    k2 = k * k
    # t = eta^2 - k^2 - sin^2, summed as (eta^2 - k^2 - 1) + cos^2 (Cook & Torrance's g^2 = eta^2 - 1 + c^2):
    # at eta = 1, k = 0 it is c^2 exactly (a = c, F = 0: no interface) instead of 1 - (1 - c^2).
    t = (e2 - k2 - vec3(1.0)) + vec3(c2)
    ab2 = sqrt(t * t + 4.0 * e2 * k2)  # a^2 + b^2
    plus = max(ab2 + t, SUM_MIN)
    minus = max(ab2 - t, SUM_MIN)
    # Per channel, pick the form without cancellation: w = 1 where t >= 0 (a^2 from the sum), else 0.
    # Written as w x + (1 - w) y, not mix(), so that the chosen form is taken exactly.
    w = step(vec3(0.0), t)
    a2 = w * (0.5 * plus) + (vec3(1.0) - w) * (2.0 * e2 * k2 / minus)
    b2 = w * (2.0 * e2 * k2 / plus) + (vec3(1.0) - w) * (0.5 * minus)
    a = sqrt(a2)
    am = a - vec3(c)
    ap = a + vec3(c)
    rs = (am * am + b2) / max(ap * ap + b2, DEN_MIN)
    pm = a * c - vec3(s2)
    pp = a * c + vec3(s2)
    bc2 = b2 * c2
    rp = rs * (pm * pm + bc2) / max(pp * pp + bc2, DEN_MIN)
    return 0.5 * (rs + rp)
