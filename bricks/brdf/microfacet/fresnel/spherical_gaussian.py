"""Gotanda's spherical Gaussian Fresnel: F = f0 + (1 - f0) 2^(-9.60232 cos^8 theta - 8.58092 cos theta).

Gotanda 2014, "Designing Reflectance Models for New Consoles", eq. 3 (seed 002), the
"improved spherical Gaussian" fitted to the exact Fresnel curve of refractive index 1.5,
with cos theta = v.h. It is not an approximation of Schlick's (1 - c)^5 (max |difference|
0.0388); it tracks the normalized exact dielectric curve (F - f0) / (1 - f0): max |error|
0.0075 at eta = 1.5, 0.0130 at 2.0, 0.0230 at 1.33 (ACCURACY-FACTS §4.12, asserted in
tests/library/test_library_fillers.py). Not to be confused with the UE4/Lagarde 2012 form
2^((-5.55473 c - 6.98316) c) (Gotanda's reference [8]).
cos^8 is three squarings (no pow); exp2 of an argument in [-18.2, 0] never overflows.
Measured in float32 within the microfacet host: 1.1e-6 on the hemisphere on every target.
"""
BRICK = {
    "kind": "fresnel",
    "cite": "Gotanda 2014 eq. 3",
}


def fresnel(f0: vec3, VdotH: float) -> vec3:
    # v.h is clamped to [0, 1] by the glue; a rounding excess over 1 only lowers the exponent.
    c = VdotH
    c2 = c * c
    c4 = c2 * c2
    w = exp2(-9.60232 * (c4 * c4) - 8.58092 * c)
    return f0 + (vec3(1.0) - f0) * w
