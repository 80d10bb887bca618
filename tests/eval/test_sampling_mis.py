"""One-sample MIS over a BRDF's terms in NumPy (generator.eval.sampling.mixture_*): the lecture's multi-layer rule.

u3.z picks term k with probability w_k(n·v), the terms' directional albedos at the material's parameters
(mis_weights, computed on the host); the pdf is Σ_k w_k pdf_k. Proven by the chi-square test of
tests/eval/chi2.py on two composite BRDFs of the example scene (scenes/example.toml), with the weights
checked against each term's albedo by quadrature, a wrong mixture pdf failing, and the MC albedo of the
whole BRDF with the mixture's samples matching quadrature.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from generator.eval import sampling
from generator.eval.evaluate import EvalError, evaluate

from .chi2 import chi2_test, sidak
from .test_sampling import N_SAMPLES, _albedo_quadrature, _frame

REPO = Path(__file__).resolve().parents[2]
SCENE = tomllib.loads((REPO / "scenes/example.toml").read_text())["materials"]
# the example scene's composite BRDFs with their own parameters: a diffuse base under a specular lobe
MIXTURES = [(SCENE[m]["brdf"], SCENE[m]["params"]) for m in ("red_plastic", "cobblestone")]
LEVEL = sidak(0.01, len(MIXTURES) * 2)  # the module's chi-square tests: two views per mixture


def _id(case):
    return case[0]


def _draw(spec, params, fr, weights=None):
    def draw(u3):
        return sampling.mixture_sample(spec, u3, fr.V[None], fr.N[None], fr.T[None], params=params, weights=weights)

    def density(L):
        return sampling.mixture_pdf(spec, L, fr.V[None], fr.N[None], fr.T[None], params=params, weights=weights)
    return draw, density


@pytest.mark.parametrize("view", [20.0, 70.0])
@pytest.mark.parametrize("case", MIXTURES, ids=_id)
def test_mixture_sampler_matches_its_pdf_chi_square(case, view):
    spec, params = case
    fr = _frame(view)
    draw, density = _draw(spec, params, fr)
    r = chi2_test(draw, density, fr, N_SAMPLES, seed=7, dims=3)
    print(f"{spec} at {view}°: p = {r.p_value:.3g} (chi2 {r.stat:.1f}, dof {r.dof}), mass {r.mass:.4f}")
    assert r.p_value > LEVEL, (r, LEVEL)


@pytest.mark.parametrize("case", MIXTURES, ids=_id)
def test_a_mixture_pdf_with_the_wrong_weights_fails(case):
    spec, params = case
    fr = _frame(20.0)
    draw, _ = _draw(spec, params, fr)
    w = sampling.mis_weights(spec, params)
    _, wrong = _draw(spec, params, fr, weights=w[:, [1, 0, 2, 3]])  # the terms' probabilities swapped
    r = chi2_test(draw, wrong, fr, N_SAMPLES, seed=7, dims=3)
    print(f"{spec}, weights swapped: p = {r.p_value:.3g}")
    assert r.p_value < LEVEL


@pytest.mark.parametrize("case", MIXTURES, ids=_id)
def test_weights_are_the_terms_albedos(case):
    """Row j of the table at n·v = j/7 holds each term's albedo (luminance), normalized: checked by quadrature."""
    spec, params = case
    w = sampling.mis_weights(spec, params)
    assert w.shape == (sampling.MIS_VIEWS, 4) and np.allclose(w.sum(axis=1), 1.0) and np.all(w[:, 2:] == 0.0)
    terms = [n.key for n in sampling.linked(spec).rb.nodes]
    lum = sampling.LUMINANCE
    for j in (2, 7):
        fr = _frame(math.degrees(math.acos(j / 7)), 0.0)
        a = []
        for t in terms:
            own = {k: v for k, v in params.items() if k in sampling.program(t).params}
            a.append(sum(c * _albedo_quadrature(t, own, fr, channel=i) for i, c in enumerate(lum)))
        print(f"{spec} at n.v = {j}/7: weights {w[j, :2].round(4)}, albedos by quadrature {np.round(a, 4)}")
        np.testing.assert_allclose(w[j, :2], np.array(a) / sum(a), atol=0.01)


def test_mixture_pdf_is_the_weighted_sum_of_the_terms_pdfs():
    spec, params = MIXTURES[1]
    fr = _frame(50.0)
    L = sampling.mixture_sample(spec, np.random.default_rng(2).random((2000, 3)), fr.V[None], fr.N[None],
                                fr.T[None], params=params)
    args = (L, fr.V[None], fr.N[None], fr.T[None])
    w = np.array([0.3, 0.7])
    np.testing.assert_allclose(sampling.mixture_pdf(spec, *args, params=params, weights=w),
                               sum(w[k] * sampling.pdf(spec, *args, params=params, term=k) for k in range(2)),
                               rtol=1e-12)
    one = sampling.mixture_sample(spec, np.random.default_rng(2).random((2000, 3)), fr.V[None], fr.N[None],
                                  fr.T[None], params=params, weights=[0.0, 1.0])  # weight 0: never picked
    u = np.random.default_rng(2).random((2000, 3))[:, :2]
    np.testing.assert_allclose(one, sampling.sample(spec, u, fr.V[None], fr.N[None], fr.T[None], params, term=1))
    with pytest.raises(EvalError, match="weights of shape"):
        sampling.mixture_pdf(spec, *args, params=params, weights=[1.0, 0.0, 0.0])


@pytest.mark.parametrize("case", MIXTURES, ids=_id)
def test_mc_albedo_with_the_mixture_matches_quadrature(case):
    spec, params = case
    fr = _frame(35.0)
    n = 40_000
    draw, density = _draw(spec, params, fr)
    L = draw(np.random.default_rng(5).random((n, 3)))
    p = density(L)
    ok = p > 0
    f = evaluate(spec, L[ok], np.broadcast_to(fr.V, L[ok].shape), np.broadcast_to(fr.N, L[ok].shape),
                 T=np.broadcast_to(fr.T, L[ok].shape), params=params, target="numpy")[:, 0]
    est = np.zeros(n)
    est[ok] = f * (L[ok] @ fr.N) / p[ok]
    mc, err = est.mean(), est.std() / math.sqrt(n)
    quad = _albedo_quadrature(spec, params, fr)
    print(f"{spec}: MC albedo {mc:.5f} ± {err:.1e} with the mixture, quadrature {quad:.5f}")
    assert abs(mc - quad) < 4 * err + 2e-3 * quad, (mc, err, quad)
