"""Float64 references of level of detail for normal-mapped highlights: Toksvig's factor and the course's
per-MIP exponent reduction, and the ground truth they approximate (the BRDF averaged over a footprint).

Hoffman & Baker 2006, "Texture Filtering Review" … "Better Hack: Level of Detail": a MIP level of a
normal map averages normals, and a nonlinear BRDF of the averaged normal is not the average of the
BRDF, Σ_r W_r (N_r·H)^p ≠ (H·Σ_r W_r N_r)^p ("Blinn-Phong isn't Linear"): minified, the highlight
is too narrow and too bright ("The Stanford bunny is much too shiny when highly minified") and it
shimmers. The course's hack: "decreasing the n parameter by about 30% for each MIP level"
(n = 32, 24, 18, 12, 7), "just an heuristic". Its list of solutions starts with Toksvig's.

Toksvig 2005, "Mipmapping Normal Maps", JGT 10(3) (NVIDIA technical brief TB-01256, 2004), sections
"Estimating Normal Variation" and "Eliminating Aliasing of Specular Highlights": the length
|N_a| ≤ 1 of the box-filtered (unnormalized) normal measures the spread of the normals it averages.
For a Gaussian spread of per-axis angular variance σ², |N_a| ≈ 1/(1 + σ²), so

    σ² = (1 − |N_a|) / |N_a|,
    f_t = |N_a| / (|N_a| + n (1 − |N_a|)),    n' = f_t n      (f_t: the "Toksvig factor"),

i.e. 1/n' = 1/n + σ²: the Blinn-Phong lobe cos^n θ ≈ exp(−n θ²/2) is a Gaussian of variance 1/n,
and the footprint's variance adds to it. The same variance added to a microfacet roughness, with
Walter et al. 2007 eq. 30's n = 2/α² − 2 (α² ≈ 2/n: Beckmann's per-axis slope variance is α²/2,
as in LEAN mapping, Olano & Baker 2010, and in the "roughness² += 2 variance" of Kaplanyan, Hill,
Patney & Lefohn 2016, "Filtering Distributions of Normals for Shading Antialiasing", and Tokuyoshi &
Kaplanyan 2019):

    α'² = α² + 2 σ² = α² + 2 (1 − |N_a|) / |N_a|.

The factor 2 is measured, not assumed (tests/library/test_lod.py): with α'² = α² + σ² (the form without it,
sometimes quoted) the GGX highlight's patch error at MIP levels 3–6 is 1.5–2.1 times that with 2σ².

The course's reduction for α goes through the same eq. 30: n(α) = 2/α² − 2 scaled by (1 − r)^lod,
then α back from n. All functions take arrays (broadcast) and return float64.
"""
from __future__ import annotations

import numpy as np

from .exact import blinn_phong_exponent

COURSE_REDUCTION = 0.3  # Hoffman & Baker 2006: "decreasing the n parameter by about 30% for each MIP level"


def _f(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)


# ------------------------------------------------------------------ Toksvig 2005

def normal_variance(length) -> np.ndarray:
    """σ² = (1 − |N_a|)/|N_a|, the per-axis angular variance of the normals a filtered normal of length |N_a|
    averages (Toksvig 2005: |N_a| = 1/(1 + σ²) for a Gaussian spread)."""
    a = _f(length)
    return (1.0 - a) / a


def toksvig_factor(length, n) -> np.ndarray:
    """f_t = |N_a| / (|N_a| + n (1 − |N_a|)) (Toksvig 2005)."""
    a, n = _f(length), _f(n)
    return a / (a + n * (1.0 - a))


def toksvig_exponent(n, length) -> np.ndarray:
    """n' = f_t n: the Blinn-Phong exponent of a filtered normal of length |N_a| (Toksvig 2005)."""
    return toksvig_factor(length, n) * _f(n)


def toksvig_alpha(alpha, length) -> np.ndarray:
    """α' = sqrt(α² + 2σ²): Toksvig's variance added to a microfacet roughness (α² ≈ 2/n, Walter et al. 2007
    eq. 30)."""
    a = _f(alpha)
    return np.sqrt(a * a + 2.0 * normal_variance(length))


# ------------------------------------------------------------------ the course's per-MIP reduction

def mip_exponent(n, lod, reduction=COURSE_REDUCTION) -> np.ndarray:
    """n (1 − r)^lod: the course's exponent reduction, r per MIP level (Hoffman & Baker 2006, about 30 %)."""
    return _f(n) * (1.0 - _f(reduction)) ** _f(lod)


def mip_alpha(alpha, lod, reduction=COURSE_REDUCTION) -> np.ndarray:
    """The course's reduction applied to α through n = 2/α² − 2 (Walter et al. 2007 eq. 30):
    α' = sqrt(2/(n' + 2))."""
    n = mip_exponent(blinn_phong_exponent(alpha), lod, reduction)
    return np.sqrt(2.0 / (n + 2.0))


def lod_exponent(n, length, lod=0.0, reduction=0.0, toksvig_weight=1.0) -> np.ndarray:
    """What `toksvig_n` provides: the course's reduction, then Toksvig's variance scaled by toksvig_weight
    (1/n' = 1/n_lod + w σ²; w = 1 is toksvig_exponent, w = 0 is mip_exponent)."""
    n_lod = mip_exponent(n, lod, reduction)
    return 1.0 / (1.0 / n_lod + _f(toksvig_weight) * normal_variance(length))


def lod_alpha(alpha, length, lod=0.0, reduction=0.0, toksvig_weight=1.0) -> np.ndarray:
    """What `toksvig_alpha` provides (before its α ≤ 1 cap): α'² = α_lod² + 2 w σ²."""
    a = mip_alpha(alpha, lod, reduction)
    return np.sqrt(a * a + 2.0 * _f(toksvig_weight) * normal_variance(length))


# ------------------------------------------------------------------ MIP chains and footprints

def mip_chain(normals) -> list[np.ndarray]:
    """Box-filtered MIP levels of a (2^m, 2^m, 3) tangent-space normal map, unnormalized: level k averages
    2^k × 2^k texels of level 0 (what a GPU's 2 × 2 box filter of a linear (t + 1)/2 encoding gives)."""
    t = _f(normals)
    size = t.shape[0]
    if t.shape[:2] != (size, size) or size & (size - 1):
        raise ValueError(f"a square power-of-two normal map is needed, got {t.shape}")
    chain = [t]
    while chain[-1].shape[0] > 1:
        s = chain[-1].shape[0] // 2
        chain.append(chain[-1].reshape(s, 2, s, 2, -1).mean((1, 3)))
    return chain


def footprint_mean(field, level: int) -> np.ndarray:
    """The mean of a level-0 field (2^m, 2^m, …) over each texel footprint of MIP level `level`
    (2^level × 2^level texels): the ground truth a level-`level` texel should shade to."""
    f = _f(field)
    s, k = f.shape[0] >> level, 1 << level
    return f.reshape(s, k, s, k, *f.shape[2:]).mean((1, 3))
