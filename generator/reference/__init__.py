"""Float64 ground truth: the BRDF of a spec and exact forms of the quantities bricks approximate.

Written from the papers (each function cites paper and equation), independent
of the brick sources. Public names:

Whole BRDFs (models.py)
  reference_brdf(spec, L, V, N, T=None, params=None, lib=None) -> (N, 3) float64 f_r,
      under the shading policy of docs/design/accuracy.md (f_r = 0 for n·l <= 0, n·v clamped to [1e-4, 1]).
  REFERENCES[kind][brick_id], reference(kind, id) (decorator), lookup(kind, id),
  missing_references(lib), brdf_parameters(resolved BRDF), ReferenceMissing.
Geometry (geometry.py)
  shading_geometry(L, V, N, T=None) -> Geometry (NdotL, NdotV, NdotH, NxH2, VdotH, ...: the inputs table), NV_MIN.
Exact quantities (exact.py); cosines in [0, 1], alpha = GGX α or Beckmann m
  NDFs:     d_ggx(cos_h, sin2_h, alpha), d_beckmann(...), d_blinn_phong(...),
            blinn_phong_exponent(alpha), cos_power(cos, sin2, n)
  Fresnel:  fresnel_schlick(f0, cos_d), fresnel_dielectric(cos_d, eta), f0_to_eta(f0),
            fresnel_dielectric_f0(f0, cos_d), fresnel_conductor(cos_d, eta, k)
  Smith:    lambda_ggx(cos, alpha), lambda_beckmann(cos, alpha) (erfc form),
            smith_g1_ggx, smith_g1_beckmann, smith_g_separable(NdotL, NdotV, alpha, lam),
            smith_g_correlated(NdotL, NdotV, alpha, lam), smith_schlick_g1(cos, k),
            schlick_k_beckmann(alpha), g_torrance_sparrow(NdotH, NdotV, NdotL, VdotH)
"""
from .exact import (blinn_phong_exponent, cos_power, d_beckmann, d_blinn_phong, d_ggx, f0_to_eta,
                    fresnel_conductor, fresnel_dielectric, fresnel_dielectric_f0, fresnel_schlick,
                    g_torrance_sparrow, lambda_beckmann, lambda_ggx, schlick_k_beckmann,
                    smith_g1_beckmann, smith_g1_ggx, smith_g_correlated, smith_g_separable,
                    smith_schlick_g1)
from .geometry import NV_MIN, Geometry, shading_geometry
from .models import (REFERENCES, ReferenceMissing, brdf_parameters, lookup, missing_references,
                     reference, reference_brdf)

__all__ = [
    "reference_brdf", "REFERENCES", "reference", "lookup", "missing_references", "brdf_parameters",
    "ReferenceMissing", "shading_geometry", "Geometry", "NV_MIN",
    "d_ggx", "d_beckmann", "d_blinn_phong", "blinn_phong_exponent", "cos_power",
    "fresnel_schlick", "fresnel_dielectric", "f0_to_eta", "fresnel_dielectric_f0", "fresnel_conductor",
    "lambda_ggx", "lambda_beckmann", "smith_g1_ggx", "smith_g1_beckmann", "smith_g_separable",
    "smith_g_correlated", "smith_schlick_g1", "schlick_k_beckmann", "g_torrance_sparrow",
]
