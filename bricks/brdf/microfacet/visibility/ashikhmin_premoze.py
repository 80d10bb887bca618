"""Ashikhmin & Premoze visibility term: V = 1 / (4 (n.l + n.v - (n.l)(n.v))).

Ashikhmin & Premoze 2007, "Distribution-based BRDFs"; RTR3 §7.6.1 (seed 001, p. 261): the
visibility term 1 / (cos theta_i + cos theta_o - cos theta_i cos theta_o), a continuous
alternative to Neumann's max; divided by 4 as every visibility filler (ACCURACY-FACTS §4.11;
Filament's V_Neubelt). Reciprocal (symmetric). No guard: n.l + n.v - n.l n.v = n.l + n.v (1 - n.l)
>= max(n.l, n.v) >= 1e-4 for cosines in [0, 1].
"""
BRICK = {
    "kind": "visibility",
    "cite": "Ashikhmin & Premoze 2007; RTR3 §7.6.1 p. 261",
}


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    return 0.25 / (NdotL + NdotV - NdotL * NdotV)
