"""Blinn-Phong normal distribution: D = (n + 2) / (2 pi) * (n.h)^n, n = 2 / alpha^2 - 2.

RTR3 §7.6.1 eq. 7.48 (normalized Blinn-Phong NDF, (n+2)/2pi); the exponent
is derived from the Beckmann roughness alpha by the equivalence n = 2/alpha^2 - 2
of Walter et al. 2007, eq. 30, so all NDF fillers share one roughness parameter.
"""
BRICK = {
    "kind": "ndf",
    "cite": "RTR3 eq. 7.48; exponent from alpha by Walter et al. 2007 eq. 30",
}


def ndf(NdotH: float, alpha: float) -> float:
    # alpha is floored at 1e-3 so that 2/alpha^2 stays finite (n <= 2e6).
    a = max(alpha, 0.001)
    n = 2.0 / (a * a) - 2.0
    return (n + 2.0) * INV_TWO_PI * pow(NdotH, n)
