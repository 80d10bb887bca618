"""Simplified Oren-Nayar (RTR3 eqs. 7.57-7.59): f_r = rho_d/pi (A + B max(0, cos phi) sin(alpha) tan(beta)).

RTR3 §7.6 eq. 7.57 with A = 1 - 0.5 sigma^2/(sigma^2 + 0.33), B = 0.45 sigma^2/(sigma^2 + 0.09)
(eq. 7.58), sigma the standard deviation of the facet slope angle in radians, and cos phi from
the light and view vectors projected on the tangent plane, normalized, dotted and clamped to be
non-negative (eq. 7.59 and the text after it); Oren & Nayar 1994 eq. 30.
sigma = 0 is Lambert (1/pi, ACCURACY-FACTS §4.7); reciprocal.

Seed misprint: RTR3 eq. 7.57 prints "cos(phi) sin(min(theta_i, theta_o)) tan(max(theta_i,
theta_o))". Oren & Nayar 1994 eq. 30 has sin(alpha) tan(beta) with alpha = max, beta = min; the
printed order is infinite at a grazing direction. The paper's order is used.

Interreflection: RTR3 notes (after Oren & Nayar) that 0.33 in A can be replaced by 0.57 to better
approximate interreflection. That is the sibling brick `oren_nayar_simplified_interreflection`,
not a parameter: the constant selects a variant of the model (a compile-time constant), not a
material property, and the spec string names which one a material uses.

Guards. The projections are normalized with rsqrt(max(|x_p|^2, 1e-30)): a direction along n has
x_p = 0 and an undefined azimuth; it gets cos phi = 0, where its sin theta = 0 multiplies the
term anyway (no cost). tan(beta) = sqrt(1 - c^2)/c with c = max(n.l, n.v) >= n.v >= 1e-4 (the
shading policy's clamp); the sqrt arguments are clamped at 0 against rounding. A view below the
horizon keeps its azimuth and is shaded at n.v = 1e-4.
"""
BRICK = {
    "kind": "diffuse",
    "cite": "RTR3 eqs. 7.57-7.59 (sin/tan order corrected); Oren & Nayar 1994 eq. 30",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "sigma": {"type": "float", "range": [0.0, 1.57], "default": 0.3,
                  "doc": "Oren-Nayar roughness: standard deviation of the facet slope angle (radians)"},
    },
    "needs": ["L", "N", "NdotL", "NdotV", "V"],
}


def diffuse(L: vec3, V: vec3, N: vec3, NdotL: float, NdotV: float, rho_d: vec3, sigma: float) -> vec3:
    s2 = sigma * sigma
    A = 1.0 - 0.5 * s2 / (s2 + 0.33)
    B = 0.45 * s2 / (s2 + 0.09)
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
