"""Ashikhmin-Shirley anisotropic specular, factored: cos^e theta_h and Schlick's (1 - k.h)^5 from baked tables.

Ashikhmin & Shirley 2000 eqs. 4-5, as `ashikhmin_shirley` (its reference is the direct one; reciprocal
as it is: every factor is symmetric in l and v). Hoffman & Baker 2006, "BRDF Costs, Shift-Invariant":
"Ashikhmin/Shirley factored" 4 textures / 10 ALU against 0 / 40 direct, for the whole model; its
diffuse half reads one 1D table twice (`ashikhmin_shirley_diffuse_factored`), this specular half two
tables: cos^e theta_h from the Blinn-Phong table (`blinn_phong_pow`, shared with
`blinn_phong_factored`: same table, same size, one artifact), read at the per-pixel anisotropic
exponent e = (n_u (h.t)^2 + n_v (h.b)^2)/(1 - (n.h)^2), and Schlick's (1 - k.h)^5 (`schlick_pow5`, 1D).
2 + 2 = the course's 4 textures. ALU: the exponent e (5), the lobe and row coordinates (6, the row's
rsqrt per pixel since e varies), Fresnel (2), the 1/((k.h) max(n.l, n.v)) and the normalization (5):
about 18, where the course counts 10 (its exponent term is a 2D table at (h.t, h.b) per material;
this one serves every n_u, n_v).

Error (hemisphere max relative error against the reference, NumPy float32, 12^4 pairs, n_u = 100,
n_v = 10): 0.28 (0.36 at f0 = 0, all Fresnel from the table; tolerance 0.4) with a 256x128 fp32 cos^e table (0.12 at 512x256, 0.58 at 128x64), the Schlick table's
size (32 to 256) and format (fp16, fp32) not mattering. The worst samples are in the lobe's far tail
(f_r ~ 1e-6 sr^-1, at accuracy's floor), where 1/((k.h) max(n.l, n.v)) lifts cos^e values of 1e-9 and
less above the floor: there the table's rows (e between them) and columns are far off relatively.
Within the lobe the table is as accurate as for `blinn_phong_factored`. 256x128 keeps one table with
Blinn-Phong; Schlick's 32 texels fp16 (its values in [0, 1], 2^-11 relative; (1 - x)^5 is smooth).
"""
BRICK = {
    "kind": "specular",
    "cite": "Ashikhmin & Shirley 2000 eqs. 4-5, factored as in Hoffman & Baker 2006 (BRDF costs, factored forms)",
    "params": {
        "n_u": {"type": "float", "range": [1.0, 100000.0], "default": 100.0, "doc": "Phong exponent along the tangent t"},
        "n_v": {"type": "float", "range": [1.0, 100000.0], "default": 10.0, "doc": "Phong exponent along the bitangent b"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_s = R_F(0), Fresnel reflectance at normal incidence"},
    },
    "textures": {
        "bp_pow": {"table": "blinn_phong_pow", "size": [256, 128], "format": "fp32",
                   "doc": "cos^e theta_h at (lobe coordinate, 1/sqrt(e)), e the anisotropic exponent"},
        "schlick": {"table": "schlick_pow5", "size": [32, 1], "format": "fp16", "doc": "(1 - k.h)^5 at k.h"},
    },
    "tolerance": 0.4,
    "needs": ["NdotL", "NdotV", "NdotH", "LdotH", "HdotT", "HdotB"],
}


def specular(NdotL: float, NdotV: float, NdotH: float, LdotH: float, HdotT: float, HdotB: float,
             n_u: float, n_v: float, f0: vec3, bp_pow: texture2d, schlick: texture2d) -> vec3:
    # The exponent e as in `ashikhmin_shirley` (its denominator 1 - (n.h)^2 written (h.t)^2 + (h.b)^2;
    # e := n_u at h = n, where the table's x is 0 and reads 1 for any e).
    tu = HdotT * HdotT
    tv = HdotB * HdotB
    s2 = tu + tv
    e = (n_u * tu + n_v * tv) / s2 if s2 > 0.0 else n_u
    # cos^e theta_h from the Blinn-Phong table (generator/reference/tables_specular.py): lobe coordinate
    # x = (1 - n.h) max(e, 24)/24 with 1 - n.h = sin^2 / (1 + n.h) (its digits kept near h = n),
    # clamped at 1; row y = (1/sqrt(e) - 1/sqrt(1e5)) / (1 - 1/sqrt(1e5)); texel centres for W = 256, H = 128.
    # 1 + n.h >= 1 for n.h >= 0; h below the horizon (n.h < 0) has s2 / (1 + n.h) > 1: clamped to x = 1.
    # s2 = 0 is h = n (1 - n.h = 0) or the undefined h = 0 of l = -v (1 - n.h = 1: no reflection).
    one_minus_c = s2 / max(1.0 + NdotH, 1e-30) if s2 > 0.0 else 1.0 - NdotH
    x = min(one_minus_c * (max(e, 24.0) * 0.0416666667), 1.0)
    y = (rsqrt(e) - 0.00316227766) * 1.003172309
    uv = vec2(x, y) * vec2(0.99609375, 0.9921875) + vec2(0.001953125, 0.00390625)
    cos_e = sample_level(bp_pow, uv, 0.0).x
    # Schlick's (1 - k.h)^5 from a 1D table at texel centres (W = 32).
    c5 = sample_level(schlick, vec2(LdotH * 0.96875 + 0.015625, 0.5), 0.0).x
    fresnel = f0 + (vec3(1.0) - f0) * c5
    # (k.h) max(n.l, n.v) is 0 only for l = -v (h = 0); floored at 1e-30 as in `ashikhmin_shirley`.
    d = max(LdotH * max(NdotL, NdotV), 1e-30)
    return fresnel * (sqrt((n_u + 1.0) * (n_v + 1.0)) / (8.0 * PI) * cos_e / d)
