"""Minnaert diffuse: f_r = rho_d / pi * (cos theta_i cos theta_r)^(k - 1).

Minnaert 1941, "The reciprocity principle in lunar photometry", Astrophysical Journal 93, eq. 1;
k = 1 is Lambert, k < 1 brightens towards the limb (the Moon's flat look), k > 1 darkens it.
Reciprocal: symmetric in n.l and n.v. Directional albedo E(mu) = rho_d 2 (mu)^(k - 1) / (k + 1).

The example brick of docs/contributing/adding-a-brick.md: an engine's brick, loaded with
`--bricks docs/contributing/bricks`.

fp16: unsafe, and declared so below: the floor of n.l n.v, 1e-8, is 0 in half (its smallest subnormal is
6e-8), where pow(0, k - 1) is infinite for k < 1.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Minnaert 1941, ApJ 93, eq. 1: rho_d/pi (cos theta_i cos theta_r)^(k-1)",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "k": {"type": "float", "range": [0.5, 1.5], "default": 0.8, "doc": "Minnaert exponent (1: Lambert)"},
    },
    "needs": ["NdotL", "NdotV"],
    "fp16": "unsafe: the floor 1e-8 of n.l n.v is 0 in half, and pow(0, k - 1) is inf for k < 1",
}

# n.l n.v is floored at 1e-8 (n.v alone is clamped to 1e-4 by the shading policy): pow of 0 with a
# negative exponent (k < 1) is infinite. Cost: below cosines of 1e-4 each, f_r stops growing.
COS_PRODUCT_MIN = 1e-8


def diffuse(NdotL: float, NdotV: float, rho_d: vec3, k: float) -> vec3:
    return rho_d * (INV_PI * pow(max(NdotL * NdotV, COS_PRODUCT_MIN), k - 1.0))
