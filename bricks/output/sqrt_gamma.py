"""Square-root gamma: write sqrt(saturate(color)) with alpha 1 (Hoffman & Baker 2006, "Gamma Conversion").

The course's pixel shaders end in `return Gamma(saturate(Out));` with
`float4 Gamma(float4 linear) { return sqrt(linear); }`: "square-root is cheaper than a
power function on most GPUs — not exactly the transfer function, but close enough".
For a UNORM (not sRGB) render target, which stores what is written.

Error against the exact sRGB encoding (IEC 61966-2-1; the `srgb` brick), measured over
10⁶ + 1 points of [0, 1] in float64 (tests/library/test_lights_packings_outputs.py): max
|sqrt(x) − sRGB(x)| = 0.0374 at x = 0.213 (sqrt is darker there: 0.462 against 0.499),
+0.0193 at x = 0.0015 on the other side; 9.5 codes of an 8-bit target (10 after rounding
both to codes). The saturate is the course's: it keeps sqrt of a negative undefined value
out, and values above 1 are clipped as a UNORM target would.
"""
BRICK = {
    "kind": "output",
    "encodes": "sqrt",  # display-encoded: a UNORM attachment stores it (an _SRGB one would encode it twice)
    "cite": "Hoffman & Baker 2006, Gamma Conversion: sqrt(linear)",
}


def output(color: vec3) -> vec4:
    return vec4(sqrt(saturate(color)), 1.0)
