"""Neumann et al. visibility term: V = 1 / (4 max(n.l, n.v)).

Neumann, Neumann & Szirmay-Kalos 1999, "Compact Metallic Reflectance Models"; RTR3 §7.6.1
(seed 001, p. 261): the visibility term 1 / max(cos theta_i, cos theta_o), i.e. G =
min(n.l, n.v); divided by 4 as every visibility filler (ACCURACY-FACTS §4.11).
Reciprocal (symmetric in n.l, n.v). No guard: max(n.l, n.v) >= n.v >= 1e-4 (the glue's clamp).
"""
BRICK = {
    "kind": "visibility",
    "cite": "Neumann et al. 1999; RTR3 §7.6.1 p. 261",
}


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    return 0.25 / max(NdotL, NdotV)
