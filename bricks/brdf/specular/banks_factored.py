"""Banks anisotropic specular, factored: f_r = (k_s / pi) max(0, v.r')^n, the bracket read from a baked table.

Banks 1994 with the course's cosine step, as `banks` (its reference is the direct one; reciprocal: the
table is symmetric and read at (l.t, v.t) with the same mapping on both axes). Hoffman & Baker 2006,
"BRDF Costs, Shift-Invariant": "Banks Factored" 1 texture / 5 ALU against 0 / 12 direct. The table
(`banks_bracket`, generator/reference/tables_specular.py) holds max(0, sqrt(1 - (l.t)^2) sqrt(1 - (v.t)^2)
- (l.t)(v.t)) for every material; the exponent n is the material's and stays in ALU (pow).
The course's table is linear in l.t and v.t; sqrt(1 - a^2) has an infinite slope at a = +-1 (l or v
along the thread), where such a table is 67 % off at n = 32 (256^2; 41 % at 1024^2). The axes here are
s = sign(a)(1 - sqrt(1 - |a|)) for a = l.t, v.t, in which the kernel is smooth: 2 sqrt and 4 more ALU
per pixel (vectorized over the pair), so about 10 ALU beside the texture where the course counts 5.
Self-shadowing f_r = 0 for n.l <= 0 as in `banks`.

Size and format by measured error (hemisphere max relative error against the reference, NumPy
float32, 12^4 pairs, n = 32; benchmarks/results/tables.md): fp32 32^2 1.2e-1, 64^2 3.1e-2,
128^2 7.8e-3, 256^2 2.0e-3; fp16 at 128^2 1.5e-2 and 256^2 1.1e-2 (its 2^-11 steps times n); unorm8
8 % or worse at every size. 256^2 fp32 is the smallest within 0.2 % at the default n = 32 (9e-4
at n = 4; 5.9e-2 at n = 1000: for sharp threads the direct `banks` is the better choice). The error grows
with n like n times the kernel's (pow), so n's range stops at 1000 and the declared tolerance is the
error there, 0.06 (2.0e-3 at the default n = 32).
"""
BRICK = {
    "kind": "specular",
    "cite": "Banks 1994; Hoffman & Baker 2006 (anisotropic Blinn-Phong of threads, factored: BRDF costs)",
    "params": {
        "n": {"type": "float", "range": [1.0, 1000.0], "default": 32.0,
              "doc": "Banks cosine power (to 1000: beyond, the table's error times n passes 6 %; use `banks`)"},
        "k_s": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5],
                "doc": "specular coefficient k_s of Banks' lighting equation (not a reflectance)"},
    },
    "textures": {"banks_kernel": {"table": "banks_bracket", "size": [256, 256], "format": "fp32",
                                 "doc": "v.r' (signed) at the remapped (l.t, v.t)"}},
    "tolerance": 0.06,
    "needs": ["NdotL", "LdotT", "VdotT"],
}


def specular(NdotL: float, LdotT: float, VdotT: float, n: float, k_s: vec3, banks_kernel: texture2d) -> vec3:
    # Table coordinates (generator/reference/tables_specular.py, banks_coordinate): for a = l.t and v.t,
    # s = sign(a) (1 - sqrt(1 - |a|)) in [-1, 1] (the kernel's sqrt(1 - a^2) is smooth in it); texel centres
    # u = (s + 1)/2 (W - 1)/W + 0.5/W = s (W - 1)/(2W) + 0.5 for W = 256 (H = 256 alike). 1 - |a| is floored
    # at 0: float32 cosines of unit vectors may exceed 1 by an ulp.
    a = vec2(LdotT, VdotT)
    s = sign(a) * (vec2(1.0) - sqrt(max(vec2(1.0) - abs(a), vec2(0.0))))
    uv = s * vec2(0.498046875, 0.498046875) + vec2(0.5)
    # the table is signed: clamped after the filter, so the kink of max(0, .) is exact (a filtered clamp leaks)
    kernel = max(sample_level(banks_kernel, uv, 0.0).x, 0.0)
    shadow = 1.0 if NdotL > 0.0 else 0.0
    return k_s * (INV_PI * shadow * pow(kernel, n))
