"""GGX / Trowbridge-Reitz normal distribution: D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2).

Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces",
eq. 33 (written with cos theta_h instead of tan theta_h); Trowbridge & Reitz 1975.
"""
BRICK = {
    "kind": "ndf",
    "cite": "Walter et al. 2007 eq. 33; Trowbridge & Reitz 1975",
}


def ndf(NdotH: float, alpha: float) -> float:
    # alpha is floored at 1e-3: below it the peak 1/(pi alpha^2) loses all its
    # digits in fp32 through the cancellation in the denominator (ACCURACY-FACTS pitfall 4).
    a = max(alpha, 0.001)
    a2 = a * a
    d = NdotH * NdotH * (a2 - 1.0) + 1.0
    return a2 / (PI * d * d)
