"""Shadow map, one tap: visibility = (depth of P in light space - bias <= stored depth).

Williams 1978, "Casting curved shadows on curved surfaces". One nearest sample
(sample_level at LOD 0, so it is valid in non-uniform control flow); no filtering.
The light-space matrix maps world space to Vulkan clip space (depth in [0, 1]).
"""
BRICK = {
    "kind": "shadow",
    "cite": "Williams 1978 (shadow mapping), single tap",
    "params": {
        "shadow_matrix": {"type": "mat4", "default": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0], "doc": "world to light clip space, column-major"},
        "shadow_bias": {"type": "float", "range": [0.0, 1.0], "default": 0.002, "doc": "depth bias against self-shadowing acne"},
    },
    "textures": {"shadow_map": {"srgb": False, "doc": "light-space depth in .x"}},
}


def shadow(P: vec3, shadow_matrix: mat4, shadow_bias: float, shadow_map: texture2d) -> float:
    c = shadow_matrix * vec4(P, 1.0)
    # w is floored so that points behind the light's near plane do not divide by zero.
    p = c.xyz / max(c.w, 0.000001)
    uv = p.xy * 0.5 + vec2(0.5)
    stored = sample_level(shadow_map, uv, 0.0).x
    return 1.0 if p.z - shadow_bias <= stored else 0.0
