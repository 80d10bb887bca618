"""The diffuse bricks: closed forms, albedos by quadrature (ACCURACY-FACTS §4.7, §4.9),
the seed misprints they correct, and Gotanda's fit against the microfacet model it fits.

Bricks run through their NumPy float64 emission (generator.evaluate), references through
generator.reference. Albedo quadratures split the domain where the integrand has a kink
(θ_v = θ_l, where min/max switch; φ = ±90°, where max(0, cos φ) does), so Gauss-Legendre
converges fast; tolerances are a few times the error measured by doubling the nodes.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from generator.eval.evaluate import evaluate
from generator.reference import diffuse as ref_diffuse
from generator.reference import reference_brdf

Z = np.array([0.0, 0.0, 1.0])
QUALITATIVE = ["oren_nayar", "oren_nayar_simplified"]
ON_ALL = QUALITATIVE + ["oren_nayar_simplified_interreflection", "oren_nayar_improved"]


def _gl(a: float, b: float, n: int):
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) * (b - a) / 2 + a, w * (b - a) / 2


def _dirs(theta, phi):
    theta, phi = np.broadcast_arrays(theta, phi)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)


def _f(spec, L, V, params, target="numpy"):
    L, V = np.broadcast_arrays(L, V)
    N = np.broadcast_to(Z, L.shape)
    return evaluate(spec, L, V, N, params=params, target=target, dtype="float64")


def albedo(spec, params, theta_l, n=48, target="numpy"):
    """E(θ_l) = ∫ f(l, v) cos θ_v dω_v over v, panels split at θ_v = θ_l and φ = ±π/2."""
    edges_t = sorted({0.0, min(max(theta_l, 0.0), math.pi / 2), math.pi / 2})
    ts, wts = zip(*(_gl(a, b, n) for a, b in zip(edges_t[:-1], edges_t[1:]) if b > a))
    ps, wps = zip(*(_gl(a, b, n) for a, b in ((-math.pi / 2, math.pi / 2), (math.pi / 2, 3 * math.pi / 2))))
    t, wt, p, wp = (np.concatenate(x) for x in (ts, wts, ps, wps))
    T, P = np.meshgrid(t, p, indexing="ij")
    W = (wt * np.cos(t) * np.sin(t))[:, None] * wp[None, :]
    V = _dirs(T.ravel(), P.ravel())
    L = _dirs(theta_l, 0.0)
    f = _f(spec, L, V, params, target)
    return np.sum(f * W.ravel()[:, None], axis=0)


# ------------------------------------------------------------------ Oren-Nayar family

@pytest.mark.parametrize("spec", ON_ALL)
def test_oren_nayar_sigma_zero_is_exactly_one_over_pi(spec):
    # ACCURACY-FACTS §4.7: σ = 0 gives 1/π exactly (0.3183098861837907), at any l, v
    rng = np.random.default_rng(3)
    L = _dirs(np.arccos(rng.uniform(1e-3, 1, 200)), rng.uniform(0, 2 * np.pi, 200))
    V = _dirs(np.arccos(rng.uniform(1e-3, 1, 200)), rng.uniform(0, 2 * np.pi, 200))
    p = {"sigma": 0.0, "rho_d": [1.0, 1.0, 1.0]}
    for target in ("numpy", "reference"):
        f = _f(spec, L, V, p, target)
        assert np.all(np.abs(f - 1 / math.pi) <= 4e-16), (spec, target)


def _qualitative_albedo_1d(sigma: float, theta_l: float, n: int = 200) -> float:
    """E(θ_l) of eq. 30 reduced to one integral: ∫ max(0, cos φ) dφ = 2, so
    E = A + (2B/π) ∫ sin α tan β cos θ_v sin θ_v dθ_v (split at θ_v = θ_l)."""
    s2 = sigma * sigma
    A, B = 1 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09)
    total = 0.0
    for a, b in ((0.0, theta_l), (theta_l, math.pi / 2)):
        if b > a:
            t, w = _gl(a, b, n)
            total += np.sum(np.sin(np.maximum(theta_l, t)) * np.tan(np.minimum(theta_l, t)) * np.cos(t) * np.sin(t) * w)
    return A + 2 * B / math.pi * total


@pytest.mark.parametrize("spec", QUALITATIVE)
@pytest.mark.parametrize("sigma,facts", [(0.3, (0.892857, 0.938177, 0.991433)),
                                         (1.0, (0.624060, 0.707216, 0.804932))])
def test_qualitative_oren_nayar_albedo(spec, sigma, facts):
    # ACCURACY-FACTS §4.7 (σ in radians): E at 0°, 45°, 80°; E(0) = A exactly (tan β = 0). The 2-D
    # quadrature of the brick agrees with the 1-D reduction to 1e-9: 0.938176055, 0.991431191 (σ = 0.3),
    # 0.707214117, 0.804929963 (σ = 1). The figures of ACCURACY-FACTS are 1-2e-6 higher off normal
    # incidence (their quadrature's error, not ours: both of ours are converged to 1e-12 by doubling).
    p = {"sigma": sigma, "rho_d": [1.0, 1.0, 1.0]}
    for deg, e in zip((0.0, 45.0, 80.0), facts):
        got = albedo(spec, p, math.radians(deg))
        assert np.all(np.abs(got - _qualitative_albedo_1d(sigma, math.radians(deg))) <= 1e-9), (spec, sigma, deg, got)
        assert np.all(np.abs(got - e) <= 3e-6), (spec, sigma, deg, got)


def test_oren_nayar_c_a_is_the_papers_not_the_seeds():
    # Hoffman & Baker 2006 print C_A = 1 - σ²/(2σ² - 0.66); Oren & Nayar 1994: 1 - 0.5 σ²/(σ² + 0.33).
    # E(0) = C_A: the brick follows the paper; the printed form exceeds 1 for σ² < 0.33 (an albedo
    # above 1) and is singular at σ² = 0.33.
    for sigma in (0.3, 0.5, 1.0):
        s2 = sigma * sigma
        e0 = albedo("oren_nayar", {"sigma": sigma, "rho_d": [1.0, 1.0, 1.0]}, 0.0)
        assert np.all(np.abs(e0 - (1 - 0.5 * s2 / (s2 + 0.33))) <= 1e-12)
        assert np.all(e0 <= 1.0)
    assert 1 - 0.09 / (2 * 0.09 - 0.66) > 1.0  # the misprint at σ = 0.3: 1.1875


def test_interreflection_variant_albedo_at_normal_incidence():
    # RTR3 p. 263: 0.57 for 0.33 in A; E(0) = A
    for sigma in (0.3, 1.0):
        s2 = sigma * sigma
        e0 = albedo("oren_nayar_simplified_interreflection", {"sigma": sigma, "rho_d": [1.0, 1.0, 1.0]}, 0.0)
        assert np.all(np.abs(e0 - (1 - 0.5 * s2 / (s2 + 0.57))) <= 1e-12)


def test_rtr3_misprinted_sin_tan_order_would_diverge():
    # RTR3 eq. 7.57 prints sin(min θ) tan(max θ): infinite as one direction grazes. The brick (the
    # paper's sin(max) tan(min)) stays bounded: at θ_v = 89.9°, θ_l = 30°, φ = 0 it is A + B sin α tan β.
    sigma = 0.5
    s2 = sigma * sigma
    A, B = 1 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09)
    tl, tv = math.radians(30.0), math.radians(89.9)
    f = _f("oren_nayar_simplified", _dirs(tl, 0.0)[None], _dirs(tv, 0.0)[None], {"sigma": sigma, "rho_d": [1.0] * 3})
    assert f[0, 0] == pytest.approx((A + B * math.sin(tv) * math.tan(tl)) / math.pi, rel=1e-12)
    assert (A + B * math.sin(tl) * math.tan(tv)) / math.pi > 50 * f[0, 0]


@pytest.mark.parametrize("spec", QUALITATIVE)
def test_qualitative_needs_no_tangent_frame_and_is_finite_at_normal_incidence(spec):
    # l = n, v = n, l = v = n, and v below the horizon (grazing, with its azimuth; v = -n: no retro term)
    p = {"sigma": 1.0, "rho_d": [1.0, 1.0, 1.0]}
    L = np.array([Z, Z, _dirs(0.5, 0.0), _dirs(0.5, 0.0), _dirs(0.5, 0.0)])
    V = np.array([Z, _dirs(0.7, 1.0), Z, _dirs(math.pi / 2 + 0.2, 0.0), -Z])
    for dtype in ("float64", "float32"):
        f = evaluate(spec, L, V, np.broadcast_to(Z, L.shape), params=p, target="numpy", dtype=dtype)
        r = reference_brdf(spec, L, V, Z, params=p)
        assert np.all(np.isfinite(f))
        np.testing.assert_allclose(f, r, rtol=1e-5 if dtype == "float32" else 1e-12)
    s2 = 1.0
    A = 1 - 0.5 * s2 / (s2 + 0.33)
    assert f[0, 0] == pytest.approx(A / math.pi, rel=1e-6) and f[4, 0] == pytest.approx(A / math.pi, rel=1e-6)


def test_improved_equals_qualitative_term_on_the_forward_side():
    # ACCURACY-FACTS §4.7: s / max(n·l, n·v) = cos Δφ sin α tan β exactly for s >= 0. Gotanda's eq. 5
    # differs from eq. 30 there only by A's constant (0.65 for 0.33); for s < 0 it keeps B s.
    rng = np.random.default_rng(5)
    L = _dirs(np.arccos(rng.uniform(1e-3, 1, 2000)), rng.uniform(0, 2 * np.pi, 2000))
    V = _dirs(np.arccos(rng.uniform(1e-3, 1, 2000)), rng.uniform(0, 2 * np.pi, 2000))
    sigma = 0.7
    s2 = sigma * sigma
    p = {"sigma": sigma, "rho_d": [1.0, 1.0, 1.0]}
    on = _f("oren_nayar", L, V, p)[:, 0] * math.pi - (1 - 0.5 * s2 / (s2 + 0.33))
    imp = _f("oren_nayar_improved", L, V, p)[:, 0] * math.pi - (1 - 0.5 * s2 / (s2 + 0.65))
    s = np.einsum("ij,ij->i", L, V) - L[:, 2] * V[:, 2]
    fwd = s >= 0
    np.testing.assert_allclose(imp[fwd], on[fwd], rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(imp[~fwd], 0.45 * s2 / (s2 + 0.09) * s[~fwd], rtol=1e-10, atol=1e-13)
    assert np.all(on[~fwd] == 0.0)
    # and stays positive on the backward side (eq. 5's second case read as f = ρ/π (A + B s))
    assert np.all(_f("oren_nayar_improved", L, V, {"sigma": 1.57})[:, 0] > 0.0)


def test_oren_nayar_fresnel_closed_forms_and_clamp():
    # σ = 0: ρ/π (1 - f0) F_diff(l, e) with eq. 6's F_diff = 21/20 (1 - f0)(1 - (1-n·l)^5)(1 - (1-n·e)^5)
    rng = np.random.default_rng(9)
    cl, cv = rng.uniform(1e-3, 1, 500), rng.uniform(1e-3, 1, 500)
    L = _dirs(np.arccos(cl), rng.uniform(0, 2 * np.pi, 500))
    V = _dirs(np.arccos(cv), rng.uniform(0, 2 * np.pi, 500))
    for f0 in (0.0, 0.04, 0.5):
        f = _f("oren_nayar_fresnel", L, V, {"sigma": 0.0, "f0": [f0] * 3, "rho_d": [1.0] * 3})[:, 0]
        expected = (1 - f0) ** 2 * 1.05 * (1 - (1 - cl) ** 5) * (1 - (1 - cv) ** 5) / math.pi
        np.testing.assert_allclose(f, expected, rtol=1e-12)
    # grazing light on the backward side: F_diff A + B s < 0 there, clamped to 0 (brick and reference)
    L = _dirs(math.radians(89.5), 0.0)[None]
    V = _dirs(math.radians(60.0), math.pi)[None]
    for target in ("numpy", "reference"):
        assert _f("oren_nayar_fresnel", L, V, {"sigma": 1.0}, target)[0, 0] == 0.0
    # reciprocal everywhere, including where it clamps
    a = _f("oren_nayar_fresnel", L, V, {"sigma": 1.0})
    b = _f("oren_nayar_fresnel", V, L, {"sigma": 1.0})
    assert np.array_equal(a, b)


# ------------------------------------------------------------------ Ashikhmin-Shirley

@pytest.mark.parametrize("deg,expected", [(0.0, 0.968750), (45.0, 0.887108), (80.0, 0.365002)])
def test_ashikhmin_shirley_diffuse_albedo_closed_form(deg, expected):
    # ACCURACY-FACTS §4.9: E(μ) = ρ_d (1 - R_s)(1 - (1 - μ/2)^5) exactly
    mu = math.cos(math.radians(deg))
    assert (1 - (1 - mu / 2) ** 5) == pytest.approx(expected, abs=1e-6)
    for f0 in (0.0, 0.04, 0.5):
        p = {"rho_d": [1.0, 0.5, 0.25], "f0": [f0] * 3}
        e = albedo("ashikhmin_shirley_diffuse", p, math.radians(deg), n=24)
        np.testing.assert_allclose(e, np.array([1.0, 0.5, 0.25]) * (1 - f0) * (1 - (1 - mu / 2) ** 5), rtol=1e-10)


# ------------------------------------------------------------------ Gotanda's fit and the model it fits

def test_gotanda_fitted_is_not_reciprocal():
    # ACCURACY-FACTS §4.6: the fit's F_r reads n·e only, L_m n·l only (excluded from test_reciprocity)
    L = _dirs(math.radians(20.0), 0.0)[None]
    V = _dirs(math.radians(75.0), 2.0)[None]
    a, b = _f("gotanda_fitted", L, V, {}), _f("gotanda_fitted", V, L, {})
    assert abs(a[0, 0] - b[0, 0]) / a[0, 0] > 0.05


def test_gotanda_fitted_at_zero_roughness():
    # α = 0: V_d = 0, F_r = 1 - (1 - n·e)^5 / 1.36053, L_m / n·l = 1 - (1 - n·l)^5
    rng = np.random.default_rng(11)
    cl, cv = rng.uniform(1e-3, 1, 500), rng.uniform(1e-3, 1, 500)
    L = _dirs(np.arccos(cl), rng.uniform(0, 2 * np.pi, 500))
    V = _dirs(np.arccos(cv), rng.uniform(0, 2 * np.pi, 500))
    f = _f("gotanda_fitted", L, V, {"alpha": 0.0, "f0": [0.04] * 3, "rho_d": [1.0] * 3})[:, 0]
    expected = 21 / (20 * math.pi) * 0.96 * (1 - (1 - cv) ** 5 / 1.36053) * (1 - (1 - cl) ** 5)
    np.testing.assert_allclose(f, expected, rtol=1e-12)


def test_gotanda_fitted_is_finite_and_continuous_as_n_dot_l_vanishes():
    # n·l is divided out analytically, with a series below n·l = 0.01: no jump at the switch, a finite limit
    for alpha in (0.1, 0.5, 1.0):
        c = np.array([1e-7, 1e-4, 0.01 - 1e-12, 0.01, 0.01 + 1e-12, 0.02])
        L = _dirs(np.arccos(c), 0.0)
        V = np.broadcast_to(_dirs(math.radians(50.0), math.pi), L.shape)
        for dtype in ("float64", "float32"):
            f = evaluate("gotanda_fitted", L, V, np.broadcast_to(Z, L.shape), params={"alpha": alpha},
                         target="numpy", dtype=dtype)[:, 0]
            assert np.all(np.isfinite(f)) and np.all(f >= 0)
        f = _f("gotanda_fitted", L, V, {"alpha": alpha})[:, 0]
        r = reference_brdf("gotanda_fitted", L, V, Z, params={"alpha": alpha})[:, 0]
        np.testing.assert_allclose(f[1:], r[1:], rtol=1e-12)
        assert abs(f[2] - f[4]) <= 1e-10 * f[3]


def test_microfacet_diffuse_limits_and_convergence():
    # α = 0: the Lambertian facet at n, F_diff(n, l, e)/π exactly; reciprocal (to the quadrature);
    # quadrupling the nodes moves it by < 5e-5 away from grazing (the fit table's errors are >= 1e-3)
    NL, NV, CP = np.array([0.9, 0.3, 0.2, 0.7]), np.array([0.7, 0.2, 0.3, 0.7]), np.array([1.0, 0.0, -1.0, 0.5])
    exact0 = 1.05 * 0.96 * (1 - (1 - NL) ** 5) * (1 - (1 - NV) ** 5) / math.pi
    np.testing.assert_allclose(ref_diffuse.microfacet_diffuse(NL, NV, CP, 0.0), exact0, rtol=1e-12)
    for a in (0.1, 0.5, 1.0):
        f = ref_diffuse.microfacet_diffuse(NL, NV, CP, a)
        fine = ref_diffuse.microfacet_diffuse(NL, NV, CP, a, n_t=384, n_phi=768)
        np.testing.assert_allclose(f, fine, rtol=5e-5)
        np.testing.assert_allclose(ref_diffuse.microfacet_diffuse(NV, NL, CP, a), f, rtol=1e-4)


def test_gotanda_fit_error_table(capsys):
    # The figures for docs/benchmarks.md (the lead's runtime-vs-error benchmark): see gotanda_fit_error_table.
    rows = ref_diffuse.gotanda_fit_error_table()
    with capsys.disabled():
        print("\nGotanda 2014 eq. 8 against eq. 4 by quadrature (α = σ, f0 = 0.04):\n"
              + ref_diffuse.fit_error_markdown(rows))
    by = {(r["sigma"], r["region"]): r for r in rows}
    for s in ref_diffuse.FIT_SIGMAS:
        # away from grazing the fit is within a few percent on average, < 45 % at worst
        assert by[(s, "both <= 60°")]["mean_rel"] < 0.1 and by[(s, "both <= 60°")]["max_rel"] < 0.45
        # away from grazing the absolute error is < 0.07 sr⁻¹ (the Lambertian level is 0.318) ...
        assert by[(s, "both <= 60°")]["max_abs"] < 0.07
        # ... and everywhere the radiance error per unit irradiance, |Δf| n·l, is < 0.11
        assert by[(s, "all")]["max_abs_cos"] < 0.11
    # ... but where both directions graze (backward) the exact model is nearly black and the fit is not:
    # the paper's own first limitation (§4), in figures
    assert by[(1.0, "both >= 80°")]["max_rel"] > 100.0
