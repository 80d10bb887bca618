"""Gotanda's fitted microfacet diffuse (Gotanda 2014 eq. 8): f_r = rho_d L_r / (n.l).

Gotanda 2014, "Designing Reflectance Models for New Consoles", eq. 8: a fit of the microfacet
diffuse model of eq. 4 (Lambertian facets; GGX D, Schlick-type Fresnel per facet, height-correlated
Smith G: footnote 3), for roughness sigma in [0, 1]:
  L_r = 21/(20 pi) (1 - f0) (F_r L_m + V_d B_p),
  F_r = (1 - (0.542026 s^2 + 0.303573 s)/(s^2 + 1.36053)) (1 - (1 - n.e)^(5 - 4 s^2)/(s^2 + 1.36053))
        ((-0.733996 s^3 + 1.50912 s^2 - 1.16402 s)(1 - n.e)^(1 + 1/(39 s^4 + 1)) + 1),
  L_m = (max(1 - 2s, 0)(1 - (1 - n.l)^5) + min(2s, 1)) ((1 - 0.5 s) n.l + 0.5 s (n.l)^2),
  V_d = s^2/((s^2 + 0.09)(1.31072 + 0.995584 n.e)) (1 - (1 - n.l)^((1 - 0.3726732 (n.e)^2)/(0.188566 + 0.388410 n.e))),
  B_p = 1.4 (n.e)(n.l) c if c < 0, c otherwise; c = e.l - (n.e)(n.l).
L_r is a radiance for rho = E0 = 1 (L_m carries n.l), so f_r = rho_d L_r / n.l. The seed text
writes "(n.e^2)" (read (n.e)^2) and repeats V_d's last factor on a line of its own (an
extraction artifact, taken once; UE4's Diffuse_Gotanda has it once).
Roughness: sigma of eq. 8 is the GGX roughness of eq. 4's D, so this brick reads the canonical
`alpha` (shared with a GGX specular of the same spec, Gotanda's point). Against the model it fits
(generator/reference/diffuse.py: microfacet_diffuse, gotanda_fit_error_table) alpha = sigma fits
best (mean relative error 1-9 % with both directions within 60° of n; alpha = sigma^2 or sqrt(sigma)
fit worse); the fit is poor where both directions graze (the paper's own limitation).
Not reciprocal (F_r reads only n.e, L_m only n.l: ACCURACY-FACTS §4.6).

Guards and their costs:
- n.l is divided out analytically: L_m / n.l and V_d / n.l are evaluated directly, so f_r is finite
  as n.l -> 0. (1 - (1 - x)^p)/x uses its binomial series (six terms) for x < 0.01 (relative
  truncation error < 1e-15 for p in [1.09, 5.31], the range of V_d's exponent) and the closed form above (rounding
  of 1 - x costs < 1e-5 there); 1 - (1 - x)^5 is expanded (Horner), exact at small x.
- The fit goes negative where V_d B_p < 0 outweighs F_r L_m (backward side, grazing light); a
  radiance cannot be negative: clamped at 0. Near that boundary the value is a difference of two
  terms and its float32 relative error is unbounded (the absolute error is not).
- pow(1 - n.e, y) with y > 0 only (5 - 4 s^2 >= 1, 1 + 1/(39 s^4 + 1) > 1): no pow(0, 0).
"""
BRICK = {
    "kind": "diffuse",
    "cite": "Gotanda 2014 eq. 8 (fit of the GGX/Smith/Fresnel Lambertian-microfacet model of eq. 4)",
    "reciprocal": "no: the fit of Gotanda 2014 eq. 8 reads n.e in F_r and V_d and n.l in L_m, asymmetrically (the eq. 4 model it fits is reciprocal)",
    "params": {
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "alpha": {"type": "float", "range": [0.0, 1.0], "default": 0.3,
                  "doc": "roughness: GGX alpha of the microfacets (Gotanda's sigma, fitted for 0 to 1)"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04],
               "doc": "Fresnel reflectance at normal incidence"},
    },
    "needs": ["LdotV", "NdotL", "NdotV"],
}

SERIES_BELOW = 0.01


def one_minus_pow5_complement(x: float) -> float:
    # 1 - (1 - x)^5, expanded (Horner): no cancellation at small x
    return x * (5.0 + x * (-10.0 + x * (10.0 + x * (-5.0 + x))))


def one_minus_pow_over_x(x: float, p: float) -> float:
    # (1 - (1 - x)^p) / x; below 0.01 its binomial series, nested: the k-th term is the previous one
    # times -(p - k + 1)/k x; six terms, truncation < 1e-15 relative for p <= 5.31
    t = 1.0 - (p - 5.0) / 6.0 * x
    t = 1.0 - (p - 4.0) * 0.2 * x * t
    t = 1.0 - (p - 3.0) * 0.25 * x * t
    t = 1.0 - (p - 2.0) / 3.0 * x * t
    series = p * (1.0 - (p - 1.0) * 0.5 * x * t)
    closed = (1.0 - pow(1.0 - x, p)) / max(x, SERIES_BELOW)
    return series if x < SERIES_BELOW else closed


def diffuse(NdotL: float, NdotV: float, LdotV: float, rho_d: vec3, alpha: float, f0: vec3) -> vec3:
    s = alpha
    s2 = s * s
    d = s2 + 1.36053
    x_e = 1.0 - NdotV
    F_r = ((1.0 - (0.542026 * s2 + 0.303573 * s) / d)
           * (1.0 - pow(x_e, 5.0 - 4.0 * s2) / d)
           * ((-0.733996 * s2 * s + 1.50912 * s2 - 1.16402 * s) * pow(x_e, 1.0 + 1.0 / (39.0 * s2 * s2 + 1.0)) + 1.0))
    # L_m / n.l
    L_m = ((max(1.0 - 2.0 * s, 0.0) * one_minus_pow5_complement(NdotL) + min(2.0 * s, 1.0))
           * ((1.0 - 0.5 * s) + 0.5 * s * NdotL))
    p = (1.0 - 0.3726732 * NdotV * NdotV) / (0.188566 + 0.388410 * NdotV)
    # V_d / n.l
    V_d = s2 / ((s2 + 0.09) * (1.31072 + 0.995584 * NdotV)) * one_minus_pow_over_x(NdotL, p)
    c = LdotV - NdotV * NdotL
    B_p = 1.4 * NdotV * NdotL * c if c < 0.0 else c
    L_r = max(F_r * L_m + V_d * B_p, 0.0)
    return rho_d * (vec3(1.0) - f0) * (1.05 * INV_PI * L_r)
