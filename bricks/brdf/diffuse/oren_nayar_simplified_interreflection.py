"""Simplified Oren-Nayar with 0.57 for 0.33 in A, "to better approximate surface interreflection".

RTR3 §7.6 p. 263 (after Oren & Nayar 1994): eqs. 7.57-7.59 with
A = 1 - 0.5 sigma^2/(sigma^2 + 0.57), B = 0.45 sigma^2/(sigma^2 + 0.09), sigma in radians:
f_r = rho_d/pi (A + B max(0, cos phi) sin(alpha) tan(beta)), alpha = max(theta_i, theta_o),
beta = min(theta_i, theta_o) (RTR3 prints sin(min) tan(max): see `oren_nayar_simplified`,
whose code, guards and their costs this brick shares; only A's constant differs).
sigma = 0 is Lambert (1/pi); reciprocal.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "RTR3 eqs. 7.57-7.59 with the 0.57 interreflection constant (p. 263); Oren & Nayar 1994",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "sigma": {"type": "float", "range": [0.0, 1.57], "default": 0.3,
                  "doc": "Oren-Nayar roughness: standard deviation of the facet slope angle (radians)"},
    },
    "needs": ["L", "N", "NdotL", "NdotV", "V"],
}


def diffuse(L: vec3, V: vec3, N: vec3, NdotL: float, NdotV: float, rho_d: vec3, sigma: float) -> vec3:
    s2 = sigma * sigma
    A = 1.0 - 0.5 * s2 / (s2 + 0.57)
    B = 0.45 * s2 / (s2 + 0.09)
    # Projections on the tangent plane, normalized (eq. 7.59); floor: see oren_nayar_simplified.
    v_proj = V - N * dot(N, V)
    l_proj = L - N * NdotL
    v_proj = v_proj * rsqrt(max(dot(v_proj, v_proj), 1e-30))
    l_proj = l_proj * rsqrt(max(dot(l_proj, l_proj), 1e-30))
    cos_phi = max(dot(l_proj, v_proj), 0.0)
    c_alpha = min(NdotL, NdotV)
    c_beta = max(NdotL, NdotV)
    sin_alpha = sqrt(max(1.0 - c_alpha * c_alpha, 0.0))
    tan_beta = sqrt(max(1.0 - c_beta * c_beta, 0.0)) / c_beta
    return rho_d * (INV_PI * (A + B * cos_phi * sin_alpha * tan_beta))
