"""Directional light: constant direction and "game intensity" c_light.

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", rendering with
point lights: L_o = sum_k pi f_r(l_k, v) c_light,k cos theta_k; a directional
light has no distance falloff (i_l(d_l) = c_light).
"""
BRICK = {
    "kind": "light",
    "cite": "Hoffman & Baker 2006, game point-light equation with i_l(d) = c_light",
    "params": {
        "direction": {"type": "vec3", "range": [-1.0, 1.0], "default": [0.0, 0.0, 1.0], "doc": "unit vector from the surface toward the light"},
        "color": {"type": "vec3", "range": [0.0, 1000000.0], "default": [1.0, 1.0, 1.0], "doc": "c_light, linear RGB game intensity"},
    },
}


def light_dir(P: vec3, direction: vec3) -> vec3:
    return normalize(direction)


def light_radiance(P: vec3, color: vec3) -> vec3:
    return color
