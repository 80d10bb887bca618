"""Float64 references of the microfacet slot fillers beyond models.py's basic ones (anisotropic NDFs, Ward,
exact and spherical-Gaussian Fresnel, the Smith and approximate visibility terms), written from the papers.

Registered in models.REFERENCES (imported at the end of models.py). Signatures per kind
(models.py): ndf f(cos_h, sin2_h, alpha[, *, g, p]) -> D; fresnel f(f0, cos_d[, *, p]) -> F;
visibility f(g, alpha[, *, p]) -> G (the geometry factor, not V = G / (4 n·l n·v)).
Each is computed from its paper's formula in float64 under the shading policy of docs/design/accuracy.md
(generator/reference/geometry.py); brick guards (roughness floors, cosine floors) are not
reproduced. Where an exact helper exists in exact.py (Smith Λ with erfc, exact Fresnel)
it is used: the bricks' algebra (cancellation-free rewrites, the erfc fit) is theirs alone.
"""
from __future__ import annotations


import numpy as np

from . import exact
from .geometry import Geometry
from .models import reference


def _f(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)


# ------------------------------------------------------------------ normal distributions

def _cos2_phi(g: Geometry) -> np.ndarray:
    """cos²φ_h, φ_h the azimuth of h in the tangent frame; 1 (φ_h = 0) where h has no tangent component."""
    t2, b2 = g["HdotT"] ** 2, g["HdotB"] ** 2
    tb2 = t2 + b2
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(tb2 > 0.0, t2 / tb2, 1.0)


def _elliptic(g: Geometry, au, av) -> np.ndarray:
    """e = cos²φ_h / α_u² + sin²φ_h / α_v²: tan²θ_h e is the exponent of the elliptical Gaussian of slopes."""
    c2p = _cos2_phi(g)
    return c2p / (au * au) + (1.0 - c2p) / (av * av)


def _aniso_alphas(p: dict):
    return _f(p["alpha_u"]), _f(p["alpha_v"])


