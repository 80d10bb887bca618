"""Test brick: a diffuse term read from a 2D lookup table, f_r = ρ_d · LUT(n·l, n·v) / π.

A tabulated BRDF in the spirit of the factored forms of Kautz & McCool 1999 (a 2D table
indexed by two cosines, sampled with bilinear filtering): here one table whose texels
scale Lambert, so the eval kernel and NumPy are compared on the texture path itself.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Kautz & McCool 1999 (2D tables indexed by cosines); Lambert 1760",
    "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5]}},
    "textures": {"lut": {"srgb": False, "doc": "RGB scale of Lambert at (n·l, n·v)"}},
}


def diffuse(NdotL: float, NdotV: float, rho_d: vec3, lut: texture2d) -> vec3:
    s = sample_level(lut, vec2(NdotL, NdotV), 0.0).xyz
    return rho_d * s * INV_PI
