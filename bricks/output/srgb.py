"""Exact sRGB encoding, piecewise: V = 12.92 L for L ≤ 0.0031308, else 1.055 L^(1/2.4) − 0.055; alpha 1.

IEC 61966-2-1:1999 (sRGB), the encoding (inverse) of the display transfer function, applied
per channel to saturate(color). For a UNORM render target: an _SRGB target encodes in
hardware, and `linear` is the brick for it.

Error against the float64 encoding (generator/reference/outputs.py), measured by
tests/library/test_lights_packings_outputs.py: 0 by definition in float64; in float32 at most
1.5e-7 in NumPy (10⁶ + 1 points of [0, 1]) and 2.1e-7 on lavapipe in GLSL, HLSL and WGSL
alike (4,600 points, denser below the threshold): about 2 ulp at 1, far below an 8-bit
code (1/255 = 3.9e-3). For comparison, over [0, 1]: the course's `sqrt_gamma` is off by
up to 0.0374 (x = 0.213), a pure 2.2 power by 0.0335 (x = 0.0022), and `linear` written to
a UNORM target without encoding by 0.287 (x = 0.244); `linear` to an sRGB target is
encoded by the hardware. The saturate clips what a UNORM target would clip and keeps
pow's base non-negative (pow of a negative base is undefined in GLSL and HLSL).
"""
BRICK = {
    "kind": "output",
    "encodes": "srgb",  # display-encoded: a UNORM attachment stores it (an _SRGB one would encode it twice)
    "cite": "IEC 61966-2-1:1999 sRGB encoding (piecewise)",
}


def encode(x: float) -> float:
    return 12.92 * x if x <= 0.0031308 else 1.055 * pow(x, 1.0 / 2.4) - 0.055


def output(color: vec3) -> vec4:
    c = saturate(color)
    return vec4(encode(c.x), encode(c.y), encode(c.z), 1.0)
