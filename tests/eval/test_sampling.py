"""The bricks' samplers and pdfs in NumPy (generator.eval.sampling), proven statistically.

Per sampled brick and one parameter set: a chi-square goodness-of-fit test of the sampler against its own
pdf (tests/eval/chi2.py: Mitsuba's and pbrt's method), at significance 0.01 Šidák-corrected for the number
of tests, fixed seeds; a wrong pdf (scaled by 1.1, or of the wrong exponent) fails the same test; the pdf
integrates to 1 minus the mass the sampler sends below the horizon; pdf at the samples is the closed form
the sampler draws from; the MC albedo with the brick's own sampler matches quadrature. The full sweep
(several roughnesses and views) is marked slow.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from generator.eval import sampling
from generator.eval.evaluate import evaluate
from generator.reference import d_ggx, lambda_ggx

from .chi2 import Frame, chi2_test, sidak

ALPHA = 0.01
N_SAMPLES = 100_000


def _frame(view_deg: float = 40.0, azimuth_deg: float = 30.0) -> Frame:
    """A shading frame off the axes (so no brick may assume N = z), with v at view_deg from N."""
    N = np.array([0.2, -0.3, 0.9])
    N /= np.linalg.norm(N)
    T = np.cross([0.0, 1.0, 0.0], N)
    T /= np.linalg.norm(T)
    B = np.cross(N, T)
    t, p = math.radians(view_deg), math.radians(azimuth_deg)
    V = math.sin(t) * math.cos(p) * T + math.sin(t) * math.sin(p) * B + math.cos(t) * N
    return Frame(V, N, T)


# (spec, params): every brick with a sampler of its own, one parameter set each
CASES = [
    ("lambert", {}),
    ("phong", {"n": 8.0}),
    ("phong_reciprocal", {"n": 8.0}),
    ("phong_normalized", {"n": 20.0}),
    ("blinn_phong_normalized", {"n": 30.0}),
    ("blinn_phong_normalized_fresnel", {"n": 30.0}),
    ("microfacet(ndf=ggx)", {"alpha": 0.4}),
    ("microfacet(ndf=ggx_anisotropic)", {"alpha_u": 0.2, "alpha_v": 0.5}),
    ("microfacet(ndf=beckmann)", {"alpha": 0.4}),
    ("microfacet(ndf=beckmann_anisotropic)", {"alpha_u": 0.25, "alpha_v": 0.5}),
    ("microfacet(ndf=blinn_phong)", {"alpha": 0.4}),
    ("ward_isotropic", {"m": 0.3}),
    ("ward_anisotropic", {"m_u": 0.2, "m_v": 0.4}),
    ("ashikhmin_shirley", {"n_u": 40.0, "n_v": 8.0}),
    ("lafortune(lobes=2)", {}),
]
SWEEP = [(s, p, v) for s, p in [
    ("phong_normalized", {"n": 200.0}), ("phong", {"n": 2.0}), ("blinn_phong_normalized", {"n": 4.0}),
    ("blinn_phong_normalized", {"n": 300.0}), ("microfacet(ndf=ggx)", {"alpha": 0.1}),
    ("microfacet(ndf=ggx)", {"alpha": 0.9}), ("microfacet(ndf=ggx_anisotropic)", {"alpha_u": 0.05, "alpha_v": 0.3}),
    ("microfacet(ndf=beckmann)", {"alpha": 0.15}), ("microfacet(ndf=beckmann)", {"alpha": 0.8}),
    ("microfacet(ndf=beckmann_anisotropic)", {"alpha_u": 0.6, "alpha_v": 0.1}),
    ("microfacet(ndf=blinn_phong)", {"alpha": 0.2}), ("ward_isotropic", {"m": 0.1}),
    ("ward_anisotropic", {"m_u": 0.5, "m_v": 0.1}), ("ashikhmin_shirley", {"n_u": 10.0, "n_v": 300.0}),
    ("lafortune(lobes=4)", {}), ("lambert", {}),
] for v in (5.0, 60.0, 85.0)]
TESTS = len(CASES) + len(SWEEP)  # the Šidák correction counts every chi-square test of the module
LEVEL = sidak(ALPHA, TESTS)


def _id(case) -> str:
    return "-".join(str(x) for x in case[:1]) + ("" if len(case) < 3 else f"-{case[2]:g}deg") + \
        "".join(f"-{k}{v}" for k, v in case[1].items())


def _sampler(spec, params, fr: Frame):
    def draw(u):
        return sampling.sample(spec, u, fr.V[None], fr.N[None], fr.T[None], params=params)

    def density(L):
        return sampling.pdf(spec, L, fr.V[None], fr.N[None], fr.T[None], params=params)
    return draw, density


def _chi2(spec, params, fr, seed=7, n=N_SAMPLES, scale=1.0, pdf_params=None, q=8):
    draw, _ = _sampler(spec, params, fr)
    _, density = _sampler(spec, pdf_params or params, fr)
    return chi2_test(draw, lambda L: scale * density(L), fr, n, seed, q=q)


def test_every_case_runs_its_own_sampler():
    for spec, _ in CASES:
        assert all(h.endswith("own sampler") for h in sampling.how(spec)), sampling.how(spec)


def test_a_brick_without_a_sampler_falls_back_to_cosine_weighted_and_says_why():
    how = sampling.how("oren_nayar+banks")
    assert how == ("oren_nayar: cosine-weighted fallback (oren_nayar has no sampler)",
                   "banks: cosine-weighted fallback (banks has no sampler)")
    assert "its ndf filler ward has no sample_h" in sampling.how("microfacet(ndf=ward)")[0]
    fr = _frame()
    r = _chi2("banks", {}, fr)
    assert r.p_value > LEVEL and abs(r.mass - 1.0) < 1e-6  # the fallback is exact cosine sampling


@pytest.mark.parametrize("case", CASES, ids=_id)
def test_sampler_matches_its_pdf_chi_square(case):
    spec, params = case
    r = _chi2(spec, params, _frame())
    print(f"{spec} {params}: p = {r.p_value:.3g} (chi2 {r.stat:.1f}, dof {r.dof}), "
          f"pdf mass above the horizon {r.mass:.4f}, samples below {r.below:.4f}")
    assert r.p_value > LEVEL, (r, LEVEL)


@pytest.mark.slow
@pytest.mark.parametrize("case", SWEEP, ids=_id)
def test_sampler_sweep_chi_square(case):
    spec, params, view = case
    r = _chi2(spec, params, _frame(view), q=32)  # grazing views: lobes narrow in φ
    print(f"{spec} {params} at {view}°: p = {r.p_value:.3g}, mass {r.mass:.4f}, below {r.below:.4f}")
    assert r.p_value > LEVEL, (r, LEVEL)


@pytest.mark.parametrize("spec, params, wrong", [
    ("microfacet(ndf=ggx)", {"alpha": 0.4}, {"scale": 1.1}),
    # the lecture's (alpha + 2)/(2 pi) cos^alpha is the BRDF's normalization, not the sampler's density
    ("phong_normalized", {"n": 4.0}, {"scale": 6.0 / 5.0}),
    ("phong_normalized", {"n": 20.0}, {"pdf_params": {"n": 22.0}}),  # a wrong exponent
    ("microfacet(ndf=beckmann)", {"alpha": 0.4}, {"pdf_params": {"alpha": 0.43}}),
])
def test_a_wrong_pdf_fails_the_chi_square_test(spec, params, wrong):
    r = _chi2(spec, params, _frame(), **wrong)
    print(f"wrong pdf {wrong} for {spec}: p = {r.p_value:.3g} (chi2 {r.stat:.1f}, dof {r.dof})")
    assert r.p_value < LEVEL


@pytest.mark.parametrize("case", CASES, ids=_id)
def test_pdf_integrates_to_one_minus_the_mass_sent_below_the_horizon(case):
    spec, params = case
    fr = _frame()
    r = _chi2(spec, params, fr, n=200_000, seed=11)
    assert r.mass <= 1.0 + 2e-3
    # what the pdf lacks is what the sampler loses: three standard errors of the below-horizon fraction
    sigma = math.sqrt(max(r.below * (1 - r.below), 1e-12) / 200_000)
    assert abs((1.0 - r.mass) - r.below) < 3 * sigma + 2e-3, (r.mass, r.below)


def test_no_mass_is_lost_where_the_lobe_stays_above_the_horizon():
    fr = _frame(0.0)
    for spec, params in [("lambert", {}), ("phong_normalized", {"n": 50.0}), ("blinn_phong_normalized", {"n": 300.0}),
                         ("ward_isotropic", {"m": 0.1})]:
        r = _chi2(spec, params, fr, n=20_000)
        assert abs(r.mass - 1.0) < 5e-3 and r.below < 5e-3, (spec, r.mass, r.below)


def _ggx_vndf_density(L, fr: Frame, alpha: float) -> np.ndarray:
    """Heitz 2018 eq. 3 over the reflection Jacobian, from the float64 references: G1(v) D(h) / (4 n.v)."""
    H = L + fr.V
    H /= np.linalg.norm(H, axis=1, keepdims=True)
    nv = fr.V @ fr.N
    g1 = 1.0 / (1.0 + lambda_ggx(np.array([nv]), alpha))
    c = H @ fr.N
    return g1 * d_ggx(c, 1.0 - c * c, alpha) / (4.0 * nv)


def test_pdf_at_the_samples_is_the_density_the_sampler_draws_from():
    fr = _frame(50.0)
    u = np.random.default_rng(3).random((5000, 2))
    draw, density = _sampler("microfacet(ndf=ggx)", {"alpha": 0.3}, fr)
    L = draw(u)
    up = L @ fr.N > 0
    p = density(L)
    assert np.all(np.isfinite(p)) and np.all(p[up] > 0) and np.all(p[~up] == 0)
    np.testing.assert_allclose(p[up], _ggx_vndf_density(L[up], fr, 0.3), rtol=1e-9)
    draw, density = _sampler("phong_normalized", {"n": 20.0}, fr)
    L = draw(u)
    up = L @ fr.N > 0
    R = 2 * (fr.V @ fr.N) * fr.N - fr.V
    np.testing.assert_allclose(density(L)[up], 21.0 / (2 * math.pi) * (L[up] @ R) ** 20, rtol=1e-9)
    for spec, params in CASES:  # every sampler draws only where its pdf is positive
        draw, density = _sampler(spec, params, fr)
        L = draw(u)
        up = L @ fr.N > 0
        p = density(L)
        assert np.all(np.isfinite(p)) and np.all(p[up] > 0), spec


def _albedo_quadrature(spec, params, fr: Frame, n: int = 192, channel: int = 0) -> float:
    x, w = np.polynomial.legendre.leggauss(n)
    mu, wm = (x + 1) / 2, w / 2
    phi, wp = (x + 1) * math.pi, w * math.pi
    M, P = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - M ** 2)
    L = fr.world((s * np.cos(P)).reshape(-1), (s * np.sin(P)).reshape(-1), M.reshape(-1))
    f = evaluate(spec, L, np.broadcast_to(fr.V, L.shape), np.broadcast_to(fr.N, L.shape),
                 T=np.broadcast_to(fr.T, L.shape), params=params, target="numpy")[:, channel]
    return float(np.sum(f * M.reshape(-1) * (wm[:, None] * wp[None, :]).reshape(-1)))


@pytest.mark.parametrize("spec, params", [
    ("lambert", {}), ("phong_normalized", {"n": 20.0}), ("blinn_phong_normalized", {"n": 30.0}),
    ("microfacet(ndf=ggx)", {"alpha": 0.5}), ("microfacet(ndf=beckmann_anisotropic)", {"alpha_u": 0.3, "alpha_v": 0.6}),
    ("ward_anisotropic", {"m_u": 0.3, "m_v": 0.5}), ("ashikhmin_shirley", {"n_u": 20.0, "n_v": 5.0}),
    ("lafortune(lobes=2)", {}),
])
def test_mc_albedo_with_the_bricks_sampler_matches_quadrature(spec, params):
    fr = _frame(35.0)
    n = 40_000
    u = np.random.default_rng(5).random((n, 2))
    draw, density = _sampler(spec, params, fr)
    L = draw(u)
    p = density(L)
    ok = p > 0
    f = evaluate(spec, L[ok], np.broadcast_to(fr.V, L[ok].shape), np.broadcast_to(fr.N, L[ok].shape),
                 T=np.broadcast_to(fr.T, L[ok].shape), params=params, target="numpy")[:, 0]
    est = np.zeros(n)
    est[ok] = f * (L[ok] @ fr.N) / p[ok]
    mc, err = est.mean(), est.std() / math.sqrt(n)
    quad = _albedo_quadrature(spec, params, fr)
    print(f"{spec}: MC albedo {mc:.5f} ± {err:.1e}, quadrature {quad:.5f}")
    assert abs(mc - quad) < 4 * err + 2e-3 * quad, (mc, err, quad)
