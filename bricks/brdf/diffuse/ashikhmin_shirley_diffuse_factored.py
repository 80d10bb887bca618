"""Ashikhmin-Shirley diffuse, factored: f_r = 28 rho_d/(23 pi) (1 - R_s) P(n.l) P(n.v), P from a baked 1D table.

Ashikhmin & Shirley 2000 eq. 5, as `ashikhmin_shirley_diffuse` (its reference is the direct one;
reciprocal: the same table at n.l and n.v), P(x) = 1 - (1 - x/2)^5. Hoffman & Baker 2006, "BRDF Costs,
Shift-Invariant": the diffuse half of "Ashikhmin/Shirley factored" (4 textures / 10 ALU with
`ashikhmin_shirley_factored`): one 1D table read twice. The table
(`ashikhmin_shirley_diffuse_factor`, generator/reference/tables_specular.py) holds P(x)/(5x/2), smooth
and in [0.775, 1], and the brick multiplies by x: a table of P itself is linear at x = 0 and bilinear
filtering is O(1/W) off relative to it there (1.0 % at W = 128).
ALU: 2 texel-centre mads, 2 multiplies by n.l, n.v, and 3 for rho_d (1 - R_s) 175/(23 pi): 7.

Size and format by measured error (hemisphere max relative error against the reference, NumPy
float32, 12^4 pairs; benchmarks/results/tables.md): fp16 4 texels 3.1e-2, 8 5.8e-3, 16 1.6e-3,
32 7.6e-4; unorm8 stops near 8e-3 (its 1/510 steps). 32 texels fp16 is the smallest within 1e-3
(accuracy's default tolerance); unorm8 16 (8e-3) is the choice where 1 % will do.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Ashikhmin & Shirley 2000 eq. 5, factored as in Hoffman & Baker 2006 (BRDF costs, factored forms)",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "R_s, the specular reflectance at normal incidence"},
    },
    "textures": {"as_factor": {"table": "ashikhmin_shirley_diffuse_factor", "size": [32, 1], "format": "fp16",
                              "doc": "(1 - (1 - x/2)^5)/(5x/2) at x = n.l or n.v"}},
    "tolerance": 0.001,
    "needs": ["NdotL", "NdotV"],
}


def diffuse(NdotL: float, NdotV: float, rho_d: vec3, f0: vec3, as_factor: texture2d) -> vec3:
    # One 1D table read twice, at texel centres u = x (W - 1)/W + 0.5/W for W = 32.
    # The table holds (1 - (1 - x/2)^5)/(5x/2) (smooth, in [0.775, 1]); x times it keeps the relative
    # digits of the factor as x -> 0. 28/(23 pi) (5/2)^2 = 175/(23 pi).
    fl = sample_level(as_factor, vec2(NdotL * 0.96875 + 0.015625, 0.5), 0.0).x
    fv = sample_level(as_factor, vec2(NdotV * 0.96875 + 0.015625, 0.5), 0.0).x
    return rho_d * (vec3(1.0) - f0) * (175.0 / (23.0 * PI) * (NdotL * fl) * (NdotV * fv))
