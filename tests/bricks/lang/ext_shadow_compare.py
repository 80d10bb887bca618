"""A hardware depth compare (sample_compare on a texture2d_shadow), for comparing lavapipe's comparison
sampler with the NumPy target's emulation (tests/backends/test_shadow_compare.py)."""
BRICK = {
    "kind": "test",
    "params": {},
}


def compare(t: texture2d_shadow, uv: vec2, ref: float) -> float:
    return sample_compare(t, uv, ref)
