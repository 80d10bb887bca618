"""No shadowing: visibility 1.

Hoffman & Baker 2006: the point-light equation's visibility factor, here constant.
"""
BRICK = {
    "kind": "shadow",
    "cite": "Hoffman & Baker 2006 (unshadowed point-light equation)",
}


def shadow(P: vec3) -> float:
    return 1.0
