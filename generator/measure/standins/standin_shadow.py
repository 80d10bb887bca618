"""Cost stand-in shadow: visibility 1 (no shadow test).

Not a model: the baseline a shadow brick is measured against.
"""
BRICK = {
    "kind": "shadow",
    "cite": "shadermatrix cost baseline (no model)",
}


def shadow(P: vec3) -> float:
    return 1.0
