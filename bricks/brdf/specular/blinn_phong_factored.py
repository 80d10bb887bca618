"""Normalized Blinn-Phong, factored: f_r = (n + 4)/(8 pi) R_F(0) cos^n(theta_h), cos^n from a baked table.

Hoffman & Baker 2006, "BRDF Costs, Shift-Invariant": "Blinn-Phong factored" 1 texture / 2 ALU against
0 / 7 direct; the model is `blinn_phong_normalized`'s (its reference is the direct one). The table
(`blinn_phong_pow`, generator/reference/tables_specular.py) holds cos^n theta_h for every exponent, so
one table serves every material: a table over (n.h, n) cannot follow the lobe of large n (1/n wide in
n.h), so its u axis is the lobe coordinate x = (1 - n.h) max(n, 24)/24 (cos^n -> e^(-24x) for large n,
the whole 1 - n.h for n < 24) and its v axis y = 1/sqrt(n) rescaled to [0, 1] over n in [1, 1e5].
The normalization (n + 4)/(8 pi) and R_F(0) stay in ALU (the table's values stay in [0, 1]).
Cost: 1 texture; ALU: 1 - n.h, its scale and clamp, the v coordinate (per material: rsqrt, mad), the
texel-centre mad, and the two multiplies, about 7 where the course counts 2 (its table is read at
(n.h, n) directly, which the lobe coordinate replaces; see above).

Size and format by measured error (hemisphere max relative error against the reference, NumPy
float32, 12^4 pairs; benchmarks/results/tables.md): at the default n = 64, 64x32 fp32 3.2e-2,
128x64 8.5e-3, 256x128 2.3e-3, 512x256 5.0e-4; at n = 4: 1.9e-1, 4.6e-2, 1.0e-2, 1.4e-3; n = 1000:
1.8e-2, 4.5e-3, 1.2e-3, 3.4e-4. 256x128 is the smallest within 0.3 % at the default and 1 % for
n >= 4 (n < 4: up to 4 % at n = 2, where cos^n changes fastest with n between the rows). unorm8
cannot hold the tail (values below 1/510 read 0: 100 % off); fp16 is as good at the default (3.5e-3)
but its subnormals lose the tail of large n (4.5e-2 at n = 1000, 100 % at n = 1e4 with f0 = 1), so
fp32. The table's last column is e^-24 of the peak: at n = 1e4 and f0 = 1 that cut-off is 1.5e-8 sr^-1
(1.5e-2 relative to accuracy's 1e-6 floor). The same table serves `ashikhmin_shirley_factored`.
"""
BRICK = {
    "kind": "specular",
    "cite": "Hoffman & Baker 2006, normalized Blinn-Phong (n+4)/(8 pi) R_F(0) cos^n(theta_h), factored (BRDF costs, factored forms)",
    "params": {
        "n": {"type": "float", "range": [1.0, 100000.0], "default": 64.0, "doc": "Blinn-Phong cosine power"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04], "doc": "R_F(0), Fresnel reflectance at normal incidence"},
    },
    "textures": {"bp_pow": {"table": "blinn_phong_pow", "size": [256, 128], "format": "fp32",
                            "doc": "cos^n theta_h at (lobe coordinate, 1/sqrt(n))"}},
    "tolerance": 0.004,
    "needs": ["NdotH"],
}


def specular(NdotH: float, n: float, f0: vec3, bp_pow: texture2d) -> vec3:
    # Table coordinates (generator/reference/tables_specular.py): the lobe coordinate
    # x = (1 - n.h) max(n, 24)/24, clamped at 1 (e^-24 of the peak, the table's last column: the
    # sampler's address mode is never relied on), and the exponent row
    # y = (1/sqrt(n) - 1/sqrt(1e5)) / (1 - 1/sqrt(1e5)); texel centres: u = x (W - 1)/W + 0.5/W
    # for W = 256, H = 128. 1/24 = 0.0416666667.
    x = min((1.0 - NdotH) * (max(n, 24.0) * 0.0416666667), 1.0)
    y = (rsqrt(n) - 0.00316227766) * 1.003172309
    uv = vec2(x, y) * vec2(0.99609375, 0.9921875) + vec2(0.001953125, 0.00390625)
    cos_n = sample_level(bp_pow, uv, 0.0).x
    return f0 * ((n + 4.0) / (8.0 * PI) * cos_n)
