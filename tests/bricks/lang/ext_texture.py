"""Texture sampling, for comparing lavapipe's sampler with the NumPy target's filter."""
BRICK = {
    "kind": "test",
    "params": {},
}


def flat(t: texture2d, uv: vec2) -> vec4:
    return sample_level(t, uv, 0.0)


def env(t: texturecube, dir: vec3) -> vec4:
    return sample_level(t, dir, 0.0)
