"""Schlick's Smith approximation with Karis' GGX-matched k = alpha / 2, as a visibility term.

G = (n.l / ((n.l)(1 - k) + k)) (n.v / ((n.v)(1 - k) + k)) (Schlick 1994; RTR3 eq. 7.56), with
k = alpha / 2 (Karis 2013, "Real Shading in Unreal Engine 4", the Schlick G1 fitted to Smith GGX
for alpha the GGX roughness; ACCURACY-FACTS §4.11). Divided by 4 (n.l)(n.v), the cosines cancel:
V = 1 / (4 ((n.l)(1-k)+k) ((n.v)(1-k)+k)).
The project's smith_schlick keeps k = alpha sqrt(2/pi) (Schlick's Beckmann fit; docs/design/accuracy.md).
Error against exact separable Smith GGX (smith_ggx_separable), measured in float64
(tests/library/test_library_fillers.py): max |G1 - G1_exact| = 0.140 at alpha = 0.1 (at n.x = 0.104),
0.100 at 0.3, 0.066 at 0.5, and 0 at alpha = 1 (k = 1/2 makes Schlick's G1 = 2c/(1 + c), the exact
one). White furnace E(mu), F = 1, mu = 1 / 0.5 / 0.1: 0.9843 / 0.8897 / 0.6577 at alpha = 0.1 and
0.6614 / 0.6077 / 0.6871 at 0.5, against 0.9883 / 0.9691 / 0.8728 and 0.6878 / 0.6860 / 0.7723 for
exact Smith (ACCURACY-FACTS §4.5): it always shadows more, most towards grazing.
"""
BRICK = {
    "kind": "visibility",
    "cite": "Schlick 1994; RTR3 eq. 7.56; k = alpha/2 from Karis 2013",
}


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    k = 0.5 * alpha
    gl = NdotL * (1.0 - k) + k
    gv = NdotV * (1.0 - k) + k
    # Both factors are >= min(k, n.x) > 0 for n.v >= 1e-4 (the caller's clamp), except alpha = 0 and
    # n.l = 0; the product is floored at 1e-8 for that corner, as smith_schlick.py. Cost: none for
    # alpha >= 1e-4, where 4 gl gv >= 4 k (1e-4 + k) = 3e-8.
    return 1.0 / max(4.0 * gl * gv, 0.00000001)
