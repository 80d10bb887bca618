"""Test brick: a specular term read from a cube map in the mirror direction, f_r = f0 · E(r) / π.

A prefiltered environment lookup in the manner of Kautz & McCool 2000 (cube maps indexed by
the reflected view direction), reduced to one texel fetch so the cube path is tested alone.
"""
BRICK = {
    "kind": "specular",
    "cite": "Kautz & McCool 2000 (environment cube maps indexed by r)",
    "params": {"f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04]}},
    "textures": {"env": {"srgb": False, "doc": "linear RGB, Vulkan face order"}},
}


def specular(V: vec3, N: vec3, f0: vec3, env: texturecube) -> vec3:
    r = reflect(-V, N)
    return f0 * sample_level(env, r, 0.0).xyz * INV_PI
