"""Cost stand-in output: the color with alpha 1, nothing else.

Not a model: the baseline an output brick is measured against.
"""
BRICK = {
    "kind": "output",
    "cite": "shadermatrix cost baseline (no model)",
}


def output(color: vec3) -> vec4:
    return vec4(color, 1.0)
