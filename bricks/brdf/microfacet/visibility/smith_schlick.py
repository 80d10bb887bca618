"""Schlick's approximation of the Smith geometry factor, as a visibility term.

G = (n.l / ((n.l)(1 - k) + k)) (n.v / ((n.v)(1 - k) + k)), k = m sqrt(2/pi)
(Schlick 1994; RTR3 eq. 7.56, m the Beckmann RMS slope = alpha). Divided by
4 (n.l)(n.v), the cosines cancel: V = 1 / (4 ((n.l)(1-k)+k) ((n.v)(1-k)+k)).

fp16: the 1e-8 floor is 0 in half, which is harmless for alpha > 0.
"""
BRICK = {
    "kind": "visibility",
    "cite": "Schlick 1994; RTR3 eq. 7.56 with k = m sqrt(2/pi)",
}

SQRT_2_OVER_PI = 0.7978845608028654


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    k = alpha * SQRT_2_OVER_PI
    gl = NdotL * (1.0 - k) + k
    gv = NdotV * (1.0 - k) + k
    # Both factors are >= min(k, n.x) > 0 for n.v >= 1e-4 (the caller's clamp), except alpha = 0 and
    # n.l = 0; the product is floored at 1e-8 for that corner. Cost: none for alpha >= 1e-4, where
    # 4 gl gv >= 4 k (1e-4 + k) = 5.7e-8 (the NDFs floor alpha at 1e-4 as well).
    return 1.0 / max(4.0 * gl * gv, 0.00000001)
