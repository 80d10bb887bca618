"""Schlick's Fresnel approximation: F = f0 + (1 - f0) (1 - v.h)^5.

Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering", eq. 15;
RTR3 eq. 7.40. The fifth power is written as multiplications (no pow(0, 0)).

fp16: safe.
"""
BRICK = {
    "kind": "fresnel",
    "cite": "Schlick 1994 eq. 15; RTR3 eq. 7.40",
}


def fresnel(f0: vec3, VdotH: float) -> vec3:
    # 1 - v.h is clamped to [0, 1]: a v.h slightly above 1 from rounding must not
    # produce a negative fifth power.
    x = clamp(1.0 - VdotH, 0.0, 1.0)
    x2 = x * x
    return f0 + (vec3(1.0) - f0) * (x2 * x2 * x)
