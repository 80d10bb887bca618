"""Cost stand-in specular term: f_r = V, no arithmetic and no parameter.

Not a model: the baseline a specular brick is measured against, and the
companion of a diffuse brick under measurement. It returns the view vector
unchanged so that V is fetched in every shader measured.
"""
BRICK = {
    "kind": "specular",
    "cite": "shadermatrix cost baseline (no model)",
    "needs": ["V"],
}


def specular(V: vec3) -> vec3:
    return V
