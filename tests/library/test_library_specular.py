"""The classic specular bricks: the properties each model claims, and its formulations.

Phong (the course's original form and its two plausibility steps), Blinn-Phong with R_F(α_h),
Banks, Ward (isotropic, anisotropic), Ashikhmin-Shirley, Lafortune, Cook-Torrance
(Hoffman & Baker 2006, seed 000). The agreement of every brick with its float64 reference,
float32 tolerances and reciprocity are tests/reference/test_reference.py's (over every brick); here:
directional albedos against closed forms and ACCURACY-FACTS §4 by quadrature, identities
between bricks, the two formulations the course prints of Ward and Ashikhmin-Shirley, and the
tangent-frame requirement of the anisotropic bricks.

Quadrature: Gauss-Legendre in cos θ times the trapezoidal rule in φ (exact for the periodic
integrand), over the hemisphere of the integrated direction; brick values from the NumPy
emission in float64.
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from generator.eval import accuracy
from generator.eval.evaluate import evaluate
from generator.library.bricks import load_library
from generator.reference import reference_brdf, shading_geometry
from generator.reference import specular as refs

LIB = load_library()
Z = np.array([0.0, 0.0, 1.0])
X = np.array([1.0, 0.0, 0.0])


def _f(spec, L, V, params=None, target="numpy", T=X):
    n = len(L)
    return evaluate(spec, L, V, np.broadcast_to(Z, (n, 3)), np.broadcast_to(T, (n, 3)), params,
                    target=target, dtype="float64", lib=LIB)


@functools.lru_cache(maxsize=None)
def _gauss(n: int):
    """Gauss-Legendre nodes and weights on [-1, 1] (cached: numpy solves an n × n eigenproblem)."""
    return np.polynomial.legendre.leggauss(n)


def _hemisphere_rule(n_mu: int = 256, n_phi: int = 256):
    x, w = _gauss(n_mu)
    mu, wmu = 0.5 * (x + 1.0), 0.5 * w
    phi = (np.arange(n_phi) + 0.5) * (2.0 * np.pi / n_phi)
    M, P = np.meshgrid(mu, phi, indexing="ij")
    W = np.outer(wmu, np.full(n_phi, 2.0 * np.pi / n_phi))
    return accuracy.direction(M.ravel(), P.ravel()), M.ravel(), W.ravel()


def albedo(spec, fixed, params=None, over="outgoing", n_mu=256, n_phi=256, T=X):
    """E = ∫ f(l, v) cos θ dω over the outgoing v (l fixed) or over the incoming l (v fixed); per RGB."""
    D, mu, w = _hemisphere_rule(n_mu, n_phi)
    F = np.broadcast_to(fixed, D.shape)
    f = _f(spec, F, D, params, T=T) if over == "outgoing" else _f(spec, D, F, params, T=T)
    return (f * (mu * w)[:, None]).sum(axis=0)


def _dir(theta_deg, phi=0.0):
    return accuracy.direction(np.array([math.cos(math.radians(theta_deg))]), phi)


@pytest.fixture(scope="module")
def pairs():
    rng = np.random.default_rng(11)
    n = 3000
    L = accuracy.direction(rng.uniform(1e-3, 1, n), rng.uniform(0, 2 * np.pi, n))
    V = accuracy.direction(rng.uniform(1e-3, 1, n), rng.uniform(0, 2 * np.pi, n))
    return L, V


# ------------------------------------------------------------------ Phong and its plausibility steps

def test_original_phong_albedos_match_accuracy_facts():
    # ACCURACY-FACTS §4.2 states them for k_s = (n + 1)/2, i.e. f = (n+1)/(2π) (r·v)^n / cos θ_l;
    # k_s is at most 1 here, so the albedo at k_s = 1 is scaled by (n + 1)/2.
    n = 10.0
    p = {"n": n, "k_s": [1.0, 1.0, 1.0]}
    scale = (n + 1.0) / 2.0
    # over the light direction (v = n): exactly 1 while the lobe is not clipped
    assert albedo("phong", Z, p, over="incoming")[0] * scale == pytest.approx(1.0, abs=1e-6)
    # over the outgoing direction: (n+1)/(n+2) at normal incidence, 1.8014 at 85°
    assert albedo("phong", Z, p)[0] * scale == pytest.approx((n + 1.0) / (n + 2.0), abs=1e-6)
    assert albedo("phong", _dir(85.0), p, n_mu=512)[0] * scale == pytest.approx(1.8014, abs=1e-4)


def test_original_phong_is_not_reciprocal_and_is_the_reciprocal_step_over_cos_theta_i(pairs):
    L, V = pairs
    p = {"n": 10.0, "k_s": [0.5, 0.5, 0.5]}
    a, b = _f("phong", L, V, p), _f("phong", V, L, p)
    nz = np.maximum(a, b) > 1e-6
    assert (np.abs(a - b)[nz] / np.minimum(a, b)[nz]).max() > 10.0  # ACCURACY-FACTS §4.6: 3.9e3
    step1 = _f("phong_reciprocal", L, V, p)
    np.testing.assert_allclose(a, step1 / L[:, 2:3], rtol=1e-13)


def test_phong_plausibility_steps_reflectance_and_normalization(pairs):
    # Step 1 (cosine removed): R_s(0) = 2 k_s / (n + 2), the maximum over θ_i (the course).
    for n in (1.0, 10.0, 100.0):
        p = {"n": n, "k_s": [1.0, 0.5, 0.0]}
        np.testing.assert_allclose(albedo("phong_reciprocal", Z, p, n_mu=512),
                                   np.array([1.0, 0.5, 0.0]) * 2.0 / (n + 2.0), atol=1e-6)
        assert albedo("phong_reciprocal", _dir(60.0), p)[0] < 2.0 / (n + 2.0)
    # Step 2 (normalized, k_s = R_F(0) (n+2)/2): the existing phong_normalized brick, E(0) = R_F(0).
    L, V = pairs
    n, f0 = 10.0, 0.04
    np.testing.assert_allclose(_f("phong_reciprocal", L, V, {"n": n, "k_s": [f0 * (n + 2.0) / 2.0] * 3}),
                               _f("phong_normalized", L, V, {"n": n, "f0": [f0] * 3}), rtol=1e-13)


# ------------------------------------------------------------------ Blinn-Phong with R_F(α_h)

def test_blinn_phong_fresnel_is_blinn_phong_at_f0_one_and_at_l_equal_v(pairs):
    L, V = pairs
    np.testing.assert_allclose(_f("blinn_phong_normalized_fresnel", L, V, {"n": 30.0, "f0": [1.0] * 3}),
                               _f("blinn_phong_normalized", L, V, {"n": 30.0, "f0": [1.0] * 3}), rtol=1e-13)
    p = {"n": 30.0, "f0": [0.04, 0.5, 0.9]}
    np.testing.assert_allclose(_f("blinn_phong_normalized_fresnel", L, L, p),
                               _f("blinn_phong_normalized", L, L, p), rtol=1e-13)
    # Schlick's rise towards grazing l·h: never below R_F(0)
    assert np.all(_f("blinn_phong_normalized_fresnel", L, V, p) >= _f("blinn_phong_normalized", L, V, p))


@pytest.mark.parametrize("n", [1.0, 10.0, 100.0])
def test_blinn_phong_fresnel_albedo_at_normal_incidence(n):
    # f0 = 1 (F ≡ 1): E(0) = (n + 2^(-n/2)) / (n + 2) for K = (n+4)/(8π) (ACCURACY-FACTS §4.3).
    e = albedo("blinn_phong_normalized_fresnel", Z, {"n": n, "f0": [1.0] * 3}, n_mu=1024)[0]
    assert e == pytest.approx((n + 2.0 ** (-n / 2.0)) / (n + 2.0), abs=1e-6)


# ------------------------------------------------------------------ Banks

def test_banks_kernel_is_the_best_mirror_direction_over_the_threads_normals(pairs):
    # Brute force: the mirror of l about every normal n' ⊥ t (3600 of them); the best v·r is the
    # closed form the brick uses, sqrt(1-(l·t)²) sqrt(1-(v·t)²) - (l·t)(v·t) (ACCURACY-FACTS §4.10).
    L, V = pairs
    L, V = L[:300], V[:300]
    a = np.linspace(0.0, 2.0 * np.pi, 3600, endpoint=False)
    normals = np.stack([np.zeros_like(a), np.cos(a), np.sin(a)], -1)  # ⊥ t = x
    nl = L @ normals.T
    R = 2.0 * nl[..., None] * normals[None] - L[:, None, :]
    best = np.einsum("ij,ikj->ik", V, R).max(axis=1)
    lt, vt = L[:, 0], V[:, 0]
    closed = np.sqrt(1 - lt ** 2) * np.sqrt(1 - vt ** 2) - lt * vt
    np.testing.assert_allclose(best, closed, atol=2e-6)  # the grid's 0.05° step: 1 - cos = 4e-7
    np.testing.assert_allclose(refs.banks_kernel(L, V, np.broadcast_to(X, L.shape)), closed, atol=1e-14)
    n = 8.0
    got = _f("banks", L, V, {"n": n, "k_s": [1.0] * 3})[:, 0]
    np.testing.assert_allclose(got, np.clip(closed, 0, None) ** n / np.pi, rtol=1e-12, atol=1e-300)


def test_banks_self_shadowing_is_the_only_effect_of_the_normal(pairs):
    L, V = pairs
    p = {"n": 16.0, "k_s": [0.5, 0.5, 0.5]}
    base = _f("banks", L, V, p)
    # Tilt N in the plane normal to t (the kernel reads only l·t, v·t): the value stays while n·l > 0 ...
    tilted = np.array([0.0, math.sin(0.4), math.cos(0.4)])
    N = np.broadcast_to(tilted, L.shape)
    got = evaluate("banks", L, V, N, np.broadcast_to(X, L.shape), p, target="numpy", dtype="float64", lib=LIB)
    lit = L @ tilted > 0.0
    np.testing.assert_allclose(got[lit], base[lit], rtol=1e-12)
    # ... and is 0 where the light is below the surface (the self-shadowing term).
    assert lit.sum() < len(L) and np.all(got[~lit] == 0.0)


# ------------------------------------------------------------------ Ward

def test_ward_formulations_agree_and_isotropic_is_anisotropic_with_equal_slopes(pairs):
    L, V = pairs
    n = len(L)
    g = shading_geometry(L, V, np.broadcast_to(Z, (n, 3)), np.broadcast_to(X, (n, 3)))
    p = {"m_u": np.full(n, 0.15), "m_v": np.full(n, 0.4), "f0": np.full((n, 3), 0.5)}
    phi_form = refs.ward_anisotropic(g, p, {})
    dot_form = refs.ward_anisotropic_dot_form(g, p)
    np.testing.assert_allclose(dot_form, phi_form, rtol=1e-12, atol=1e-300)
    q = {"m_u": 0.15, "m_v": 0.4, "f0": [0.5] * 3}
    got = _f("ward_anisotropic", L, V, q)
    np.testing.assert_allclose(got, phi_form, rtol=1e-11, atol=1e-300)  # the brick: the dot-product form
    for m in (0.05, 0.3):
        np.testing.assert_allclose(_f("ward_anisotropic", L, V, {"m_u": m, "m_v": m, "f0": [0.3] * 3}),
                                   _f("ward_isotropic", L, V, {"m": m, "f0": [0.3] * 3}), rtol=1e-12)


def test_ward_anisotropic_stretches_the_highlight_along_the_rougher_axis():
    # A half vector tilted 10° towards t against one tilted towards b: m_u < m_v keeps more along b.
    v = Z[None]
    p = {"m_u": 0.1, "m_v": 0.3, "f0": [1.0] * 3}
    along_t = _f("ward_anisotropic", _dir(20.0, 0.0), v, p)[0, 0]
    along_b = _f("ward_anisotropic", _dir(20.0, np.pi / 2), v, p)[0, 0]
    assert along_b > 10.0 * along_t


@pytest.mark.parametrize("m", [0.05, 0.2])
def test_ward_normal_incidence_albedo_by_quadrature(m):
    # Course form f = ρ_s e^(-tan²θ_h/m²) / (4π m² cos θ_i cos θ_e) = D_Beckmann(h) cos⁴θ_h / (4 cos θ_i
    # cos θ_e), and dω_l = 4 (v·h) dω_h, so at v = n: E(0) = ∫ D cos⁵θ_h dω_h over θ_h < 45° (where l
    # stays above the horizon), a 1-D integral in θ_h (Gauss-Legendre), against the brick's 2-D albedo.
    x, w = _gauss(1024)
    th = (x + 1.0) * (np.pi / 8.0)
    wt = w * (np.pi / 8.0)
    integrand = np.exp(-np.tan(th) ** 2 / m ** 2) / (np.pi * m * m * np.cos(th) ** 4) * np.cos(th) ** 5
    exact = float((integrand * 2.0 * np.pi * np.sin(th) * wt).sum())
    e = albedo("ward_isotropic", Z, {"m": m, "f0": [1.0] * 3}, n_mu=1024, n_phi=32)[0]
    assert e == pytest.approx(exact, rel=2e-4)
    assert 0.9 < e < 1.0  # "well normalized", and below 1 at normal incidence


def test_ward_duer_f_cos_does_not_vanish_at_grazing_light():
    # ACCURACY-FACTS §4.8: with 1/(cos θ_i cos θ_e), f cos θ_l at the grazing mirror configuration tends
    # to ρ_s/(4π m² cos θ_e), not to 0 (Ward 1992's 1/sqrt(cos cos) would give 0).
    m = 0.2
    for c in (1e-2, 1e-3, 1e-4):
        L = accuracy.direction(np.array([c]), 0.0)
        V = accuracy.direction(np.array([c]), np.pi)
        fc = _f("ward_isotropic", L, V, {"m": m, "f0": [1.0] * 3})[0, 0] * c
        assert fc == pytest.approx(1.0 / (4.0 * np.pi * m * m * c), rel=1e-6)


def test_ward_zero_roughness_is_finite_in_float32():
    L, V = accuracy.direction(np.array([0.6, 1e-7, 0.3]), 0.0), accuracy.direction(np.array([0.6, 1e-7, 0.9]), np.pi)
    for spec, p in (("ward_isotropic", {"m": 0.0}), ("ward_anisotropic", {"m_u": 0.0, "m_v": 0.0})):
        n = len(L)
        got = evaluate(spec, L, V, np.broadcast_to(Z, (n, 3)), np.broadcast_to(X, (n, 3)), p,
                       target="numpy", dtype="float32", lib=LIB)
        assert np.all(np.isfinite(got)) and got[0, 0] > 1e5  # the floored peak, m = 1e-4


# ------------------------------------------------------------------ Ashikhmin-Shirley

def test_ashikhmin_shirley_formulations_agree_and_the_seed_denominator_is_a_typo(pairs):
    L, V = pairs
    n = len(L)
    g = shading_geometry(L, V, np.broadcast_to(Z, (n, 3)), np.broadcast_to(X, (n, 3)))
    p = {"n_u": np.full(n, 10.0), "n_v": np.full(n, 300.0), "f0": np.full((n, 3), 0.05)}
    phi_form = refs.ashikhmin_shirley(g, p, {})
    np.testing.assert_allclose(refs.ashikhmin_shirley_dot_form(g, p), phi_form, rtol=1e-11, atol=1e-300)
    typo = refs.ashikhmin_shirley_dot_form(g, p, seed_typo=True)
    assert np.abs(typo - phi_form).max() > 0.1 * phi_form.max()  # 1 + cos²θ_h is another model
    got = _f("ashikhmin_shirley", L, V, {"n_u": 10.0, "n_v": 300.0, "f0": [0.05] * 3})
    np.testing.assert_allclose(got, phi_form, rtol=1e-10, atol=1e-300)


def test_ashikhmin_shirley_exponent_at_h_equal_n_is_finite():
    # l = v = n: (n·h)^e with e = 0/0 in the dot form (ACCURACY-FACTS pitfall 14); the brick takes n_u.
    L = np.array([Z, Z])
    for dtype in ("float64", "float32"):
        got = evaluate("ashikhmin_shirley", L, L, L, np.array([X, X]), {"n_u": 10.0, "n_v": 1000.0, "f0": [1.0] * 3},
                       target="numpy", dtype=dtype, lib=LIB)
        want = math.sqrt(11.0 * 1001.0) / (8.0 * math.pi)  # (n·h)^e = 1, k·h = 1, max(n·l, n·v) = 1, F = 1
        np.testing.assert_allclose(got, want, rtol=1e-6)


@pytest.mark.parametrize("n_u,n_v", [(10.0, 10.0), (10.0, 100.0), (1000.0, 50.0)])
def test_ashikhmin_shirley_half_vector_density_is_normalized(n_u, n_v):
    # D_AS = sqrt((n_u+1)(n_v+1))/(2π) (n·h)^(n_u cos²φ + n_v sin²φ) integrates to 1 over the solid angle of
    # h (Ashikhmin & Shirley 2000: the density of h; ∫_0^2π dφ / (1 + n_u cos²φ + n_v sin²φ) = 2π/sqrt((n_u+1)
    # (n_v+1)) exactly). Against cos θ_h, as ACCURACY-FACTS §4.9 states it, the integral is below 1:
    # (n+1)/(n+2) for n_u = n_v = n (the check was written for the wrong measure).
    # ∫ over cos θ_h of μ^e is 1/(e+1) (1/(e+2) against cos θ_h); the rest is the φ integral, by the
    # trapezoidal rule (exact to rounding for this smooth periodic integrand).
    phi = (np.arange(4096) + 0.5) * (2.0 * np.pi / 4096)
    e = n_u * np.cos(phi) ** 2 + n_v * np.sin(phi) ** 2
    k = np.sqrt((n_u + 1.0) * (n_v + 1.0)) / (2.0 * np.pi)
    assert (k / (e + 1.0)).sum() * (2.0 * np.pi / 4096) == pytest.approx(1.0, abs=1e-12)
    with_cos = (k / (e + 2.0)).sum() * (2.0 * np.pi / 4096)
    assert with_cos < 1.0
    if n_u == n_v:
        assert with_cos == pytest.approx((n_u + 1.0) / (n_u + 2.0), abs=1e-12)
    # and the density itself (ashikhmin_shirley_ndf), by quadrature over the hemisphere of h
    x, w = _gauss(512)
    u, wu = 0.5 * (x + 1.0), 0.5 * w
    mu = 1.0 - u ** 4  # crowds the nodes towards μ = 1, where μ^1000 lives; dμ = 4u³ du
    M, P = np.meshgrid(mu, phi[::16], indexing="ij")
    D = refs.ashikhmin_shirley_ndf(M, P, n_u, n_v)
    total = (D * (4.0 * u ** 3 * wu)[:, None]).sum() * (2.0 * np.pi / 256)
    assert total == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("n", [10.0, 100.0])
def test_ashikhmin_shirley_albedo_at_normal_incidence_closed_form(n):
    # F ≡ 1 (f0 = 1), n_u = n_v = n, v = n: max(n·l, n·v) = 1 and dω_l = 4 (k·h) dω_h, so
    # E(0) = ∫ D_AS cos θ_l dω_h with cos θ_l = 2 cos²θ_h - 1 over θ_h < 45°:
    # (n+1) [2 (1 - c^(n+3))/(n+3) - (1 - c^(n+1))/(n+1)], c = 1/√2 ((n-1)/(n+3) without the clipping).
    c = math.sqrt(0.5)
    want = (n + 1.0) * (2.0 * (1.0 - c ** (n + 3.0)) / (n + 3.0) - (1.0 - c ** (n + 1.0)) / (n + 1.0))
    e = albedo("ashikhmin_shirley", Z, {"n_u": n, "n_v": n, "f0": [1.0] * 3}, n_mu=1024)[0]
    assert e == pytest.approx(want, abs=1e-6)


def test_ashikhmin_shirley_anisotropy_follows_the_exponents():
    v = Z[None]
    p = {"n_u": 10.0, "n_v": 1000.0, "f0": [1.0] * 3}
    along_t = _f("ashikhmin_shirley", _dir(10.0, 0.0), v, p)[0, 0]
    along_b = _f("ashikhmin_shirley", _dir(10.0, np.pi / 2), v, p)[0, 0]
    assert along_t > 10.0 * along_b  # the smaller exponent (n_u, along t) spreads the lobe that way


# ------------------------------------------------------------------ Lafortune

PHONG_LOBE = [[-1.0, -1.0, 1.0, 20.0]] + [[0.0, 0.0, 0.0, 1.0]] * 3


def test_lafortune_lobe_minus_one_minus_one_one_is_phong(pairs):
    # ACCURACY-FACTS §4.10: (C_x, C_y, C_z) = (-1, -1, 1) is (r·v)^n exactly.
    L, V = pairs
    n = 20.0
    K = [[1.0, 1.0, 1.0]] + [[0.0] * 3] * 3
    got = _f("lafortune(lobes=1)", L, V, {"lobes": PHONG_LOBE, "K": K})[:, 0]
    rv = np.clip(np.einsum("ij,ij->i", 2.0 * L[:, 2:3] * Z - L, V), 0.0, 1.0)
    np.testing.assert_allclose(got, rv ** n, rtol=1e-10, atol=1e-300)  # n = 20 amplifies rounding
    # The course's Phong: K = R_F(0), -C_x = -C_y = C_z = ((n+2)/(2π))^(1/n): phong_normalized.
    c = ((n + 2.0) / (2.0 * np.pi)) ** (1.0 / n)
    f0 = [0.04, 0.5, 0.9]
    lobes = [[-c, -c, c, n]] + PHONG_LOBE[1:]
    np.testing.assert_allclose(_f("lafortune(lobes=1)", L, V, {"lobes": lobes, "K": [f0] + K[1:]}),
                               _f("phong_normalized", L, V, {"n": n, "f0": f0}), rtol=1e-10, atol=1e-300)
    # ... whose albedo at normal incidence is R_F(0) (ACCURACY-FACTS §4.2)
    np.testing.assert_allclose(albedo("lafortune(lobes=1)", Z, {"lobes": lobes, "K": [f0] + K[1:]}, n_mu=512),
                               f0, rtol=1e-6)


def test_lafortune_lambertian_lobe_and_lobe_count(pairs):
    L, V = pairs
    rho = np.array([0.2, 0.5, 0.8])
    lobes = [[0.0, 0.0, 0.0, 0.0], [-1.0, -1.0, 1.0, 8.0], [0.7, 0.7, 0.7, 3.0], [-0.5, -2.0, 1.0, 40.0]]
    K = [list(rho / np.pi), [0.3, 0.3, 0.3], [0.1, 0.2, 0.3], [1.0, 1.0, 1.0]]
    # n = 0 (0^0 = 1): the course's Lambertian case, K = ρ_d/π everywhere
    np.testing.assert_allclose(_f("lafortune(lobes=1)", L, V, {"lobes": lobes, "K": K}),
                               np.broadcast_to(rho / np.pi, L.shape), rtol=1e-15)
    # lafortune(lobes=k) sums the first k lobes (the reference computes each lobe from the frame)
    T = np.broadcast_to(X, L.shape)
    N = np.broadcast_to(Z, L.shape)
    prev = 0.0
    for k in (1, 2, 3, 4):
        spec = f"lafortune(lobes={k})"
        ref = reference_brdf(spec, L, V, N, T, {"lobes": lobes, "K": K}, lib=LIB)
        np.testing.assert_allclose(_f(spec, L, V, {"lobes": lobes, "K": K}), ref, rtol=1e-12, atol=1e-300)
        assert np.all(ref >= prev) and np.any(ref > prev)
        prev = ref


def test_lafortune_anisotropic_lobe_reads_the_tangent_frame(pairs):
    L, V = pairs
    p = {"lobes": [[-1.0, -0.2, 1.0, 10.0]] * 4, "K": [[1.0] * 3] * 4}
    a = _f("lafortune(lobes=1)", L, V, p, T=X)
    b = _f("lafortune(lobes=1)", L, V, p, T=np.array([0.0, 1.0, 0.0]))
    assert np.abs(a - b).max() > 0.1 * a.max()


# ------------------------------------------------------------------ Cook-Torrance

def test_cook_torrance_is_lambert_and_microfacet_weighted_by_s(pairs):
    L, V = pairs
    p = {"alpha": 0.3, "f0": [0.9, 0.6, 0.3], "rho_d": [0.2, 0.4, 0.8]}
    micro = _f("microfacet(ndf=beckmann,fresnel=schlick,vis=torrance_sparrow)", L, V,
               {"alpha": 0.3, "f0": [0.9, 0.6, 0.3]})
    lambert = np.broadcast_to(np.array(p["rho_d"]) / np.pi, L.shape)
    for s in (0.0, 0.25, 1.0):
        got = _f("cook_torrance", L, V, dict(p, s=s))
        np.testing.assert_allclose(got, (1.0 - s) * lambert + s * micro, rtol=1e-13)


def test_cook_torrance_defaults_are_cook_and_torrances_choices():
    from generator.spec.permutation import canonical, parse_brdf
    assert canonical(parse_brdf("cook_torrance", LIB)) == \
        "cook_torrance(ndf=beckmann,fresnel=schlick,vis=torrance_sparrow)"


def test_cook_torrance_loses_energy_through_g():
    # The course: "Not well-normalized - significant energy lost via G". F ≡ 1 (f0 = 1), s = 1: the
    # albedo at normal incidence is below 1, the more so the rougher (V-cavity G, Beckmann D).
    e = [albedo("cook_torrance", Z, {"s": 1.0, "rho_d": [0.0] * 3, "alpha": a, "f0": [1.0] * 3}, n_mu=1024)[0]
         for a in (0.1, 0.3, 0.6)]
    assert 0.0 < e[2] < e[1] < e[0] <= 1.0 + 1e-9
    assert e[2] < 0.9


# ------------------------------------------------------------------ the tangent frame

ANISOTROPIC = ["banks", "ward_anisotropic", "ashikhmin_shirley", "lafortune"]


@pytest.mark.parametrize("brick", ANISOTROPIC)
def test_anisotropic_brick_without_tangents_is_an_error_naming_the_material(brick, tmp_path):
    from generator.lang import SourceError
    from generator.scene.load import load_scene
    s = tmp_path / "s.toml"
    s.write_text(f'[materials.brushed_steel]\nbrdf = "{brick}"\n')
    with pytest.raises(SourceError) as e:
        load_scene(s, LIB)
    text = str(e.value)
    assert "brushed_steel" in text and "tangent" in text and "vertex_tangent" in text
    s.write_text(f'[materials.brushed_steel]\nbrdf = "{brick}"\npacking = "constants(normal=vertex_tangent)"\n')
    assert "brushed_steel" in load_scene(s, LIB).materials


def test_isotropic_specular_bricks_need_no_tangent(tmp_path):
    from generator.scene.load import load_scene
    s = tmp_path / "s.toml"
    s.write_text("".join(f'[materials.m{i}]\nbrdf = "{b}"\n' for i, b in enumerate(
        ["phong", "phong_reciprocal", "blinn_phong_normalized_fresnel", "ward_isotropic", "lambert+cook_torrance"])))
    assert len(load_scene(s, LIB).materials) == 5
