"""Cost stand-in normal: the interpolated normal, unchanged.

Not a model: the baseline a normal brick is measured against.
"""
BRICK = {
    "kind": "normal",
    "cite": "shadermatrix cost baseline (no model)",
}


def normal(N: vec3) -> vec3:
    return N
