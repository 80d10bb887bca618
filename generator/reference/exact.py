"""Exact float64 formulas: normal distributions, Fresnel reflectance, Smith masking.

Each function is written from its paper (cited per function) in the form that
keeps its digits in float64 at the extremes: sin²θ_h comes from |n × h|²
instead of 1 - cos², tails use erfc instead of 1 - erf, cos^n uses log1p.
They are the ground truth of the brick references (models.py) and of the
approximations the bricks make (Schlick's Fresnel, Schlick's Smith G).

Conventions: cosines are arrays in [0, 1]; alpha is the GGX α or the Beckmann
RMS slope m (scalar or per-sample array). alpha = 0 is the limit of a perfect
mirror: an NDF is then a Dirac delta, returned as +inf at h = n and 0 elsewhere.
"""
from __future__ import annotations

import math

import numpy as np

_ERFC = np.frompyfunc(math.erfc, 1, 1)
SQRT_PI = math.sqrt(math.pi)


def _f(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)


# sin²θ_h at or below this is h = n up to float64 rounding of the directions (θ_h <= 1e-12 rad).
PEAK_SIN2 = 1e-24


def _delta(cos_h, sin2_h) -> np.ndarray:
    """The alpha -> 0 limit of a normalized NDF: +inf at h = n (to rounding), else 0."""
    return np.where((sin2_h <= PEAK_SIN2) & (cos_h > 0.0), np.inf, 0.0)


# ------------------------------------------------------------------ normal distributions

