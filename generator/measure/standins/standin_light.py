"""Cost stand-in light: direction and radiance are parameters, used as given.

Not a model: the one light of the synthetic permutation in which light,
shadow, packing, normal and output bricks are measured.
"""
BRICK = {
    "kind": "light",
    "cite": "shadermatrix cost baseline (no model)",
    "params": {
        "direction": {"type": "vec3", "range": [-1.0, 1.0], "default": [0.0, 0.0, 1.0]},
        "color": {"type": "vec3", "range": [0.0, 1000000.0], "default": [1.0, 1.0, 1.0]},
    },
}


def light_dir(P: vec3, direction: vec3) -> vec3:
    return direction


def light_radiance(P: vec3, color: vec3) -> vec3:
    return color
