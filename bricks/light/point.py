"""Point light with inverse-square falloff: c_light(d) = color / d^2.

Hoffman & Baker 2006, "Physically-Based Reflectance for Games": a point light's
game intensity i_l(d_l) at distance d_l; here the physical 1/d^2 falloff with
`color` the intensity at unit distance.
"""
BRICK = {
    "kind": "light",
    "cite": "Hoffman & Baker 2006, point light game intensity i_l(d_l); inverse-square falloff",
    "params": {
        "position": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 2.0, 0.0], "doc": "world-space position"},
        "color": {"type": "vec3", "range": [0.0, 1000000.0], "default": [1.0, 1.0, 1.0], "doc": "linear RGB intensity at unit distance"},
    },
}


def light_dir(P: vec3, position: vec3) -> vec3:
    return normalize(position - P)


def light_radiance(P: vec3, position: vec3, color: vec3) -> vec3:
    d = position - P
    # d^2 is floored at 1e-4 (1 cm at metre scale): a surface point on the light
    # would otherwise divide by zero.
    return color / max(dot(d, d), 0.0001)