def d_ggx(cos_h, sin2_h, alpha) -> np.ndarray:
    """GGX / Trowbridge-Reitz D = α² / (π (α² cos²θ_h + sin²θ_h)²) (Walter et al. 2007 eq. 33).

    Eq. 33 is α² / (π cos⁴θ (α² + tan²θ)²); multiplying out cos⁴θ gives this form,
    which has no cancellation as θ_h → 0.
    """
    c, s2, a = _f(cos_h), _f(sin2_h), _f(alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        a2 = a * a
        d = a2 * c * c + s2
        return np.where(a > 0.0, a2 / (np.pi * d * d), _delta(c, s2))


def d_beckmann(cos_h, sin2_h, alpha) -> np.ndarray:
    """Beckmann D = exp(-tan²θ_h / m²) / (π m² cos⁴θ_h) (Walter et al. 2007 eq. 25; Cook & Torrance 1982 eq. 5)."""
    c, s2, a = _f(cos_h), _f(sin2_h), _f(alpha)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a2 = a * a
        c2 = c * c
        d = np.exp(-(s2 / c2) / a2) / (np.pi * a2 * c2 * c2)
        d = np.where(c > 0.0, d, 0.0)  # the limit as θ_h → 90°
        return np.where(a > 0.0, d, _delta(c, s2))


def blinn_phong_exponent(alpha) -> np.ndarray:
    """n = 2/α² - 2, the Blinn-Phong exponent equivalent to Beckmann roughness α (Walter et al. 2007 eq. 30)."""
    a = _f(alpha)
    with np.errstate(divide="ignore"):
        return 2.0 / (a * a) - 2.0


def cos_power(cos, sin2, n) -> np.ndarray:
    """cos^n θ, from sin²θ as exp(n/2 · log1p(-sin²θ)) near θ = 0 (exact for huge n), else pow; 0^0 = 1."""
    c, s2, n = _f(cos), _f(sin2), _f(n)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        v = np.where(c * c > 0.5, np.exp(0.5 * n * np.log1p(-s2)), np.maximum(c, 0.0) ** n)
    return np.where(n == 0.0, 1.0, v)


def d_blinn_phong(cos_h, sin2_h, alpha) -> np.ndarray:
    """Normalized Blinn-Phong D = (n+2)/(2π) cos^n θ_h, n = 2/α² - 2 (RTR3 eq. 7.48; Walter et al. 2007 eq. 30)."""
    c, s2, a = _f(cos_h), _f(sin2_h), _f(alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        n = blinn_phong_exponent(np.where(a > 0.0, a, 1.0))
        d = (n + 2.0) / (2.0 * np.pi) * cos_power(c, s2, n)
    return np.where(a > 0.0, d, _delta(c, s2))


# ------------------------------------------------------------------ Fresnel

def fresnel_schlick(f0, cos_d) -> np.ndarray:
    """Schlick's approximation F = f0 + (1 - f0)(1 - cos θ_d)^5 (Schlick 1994 eq. 15; RTR3 eq. 7.40)."""
    f0, c = _f(f0), _f(cos_d)
    x = (1.0 - c)[..., None] if f0.ndim > c.ndim else 1.0 - c
    return f0 + (1.0 - f0) * x ** 5


def fresnel_dielectric(cos_d, eta) -> np.ndarray:
    """Exact unpolarized Fresnel reflectance of a dielectric interface of relative index eta.

    F = ½ (g-c)²/(g+c)² (1 + (c(g+c) - 1)²/(c(g-c) + 1)²), g² = η² - 1 + c²
    (Cook & Torrance 1982, Fresnel equation of §"The Fresnel term"; Walter et al. 2007 eq. 22).
    Total internal reflection (g² < 0, possible for η < 1) gives 1.
    """
    c, eta = _f(cos_d), _f(eta)
    g2 = eta * eta - 1.0 + c * c
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.sqrt(np.maximum(g2, 0.0))
        a = (g - c) / (g + c)
        b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
        f = 0.5 * a * a * (1.0 + b * b)
    return np.where(g2 > 0.0, f, 1.0)


def f0_to_eta(f0) -> np.ndarray:
    """The relative index with normal-incidence reflectance f0: η = (1 + √f0) / (1 - √f0) (f0 = ((η-1)/(η+1))²)."""
    s = np.sqrt(_f(f0))
    with np.errstate(divide="ignore"):
        return (1.0 + s) / (1.0 - s)


def fresnel_dielectric_f0(f0, cos_d) -> np.ndarray:
    """Exact dielectric Fresnel, parameterized by f0 per channel (f0 = 1: a perfect mirror, F = 1).

    f0: (..., 3) or scalar; cos_d: (...). Returns f0's shape broadcast with cos_d.
    """
    f0, c = _f(f0), _f(cos_d)
    if f0.ndim > c.ndim:
        c = c[..., None]
    eta = f0_to_eta(np.minimum(f0, 1.0 - 1e-16))
    return np.where(f0 >= 1.0, 1.0, fresnel_dielectric(c, eta))


def fresnel_conductor(cos_d, eta, k) -> np.ndarray:
    """Exact unpolarized Fresnel reflectance for a complex index η + ik (k = 0: a dielectric).

    r_s = (cos θ - η̃ cos θ_t)/(cos θ + η̃ cos θ_t), r_p = (η̃ cos θ - cos θ_t)/(η̃ cos θ + cos θ_t),
    η̃ cos θ_t = sqrt(η̃² - sin²θ), F = (|r_s|² + |r_p|²)/2 (the Fresnel equations with a
    complex index: Born & Wolf, Principles of Optics, §1.5.2 and §14.2; pbrt-v4 §9.3.6).
    """
    c = _f(cos_d).astype(np.complex128)
    n = _f(eta) + 1j * _f(k)
    et = np.sqrt(n * n - (1.0 - c * c))  # η̃ cos θ_t (principal root: Im ≥ 0, decaying wave)
    with np.errstate(divide="ignore", invalid="ignore"):
        rs = (c - et) / (c + et)
        rp = (n * n * c - et) / (n * n * c + et)
    return np.real(0.5 * (rs * np.conj(rs) + rp * np.conj(rp)))


# ------------------------------------------------------------------ Smith masking

def _tan2(cos) -> np.ndarray:
    c = _f(cos)
    with np.errstate(divide="ignore"):
        return (1.0 - c) * (1.0 + c) / (c * c)


def lambda_ggx(cos, alpha) -> np.ndarray:
    """Smith Λ for GGX: Λ = (-1 + sqrt(1 + α² tan²θ)) / 2 (Heitz 2014 eq. 86; Walter et al. 2007 eq. 34)."""
    a = _f(alpha)
    with np.errstate(invalid="ignore", over="ignore"):
        x = a * a * _tan2(cos)
        lam = 0.5 * x / (1.0 + np.sqrt(1.0 + x))  # = (sqrt(1+x) - 1)/2 without cancellation
    return np.where(np.isnan(lam), np.inf, lam)  # inf/inf at cos = 0: Λ → ∞


def lambda_beckmann(cos, alpha) -> np.ndarray:
    """Smith Λ for Beckmann: Λ = (exp(-a²)/(a√π) - erfc(a)) / 2, a = 1/(m tanθ)

    (Walter et al. 2007 eq. 27, G1 = 1/(1 + Λ); Heitz 2014 eq. 83), written with
    erfc so that it keeps its digits when Λ → 0 (large a).
    """
    c, m = _f(cos), _f(alpha)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a = c / (m * np.sqrt((1.0 - c) * (1.0 + c)))
        erfc = np.asarray(_ERFC(np.where(np.isfinite(a), a, 30.0)), dtype=np.float64)
        lam = 0.5 * (np.exp(-a * a) / (a * SQRT_PI) - erfc)
    lam = np.where(np.isinf(a) | (a > 30.0), 0.0, lam)  # θ = 0 or m → 0: no masking
    return np.where(c <= 0.0, np.inf, lam)


def smith_g1_ggx(cos, alpha) -> np.ndarray:
    """Exact Smith G1 for GGX = 1/(1 + Λ) = 2/(1 + sqrt(1 + α² tan²θ)) (Walter et al. 2007 eq. 34)."""
    return 1.0 / (1.0 + lambda_ggx(cos, alpha))


def smith_g1_beckmann(cos, alpha) -> np.ndarray:
    """Exact Smith G1 for Beckmann = 1/(1 + Λ), Λ in the erfc form (Walter et al. 2007 eq. 27)."""
    return 1.0 / (1.0 + lambda_beckmann(cos, alpha))


def smith_g_separable(NdotL, NdotV, alpha, lam=lambda_ggx) -> np.ndarray:
    """Separable Smith G2 = G1(l) G1(v) (Walter et al. 2007 eq. 23; Heitz 2014 eq. 98)."""
    return 1.0 / ((1.0 + lam(NdotL, alpha)) * (1.0 + lam(NdotV, alpha)))


def smith_g_correlated(NdotL, NdotV, alpha, lam=lambda_ggx) -> np.ndarray:
    """Height-correlated Smith G2 = 1/(1 + Λ(l) + Λ(v)) (Heitz 2014 eq. 99)."""
    return 1.0 / (1.0 + lam(NdotL, alpha) + lam(NdotV, alpha))


def smith_schlick_g1(cos, k) -> np.ndarray:
    """Schlick's Smith approximation G1 = cos θ / (cos θ (1 - k) + k) (Schlick 1994; RTR3 eq. 7.56)."""
    c, k = _f(cos), _f(k)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(c > 0.0, c / (c * (1.0 - k) + k), 0.0)


def schlick_k_beckmann(alpha) -> np.ndarray:
    """k = m sqrt(2/π), Schlick's fit to Smith-Beckmann (Schlick 1994; RTR3 eq. 7.56 with k = sqrt(2m²/π))."""
    return _f(alpha) * math.sqrt(2.0 / math.pi)


def g_torrance_sparrow(NdotH, NdotV, NdotL, VdotH) -> np.ndarray:
    """V-cavity G = min(1, 2 cosθ_h cosθ_o / cos α_h, 2 cosθ_h cosθ_i / cos α_h) (RTR3 eq. 7.54; Blinn 1977).

    cos α_h = v·h = 0 only for an undefined half vector (l = -v): G is then 0.
    """
    nh, vh = _f(NdotH), _f(VdotH)
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.minimum(1.0, np.minimum(2.0 * nh * _f(NdotV) / vh, 2.0 * nh * _f(NdotL) / vh))
    return np.where(vh > 0.0, g, 0.0)
