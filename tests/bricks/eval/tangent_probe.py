"""Test probe, not a shading model: reads the tangent frame and a parameter of each kind.

f = (T.L, B.V, w) * c + (M (L, 1)).xyz, with B = cross(N, T): checks the eval
kernels' sample layout (T is the fourth vec4) and parameter layout (float,
vec3, mat4 in column-major vec4s) against a direct NumPy formula.
"""
BRICK = {
    "kind": "specular",
    "cite": "none (test probe for the eval kernel layout)",
    "params": {
        "w": {"type": "float", "range": [-10.0, 10.0], "default": 0.5},
        "c": {"type": "vec3", "range": [-10.0, 10.0], "default": [1.0, 2.0, 3.0]},
        "m": {"type": "mat4", "default": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0,
                                          0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]},
    },
}


def specular(L: vec3, V: vec3, T: vec3, B: vec3, w: float, c: vec3, m: mat4) -> vec3:
    return vec3(dot(T, L), dot(B, V), w) * c + (m * vec4(L, 1.0)).xyz
