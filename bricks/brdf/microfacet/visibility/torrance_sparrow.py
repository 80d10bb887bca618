"""Torrance-Sparrow (V-cavity) geometry factor as a visibility term.

G = min(1, 2 (n.h)(n.v) / (v.h), 2 (n.h)(n.l) / (v.h)) (Torrance & Sparrow 1967;
Blinn 1977; RTR3 eq. 7.54), and V = G / (4 (n.l)(n.v)).
"""
BRICK = {
    "kind": "visibility",
    "cite": "Torrance & Sparrow 1967; RTR3 eq. 7.54",
}


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    # v.h is floored at 1e-4: it is 0 only for l = -v, where G is 0/0 (and n.h = 0 makes G 0).
    # n.l is floored at 1e-4 like n.v (the caller's clamp): at the grazing mirror direction
    # (h = n, G = 1) f grows as 1/(n.l n.v) (ACCURACY-FACTS pitfall 3b) and overflows float32
    # for n.l -> 0; floored, f is capped at D F / 4e-8 and stays reciprocal. Cost, measured:
    # none for n.l >= 1e-4; below, f is scaled by n.l / 1e-4 where G = 1 (0.999 relative
    # error at the mirror direction with n.l = 1e-7), while f cos(theta_l) still -> 0.
    vh = max(VdotH, 0.0001)
    nl = max(NdotL, 0.0001)
    G = min(1.0, min(2.0 * NdotH * NdotV / vh, 2.0 * NdotH * nl / vh))
    return G / (4.0 * nl * NdotV)
