"""Texture arrays: a layer of a 2D array, of a cube array and of a depth array, for comparing lavapipe's
samplers with the NumPy target's (tests/backends/test_texture_arrays.py)."""
BRICK = {
    "kind": "test",
    "params": {},
}


def layered(t: texture2d_array, uv: vec2, layer: int) -> vec4:
    return sample_level(t, uv, layer, 0.0)


def cubes(t: texturecube_array, dir: vec3, layer: uint) -> vec4:
    return sample_level(t, dir, layer, 0.0)


def shadowed(t: texture2d_array_shadow, uv: vec2, layer: int, ref: float) -> float:
    return sample_compare(t, uv, layer, ref)


def implicit(t: texture2d_array, uv: vec2, layer: int) -> vec4:
    return sample(t, uv, layer)


def implicit_cubes(t: texturecube_array, dir: vec3, layer: int) -> vec4:
    return sample(t, dir, layer) + sample_level(t, dir, layer + 1, 1.0)
