"""Implicit geometry factor: G = (n.l)(n.v), so V = G / (4 (n.l)(n.v)) = 1/4.

RTR3 §7.6.1 eq. 7.53: the implicit G cancels the foreshortening denominator.
"""
BRICK = {
    "kind": "visibility",
    "cite": "RTR3 eq. 7.53",
}


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    return 0.25
