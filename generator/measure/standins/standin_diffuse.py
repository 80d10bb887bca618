"""Cost stand-in diffuse term: f_r = V, no arithmetic and no parameter.

Not a model: the baseline a diffuse brick is measured against (`shadermatrix
costs --per-brick`), and the companion of a specular brick under measurement.
It returns the view vector unchanged so that V is fetched in every shader
measured: the view vector is an input, never part of a brick's cost.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "shadermatrix cost baseline (no model)",
    "needs": ["V"],
}


def diffuse(V: vec3) -> vec3:
    return V