@reference("ndf", "ggx_anisotropic")
def ndf_ggx_anisotropic(cos_h, sin2_h, alpha, *, g: Geometry, p: dict):
    """Anisotropic GGX D = 1 / (π α_u α_v cos⁴θ_h (1 + tan²θ_h (cos²φ_h/α_u² + sin²φ_h/α_v²))²)
    (Heitz 2014 eq. 85), cos⁴θ_h multiplied out. α_u or α_v = 0: the Dirac limit at h = n."""
    c, s2 = _f(cos_h), _f(sin2_h)
    au, av = _aniso_alphas(p)
    ok = (au > 0.0) & (av > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        au1, av1 = np.where(ok, au, 1.0), np.where(ok, av, 1.0)
        d = c * c + s2 * _elliptic(g, au1, av1)
        D = 1.0 / (np.pi * au1 * av1 * d * d)
    return np.where(ok, D, exact._delta(c, s2))


@reference("ndf", "beckmann_anisotropic")
def ndf_beckmann_anisotropic(cos_h, sin2_h, alpha, *, g: Geometry, p: dict):
    """Anisotropic Beckmann D = exp(-tan²θ_h (cos²φ_h/α_u² + sin²φ_h/α_v²)) / (π α_u α_v cos⁴θ_h)
    (Heitz 2014 eq. 82; Ward 1992 eq. 5a's elliptical Gaussian). 0 at θ_h = 90°; Dirac at α = 0."""
    c, s2 = _f(cos_h), _f(sin2_h)
    au, av = _aniso_alphas(p)
    ok = (au > 0.0) & (av > 0.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        au1, av1 = np.where(ok, au, 1.0), np.where(ok, av, 1.0)
        c2 = c * c
        D = np.exp(-(s2 / c2) * _elliptic(g, au1, av1)) / (np.pi * au1 * av1 * c2 * c2)
        D = np.where(c > 0.0, D, 0.0)
    return np.where(ok, D, exact._delta(c, s2))


@reference("ndf", "ward")
def ndf_ward(cos_h, sin2_h, alpha):
    """Ward's isotropic Gaussian as a distribution of h: D = exp(-tan²θ_h/m²) / (π m² cos³θ_h), m = α
    (Ward 1992 eq. 4; Walter 2005). Normalized in solid angle (∫ D dω_h = 1). 0 at θ_h = 90°."""
    c, s2, m = _f(cos_h), _f(sin2_h), _f(alpha)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        m2 = np.where(m > 0.0, m * m, 1.0)
        D = np.exp(-(s2 / (c * c)) / m2) / (np.pi * m2 * c ** 3)
        D = np.where(c > 0.0, D, 0.0)
    return np.where(m > 0.0, D, exact._delta(c, s2))


# ------------------------------------------------------------------ Fresnel

def _per_channel(f0, cos_d):
    f0, c = _f(f0), _f(cos_d)
    return f0, (c[..., None] if f0.ndim > c.ndim else c)


@reference("fresnel", "spherical_gaussian")
def fresnel_spherical_gaussian(f0, cos_d):
    """F = f0 + (1 - f0) 2^(-9.60232 cos⁸θ - 8.58092 cos θ) (Gotanda 2014 eq. 3)."""
    f0, c = _per_channel(f0, cos_d)
    return f0 + (1.0 - f0) * np.exp2(-9.60232 * c ** 8 - 8.58092 * c)


@reference("fresnel", "dielectric_exact")
def fresnel_dielectric_exact(f0, cos_d):
    """Exact unpolarized dielectric Fresnel at the index η = (1 + √f0)/(1 - √f0) (Gotanda 2014 eq. 2
    is this with η eliminated; computed from the η form, Walter et al. 2007 eq. 22). f0 = 0 is η = 1,
    no interface: F = 0 at every angle; f0 = 1 a perfect mirror, F = 1."""
    f0, c = _per_channel(f0, cos_d)
    f = exact.fresnel_dielectric_f0(f0, np.broadcast_to(c, np.broadcast_shapes(f0.shape, c.shape)))
    return np.where(f0 <= 0.0, 0.0, f)


def gotanda_eq2(f0, cos) -> np.ndarray:
    """Gotanda 2014 eq. 2 as printed, in float64 (for 0 < f0 < 1 and cos > 0: tests cross-check it)."""
    s, c = np.sqrt(_f(f0)), _f(cos)
    a = np.sqrt(1.0 - (s - 1.0) ** 2 * (1.0 - c * c) / (s + 1.0) ** 2)
    r1 = ((s + 1.0) * c + (s - 1.0) * a) / ((s + 1.0) * c - (s - 1.0) * a)
    r2 = ((s - 1.0) * c + (s + 1.0) * a) / ((s - 1.0) * c - (s + 1.0) * a)
    return 0.5 * (r1 * r1 + r2 * r2)


@reference("fresnel", "conductor_exact")
def fresnel_conductor_exact(f0, cos_d, *, p: dict):
    """Exact unpolarized Fresnel at the complex index η + ik per channel (Born & Wolf §14.2), f0 unused.

    The degenerate index η = 1, k = 0 at cos = 0 (0/0) is its limit 0 (no interface)."""
    f0, c = _per_channel(f0, cos_d)
    eta = np.broadcast_to(_f(p["eta"]), f0.shape if f0.ndim else (3,))
    k = np.broadcast_to(_f(p["k"]), eta.shape)
    f = fresnel_complex(c, eta, k)
    return np.where(np.isnan(f), 0.0, f)


def fresnel_complex(cos, eta, k) -> np.ndarray:
    """Unpolarized Fresnel reflectance at the complex index ñ = η + ik (Born & Wolf §1.5.2, §14.2):
    r_s = (c - ñ cos θ_t)/(c + ñ cos θ_t), r_p = (ñ² c - ñ cos θ_t)/(ñ² c + ñ cos θ_t),
    F = (|r_s|² + |r_p|²)/2,
    with ñ cos θ_t = sqrt((ñ² - 1) + c²): the same as exact.fresnel_conductor's sqrt(ñ² - sin²θ), summed
    so that ñ = 1 keeps its digits at grazing c (no interface: F = 0, not the rounding of 1 - (1 - c²))."""
    c = _f(cos).astype(np.complex128)
    n = _f(eta) + 1j * _f(k)
    et = np.sqrt((n * n - 1.0) + c * c)
    with np.errstate(divide="ignore", invalid="ignore"):
        rs = (c - et) / (c + et)
        rp = (n * n * c - et) / (n * n * c + et)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


# ------------------------------------------------------------------ visibility (G)

@reference("visibility", "kelemen_szirmay_kalos")
def vis_kelemen_szirmay_kalos(g: Geometry, alpha):
    """G / (cos θ_i cos θ_o) = 2 / (1 + l·v) (Kelemen & Szirmay-Kalos 2001; RTR3 eq. 7.55).
    l = -v (undefined h): G = 0, as the V-cavity G it approximates (exact.g_torrance_sparrow)."""
    s = 1.0 + g.LdotV
    with np.errstate(divide="ignore", invalid="ignore"):
        G = 2.0 * g.NdotL * g.NdotV / s
    return np.where(s > 0.0, G, 0.0)


@reference("visibility", "neumann")
def vis_neumann(g: Geometry, alpha):
    """G / (cos θ_i cos θ_o) = 1 / max(cos θ_i, cos θ_o) (Neumann et al. 1999; RTR3 §7.6.1)."""
    return g.NdotL * g.NdotV / np.maximum(g.NdotL, g.NdotV)


@reference("visibility", "ashikhmin_premoze")
def vis_ashikhmin_premoze(g: Geometry, alpha):
    """G / (cos θ_i cos θ_o) = 1 / (cos θ_i + cos θ_o - cos θ_i cos θ_o)
    (Ashikhmin & Premože 2007; RTR3 §7.6.1)."""
    nl, nv = g.NdotL, g.NdotV
    return nl * nv / (nl + nv - nl * nv)


def schlick_k_ggx(alpha) -> np.ndarray:
    """k = α/2, Schlick's G1 fitted to Smith GGX (Karis 2013)."""
    return 0.5 * _f(alpha)


@reference("visibility", "smith_schlick_ggx")
def vis_smith_schlick_ggx(g: Geometry, alpha):
    """G = G1(l) G1(v), Schlick's G1 = cos/(cos (1-k) + k) with k = α/2 (Schlick 1994; RTR3 eq. 7.56; Karis 2013)."""
    k = schlick_k_ggx(alpha)
    return exact.smith_schlick_g1(g.NdotL, k) * exact.smith_schlick_g1(g.NdotV, k)


@reference("visibility", "smith_ggx_separable")
def vis_smith_ggx_separable(g: Geometry, alpha):
    """Separable Smith G = G1(l) G1(v), exact GGX Λ (Walter et al. 2007 eq. 23 and 34)."""
    return exact.smith_g_separable(g.NdotL, g.NdotV, alpha, exact.lambda_ggx)


@reference("visibility", "smith_ggx_height_correlated")
def vis_smith_ggx_height_correlated(g: Geometry, alpha):
    """Height-correlated Smith G = 1/(1 + Λ(l) + Λ(v)), exact GGX Λ (Heitz 2014 eq. 99 and 86)."""
    return exact.smith_g_correlated(g.NdotL, g.NdotV, alpha, exact.lambda_ggx)


@reference("visibility", "smith_beckmann")
def vis_smith_beckmann(g: Geometry, alpha):
    """Separable Smith G = G1(l) G1(v), exact Beckmann Λ with erfc (Walter et al. 2007 eq. 23 and 27)."""
    return exact.smith_g_separable(g.NdotL, g.NdotV, alpha, exact.lambda_beckmann)


def lambda_ggx_anisotropic(cos, x_t, x_b, alpha_u, alpha_v) -> np.ndarray:
    """Anisotropic GGX Λ = (-1 + sqrt(1 + α_o² tan²θ))/2,
    α_o² tan²θ = (α_u² (x·t)² + α_v² (x·b)²)/cos²θ
    (Heitz 2014 eq. 86 with the projected roughness of eq. 80). Λ → ∞ at cos = 0 (unless both α are 0)."""
    c = _f(cos)
    num = _f(alpha_u) ** 2 * _f(x_t) ** 2 + _f(alpha_v) ** 2 * _f(x_b) ** 2
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        X = num / (c * c)
        lam = 0.5 * X / (1.0 + np.sqrt(1.0 + X))
    lam = np.where(num == 0.0, 0.0, lam)
    return np.where(np.isnan(lam), np.inf, lam)


@reference("visibility", "smith_ggx_height_correlated_anisotropic")
def vis_smith_ggx_height_correlated_anisotropic(g: Geometry, alpha, *, p: dict):
    """Height-correlated Smith G = 1/(1 + Λ(l) + Λ(v)) with the anisotropic GGX Λ (Heitz 2014 eq. 99, 86, 80)."""
    au, av = _aniso_alphas(p)
    ll = lambda_ggx_anisotropic(g.NdotL, g["LdotT"], g["LdotB"], au, av)
    lv = lambda_ggx_anisotropic(g.NdotV, g["VdotT"], g["VdotB"], au, av)
    return 1.0 / (1.0 + ll + lv)

