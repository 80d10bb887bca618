"""Linear output: write linear RGB radiance with alpha 1 (the target is an sRGB or float framebuffer).

Hoffman & Baker 2006: shading happens in linear space; encoding is left to the framebuffer.
"""
BRICK = {
    "kind": "output",
    "cite": "Hoffman & Baker 2006, linear-space shading",
}


def output(color: vec3) -> vec4:
    return vec4(color, 1.0)
