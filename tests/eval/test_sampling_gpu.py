"""The samplers on lavapipe: the mixture's sample and pdf kernels in GLSL, HLSL and WGSL (eval kernel machinery).

Per sampled brick, per composite BRDF of the example scene, and per language: uniforms u3 drawn on the host
with a fixed seed, L and pdf(L) from the GPU (float32, validation layer on: any message fails), and
- the chi-square test of tests/eval/chi2.py (Mitsuba's and pbrt's method) of the GPU's L against the NumPy
  float64 density, at significance 0.01 Šidák-corrected over every chi-square test of this module (the slow
  sweep's included);
- the GPU's pdf at its own samples against the NumPy float64 pdf of the same (float32) L:
  |pdf32 - pdf64| <= EPS32 (64 + 4 κ) pdf64 + 2^-20 max pdf64, κ the lobe's sharpness (the largest exponent,
  or 2/α² for a roughness α: test_eval.py's condition number); the absolute floor is for samples near the
  horizon, where n·l, rounded to 1 ulp of 1, is a small cosine (cos θ / π loses its relative accuracy there);
  and exactly 0 on both where either is 0. Measured worst case over the default cases: 9.7e-6 relative
  (lambert+blinn_phong_normalized, n = 64: 0.25 of its bound).
The default run draws 2·10⁴ samples per test at one parameter set; `-m slow` runs test_sampling.py's sweep.
"""
from __future__ import annotations

import numpy as np
import pytest

from generator.eval import sampling
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

from .chi2 import chi2_test, sidak
from .test_sampling import CASES, SWEEP, _frame
from .test_sampling import _id as _case_id
from .test_sampling_mis import MIXTURES

pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]  # compiles and runs kernels

LANGS = sampling.GPU_TARGETS
N_GPU = 20_000
EPS32 = float(np.finfo(np.float32).eps)
ATOL_SCALE = 2.0 ** -20  # of the batch's largest pdf, as tests/eval/test_eval.py's floor for f_r
DEFAULT = CASES + MIXTURES
LEVEL = sidak(0.01, (len(DEFAULT) + len(SWEEP) + 1) * len(LANGS))  # + 1: the wrong pdf, which must fail
EXPONENTS = ("n", "n_u", "n_v")
ROUGHNESS = ("alpha", "alpha_u", "alpha_v", "m", "m_u", "m_v")


def _kappa(params: dict) -> float:
    k = [float(params[p]) for p in EXPONENTS if p in params]
    k += [2.0 / float(params[p]) ** 2 for p in ROUGHNESS if p in params]
    return max(k, default=0.0)


def _gpu(spec, params, fr, lang, session, weights=None):
    args = (fr.V[None], fr.N[None], fr.T[None])

    def draw(u3):
        L = sampling.mixture_sample(spec, u3, *args, params=params, target=lang, session=session)
        p32 = sampling.mixture_pdf(spec, L, *args, params=params, target=lang, session=session)
        p64 = sampling.mixture_pdf(spec, L.astype(np.float32).astype(np.float64), *args, params=params)
        rtol = EPS32 * (64.0 + 4.0 * _kappa(params))
        assert np.array_equal(p32 > 0.0, p64 > 0.0), f"{spec}: pdf 0 on one side only"
        bound = rtol * p64 + ATOL_SCALE * p64.max()
        worst = float(np.max(np.abs(p32 - p64) / bound))
        rel = float(np.max(np.abs(p32 - p64) / np.where(p64 > 0.0, p64, 1.0)))
        print(f"{spec} {lang}: pdf(sample) float32 vs float64 worst relative {rel:.2e}, {worst:.2f} of the bound")
        assert worst <= 1.0, (spec, lang, worst, rel, rtol)
        return L

    def density(L):
        return sampling.mixture_pdf(spec, L, *args, params=params, weights=weights)
    return draw, density


@pytest.mark.parametrize("lang", LANGS)
@pytest.mark.parametrize("case", DEFAULT, ids=_case_id)
def test_gpu_sampler_matches_its_pdf_chi_square(case, lang, device, eval_session):
    spec, params = case
    fr = _frame()
    draw, density = _gpu(spec, params, fr, lang, eval_session)
    r = chi2_test(draw, density, fr, N_GPU, seed=7, dims=3)
    print(f"{spec} {lang}: p = {r.p_value:.3g} (chi2 {r.stat:.1f}, dof {r.dof}), below {r.below:.4f}")
    assert r.p_value > LEVEL, (r, LEVEL)


@pytest.mark.parametrize("lang", LANGS)
def test_gpu_samples_fail_against_a_wrong_mixture_pdf(lang, device, eval_session):
    spec, params = MIXTURES[0]
    fr = _frame()
    w = sampling.mis_weights(spec, params)
    draw, density = _gpu(spec, params, fr, lang, eval_session, weights=0.5 * w + 0.5 * w[:, [1, 0, 2, 3]])
    r = chi2_test(draw, density, fr, N_GPU, seed=7, dims=3)
    print(f"{spec} {lang} against the pdf of half-swapped weights: p = {r.p_value:.3g}")
    assert r.p_value < LEVEL


@pytest.mark.slow
@pytest.mark.parametrize("lang", LANGS)
@pytest.mark.parametrize("case", SWEEP, ids=_case_id)
def test_gpu_sampler_sweep_chi_square(case, lang, device, eval_session):
    spec, params, view = case
    fr = _frame(view)
    draw, density = _gpu(spec, params, fr, lang, eval_session)
    r = chi2_test(draw, density, fr, 100_000, seed=7, q=32, dims=3)
    print(f"{spec} {params} at {view}° {lang}: p = {r.p_value:.3g}")
    assert r.p_value > LEVEL, (r, LEVEL)
