"""The course's packed texture: normal xy, specular power and gloss in one RGBA texture (Hoffman & Baker 2006).

Hoffman & Baker 2006, "Texture Management": "Can often pack data into one texture —
Example: store normals as only x and y, pack power and gloss coefficients in other two
channels". One linear RGBA texture `normal_map`:

  R, G  tangent-space normal x, y as (t + 1)/2, read by the normal slot's default filler
        `normal_map_xy` (z reconstructed), which names the same texture: one binding;
  B     specular power p: n = n_max^p (n_max = 8192: Lazarov 2011, "Physically based lighting in
        Call of Duty: Black Ops", the exponent 8192^gloss), so 8 bits cover n in [1, n_max]
        with a constant ratio 8192^(1/255) = 1.036 between codes;
  A     gloss g, the course's "gloss map": "R_F(0) usually stored in textures as a scalar
        (gloss map) … multiplying a scalar value stored in a texture with an RGB material
        constant": f0 = g · f0 (the material's constant f0).

Provides `n` and `f0`, so it fits a BRDF reading both (blinn_phong_normalized, with lambert
or alone); rho_d stays the material's constant. Linear texture: the exponent and the
normal are not colors, and the gloss is kept linear with them (one format for the four
channels). No guards: p in [0, 1] gives n in [1, n_max], within every Phong-family
exponent's range.
"""
BRICK = {
    "kind": "packing",
    "cite": "Hoffman & Baker 2006, Texture Management (normal xy + power + gloss in one texture); Lazarov 2011 (n = 8192^p)",
    "params": {"n_max": {"type": "float", "range": [1.0, 10000.0], "default": 8192.0, "doc": "the exponent at B = 1 (n = n_max^B)"}},
    "textures": {"normal_map": {"srgb": False, "holds": "normal_xy", "doc": "linear RGBA; RG: normal xy as (t + 1) / 2; B: specular power p (n = n_max^p); A: gloss (f0 scale)"}},
    "slots": {"normal": {"kind": "normal", "default": "normal_map_xy"}},
}


def get_n(uv: vec2, normal_map: texture2d, n_max: float) -> float:
    return pow(n_max, sample(normal_map, uv).z)


def get_f0(uv: vec2, normal_map: texture2d, f0: vec3) -> vec3:
    return f0 * sample(normal_map, uv).w
