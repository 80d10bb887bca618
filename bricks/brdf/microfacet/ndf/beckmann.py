"""Beckmann normal distribution: D = exp(-tan^2 theta_h / m^2) / (pi m^2 cos^4 theta_h).

Beckmann & Spizzichino 1963; Cook & Torrance 1982 eq. 5 (with the 1/pi that
normalizes the projected area, Walter et al. 2007 eq. 25); alpha is the RMS slope m.
"""
BRICK = {
    "kind": "ndf",
    "cite": "Cook & Torrance 1982 eq. 5; normalized form Walter et al. 2007 eq. 25",
}


def ndf(NdotH: float, alpha: float) -> float:
    # cos^2 is floored at 1e-8 so that at n.h = 0 the exponent is -inf-like and D
    # is exactly 0 instead of 0/0 (ACCURACY-FACTS pitfall 9); alpha is floored at
    # 1e-3 so that 1/alpha^2 stays finite.
    a2 = max(alpha * alpha, 0.000001)
    c2 = max(NdotH * NdotH, 0.00000001)
    tan2 = (1.0 - c2) / c2
    return exp(-tan2 / a2) / (PI * a2 * c2 * c2)
