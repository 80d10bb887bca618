"""Test brick: isotropic Lafortune lobes, an array parameter of up to 4 generalized cosine lobes.

f = Σ_i ρ_i max(C_xy,i (u_x v_x + u_y v_y) + C_z,i u_z v_z, 0)^n_i (Lafortune et al. 1997,
eq. 4 with C_x = C_y), written without a tangent frame: u_x v_x + u_y v_y = l·v − (n·l)(n·v).
Lobe i is the vec4 (C_xy, C_z, n, ρ); how many lobes are summed (lobes_count) is part of
the permutation key: lobes(lobes=2).
"""
BRICK = {
    "kind": "specular",
    "cite": "Lafortune et al. 1997 eq. 4 (isotropic, C_x = C_y)",
    "params": {
        "lobes": {"type": "vec4", "count": 4, "range": [-100.0, 1000.0],
                  "default": [[-1.0, 1.0, 8.0, 0.5], [-1.0, 1.0, 64.0, 0.3], [0.5, 0.5, 2.0, 0.1],
                              [-0.9, 0.9, 200.0, 0.05]],
                  "doc": "per lobe (C_xy, C_z, n, rho)"},
    },
}


def specular(NdotL: float, NdotV: float, LdotV: float, lobes: array[vec4, 4], lobes_count: int) -> vec3:
    f = 0.0
    for i in range(lobes_count):
        c = lobes[i]
        d = c.x * (LdotV - NdotL * NdotV) + c.y * (NdotL * NdotV)
        f += c.w * pow(max(d, 0.0), c.z)
    return vec3(f)
