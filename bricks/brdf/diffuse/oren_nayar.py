"""Oren-Nayar diffuse, the qualitative model: f_r = rho_d/pi (C_A + C_B max(0, cos phi) sin(alpha) tan(beta)).

Hoffman & Baker 2006, "Physically-Based Reflectance for Games", the Oren-Nayar
slide; Oren & Nayar 1994, "Generalization of Lambert's Reflectance Model",
eq. 30 (the qualitative model), with alpha = max(theta_i, theta_r),
beta = min(theta_i, theta_r), phi the azimuth between l and v, sigma the standard
deviation of the facet slope angle in radians, and
C_A = 1 - 0.5 sigma^2/(sigma^2 + 0.33) = 1 - sigma^2/(2 sigma^2 + 0.66),
C_B = 0.45 sigma^2/(sigma^2 + 0.09).
sigma = 0 is Lambert (1/pi exactly, ACCURACY-FACTS §4.7); reciprocal.

Seed misprints. The course notes (seed 000) print
  "C_B = 0.45 \\frac{\\sigma^2}{\\sigma^2 + 0.09} \\quad C_A = 1 - \\frac{\\sigma^2}{2\\sigma^2 - 0.66}"
and
  "f_r = \\frac{\\rho_d}{\\pi} (C_A + C_B \\cos \\varphi)
         \\sin(\\max(\\theta_i, \\theta_e)) \\cos(\\min(\\theta_i, \\theta_e))" (one line there).
Against Oren & Nayar 1994 eq. 30:
- the minus in 2 sigma^2 - 0.66 is a sign error: it makes C_A > 1 (an albedo above 1) for
  sigma^2 < 0.33, e.g. 1.1875 at sigma = 0.3, and infinite at sigma^2 = 0.33;
- the paper clamps the cosine, max(0, cos(phi_r - phi_i));
- its factor is sin(alpha) tan(beta), not sin(max) cos(min), and it multiplies the C_B term
  only: read as printed, sigma = 0 would give rho_d/pi sin(max theta) cos(min theta), not
  Lambert's rho_d/pi.
The paper's form is used.

No tangent frame: with l_p = l - n (n.l), v_p = v - n (n.v) the projections on the tangent
plane (|l_p| = sin theta_i, |v_p| = sin theta_r),
  cos phi sin(alpha) tan(beta) = cos phi sin(theta_i) sin(theta_r) / cos(beta)
                               = (l_p . v_p) / max(n.l, n.v),
which needs no normalization (finite at normal incidence, where l_p or v_p is 0) and keeps
its digits near the normal (no sqrt(1 - cos^2)). max(n.l, n.v) >= n.v >= 1e-4 (the clamp of
the shading policy). A view below the horizon is shaded as grazing (n.v clamped to 1e-4) with
its own azimuth: v_p is rescaled to the length sin(theta_r) of the clamped cosine (v = -n,
where the azimuth is undefined, keeps v_p = 0: no retro-reflection term).
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Oren & Nayar 1994 eq. 30 (qualitative model); Hoffman & Baker 2006 (C_A sign corrected)",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "sigma": {"type": "float", "range": [0.0, 1.57], "default": 0.3,
                  "doc": "Oren-Nayar roughness: standard deviation of the facet slope angle (radians)"},
    },
    "needs": ["L", "N", "NdotL", "NdotV", "V"],
}


def diffuse(L: vec3, V: vec3, N: vec3, NdotL: float, NdotV: float, rho_d: vec3, sigma: float) -> vec3:
    s2 = sigma * sigma
    C_A = 1.0 - s2 / (2.0 * s2 + 0.66)
    C_B = 0.45 * s2 / (s2 + 0.09)
    l_p = L - N * NdotL
    NdotV_raw = dot(N, V)
    v_p = V - N * NdotV_raw
    if NdotV_raw < NdotV:
        # Below the horizon (n.v clamped): the grazing direction of v's azimuth. The floor keeps
        # v = -n at v_p = 0 (rsqrt(0) is inf); it is far below any nonzero |v_p|^2 of a unit v.
        v_p = v_p * (sqrt(1.0 - NdotV * NdotV) * rsqrt(max(dot(v_p, v_p), 1e-30)))
    retro = max(dot(l_p, v_p), 0.0) / max(NdotL, NdotV)
    return rho_d * (INV_PI * (C_A + C_B * retro))
