"""Kelemen & Szirmay-Kalos visibility term: V = 1 / (4 (v.h)^2).

Kelemen & Szirmay-Kalos 2001, "A Microfacet Based Coupled Specular-Matte BRDF Model with
Importance Sampling"; RTR3 §7.6.1 eq. 7.55 (seed 001): G / (cos theta_i cos theta_o)
~ 2 / (1 + l.v) = 4 / (h'.h') = 1 / cos^2 alpha_h, h' = l + v unnormalized, alpha_h the
angle between v and h. Divided by 4: V = 1 / (2 (1 + l.v)) = 1 / (4 (v.h)^2) (ACCURACY-FACTS
§4.11). Reciprocal (v.h = l.h); independent of roughness.
Near l = -v the glue's v.h is ill-conditioned in float32 (h = normalize(l + v) with |l + v| =
2 v.h): measured on the stress set, relative error 0.91 at the grazing mirror with cosines 1e-4
(v.h = 1e-4, at the floor below) and 1.0 where float32 rounds v.h to 0 (V = 0, reference ~1e10);
2e-4 at cosines 1e-2; 1.6e-5 on the hemisphere.
"""
BRICK = {
    "kind": "visibility",
    "cite": "Kelemen & Szirmay-Kalos 2001; RTR3 eq. 7.55",
}

# (v.h)^2 is floored at 1e-8 (v.h at 1e-4): v.h -> 0 only as l -> -v (ACCURACY-FACTS pitfall 3),
# where 1/(v.h)^2 -> inf. Cost: V is capped at 2.5e7 where l and v are within 0.0115 degrees of
# opposite. At v.h = 0 exactly (the undefined half vector h = 0) V is 0, as the reference's
# (and the V-cavity's) G there.
VH2_MIN = 1e-8


def vis(NdotL: float, NdotV: float, NdotH: float, VdotH: float, alpha: float) -> float:
    return 0.25 / max(VdotH * VdotH, VH2_MIN) if VdotH > 0.0 else 0.0
