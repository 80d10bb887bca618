"""KHR_texture_transform: uv' = T(offset) · R(rotation) · S(scale) · uv, one affine map for every texture.

glTF 2.0 extension KHR_texture_transform (Khronos, on a textureInfo: `offset`, `rotation`,
`scale`; defaults [0, 0], 0, [1, 1]): the UVs are scaled, then rotated by `rotation` radians
"counter-clockwise" in UV space, whose v axis points down, then offset:
    u' =  sx cos r · u + sy sin r · v + ox
    v' = −sx sin r · u + sy cos r · v + oy
The sign is that of the extension's own example (offset [0, 1], rotation π/2, scale [0.5, 0.5]
samples the lower-left quadrant, turned 90° clockwise) and of Babylon.js and the Blender glTF I/O;
the extension's GLSL listing, read column-major, rotates the other way (the glTF repository's
discussion "KHR_texture_transform has the wrong rotation matrix").

Parameters are the glTF values as they are (the Material block holds offset, scale and rotation,
not a matrix): cos r and sin r are computed per fragment, two transcendentals, where a baked
2 × 3 matrix would cost none but would not be the file's values. Unbounded, as in the extension
(a result outside [0, 1] wraps by the sampler's address mode).
"""
BRICK = {
    "kind": "uv",
    "cite": "glTF 2.0 KHR_texture_transform (Khronos): uv' = T(offset) R(rotation) S(scale) uv, rotation "
            "counter-clockwise in v-down UV space",
    "params": {
        "uv_offset": {"type": "vec2", "default": [0.0, 0.0], "doc": "KHR_texture_transform offset (added last)"},
        "uv_scale": {"type": "vec2", "default": [1.0, 1.0], "doc": "KHR_texture_transform scale (applied first)"},
        "uv_rotation": {"type": "float", "default": 0.0, "doc": "KHR_texture_transform rotation (radians)"},
    },
}


def map_uv(uv: vec2, uv_offset: vec2, uv_scale: vec2, uv_rotation: float) -> vec2:
    c = cos(uv_rotation)
    s = sin(uv_rotation)
    p = uv * uv_scale
    return vec2(c * p.x + s * p.y, c * p.y - s * p.x) + uv_offset
