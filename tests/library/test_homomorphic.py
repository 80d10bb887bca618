"""Homomorphic factorization (generator/reference/tables_homomorphic.py, McCool et al. 2001) and the brick
`homomorphic_factorization` that samples its cube maps: the solve, its error, and the three languages."""
from __future__ import annotations

import numpy as np
import pytest

from generator.reference import tables
from generator.reference import tables_homomorphic as th

LANGS = ("glsl", "hlsl", "wgsl")
SIZE = 16  # the brick's declared cube size


def _separable(L, V):
    """An exactly separable f = p(l) q(h) p(v) with smooth, known, anisotropic, coloured factors."""
    def p(w):
        return (1.0 + 0.4 * w[:, 2:3] ** 2 + 0.2 * w[:, 0:1]) * np.array([1.0, 0.9, 0.8])

    def q(h):
        return np.exp(-(h[:, 0:1] ** 2 / 0.5 + h[:, 1:2] ** 2 / 0.2)) * np.array([2.0, 1.5, 1.0])
    return p(L) * q(th.half_vectors(L, V)) * p(V), p, q


def test_the_solve_is_deterministic_and_fixes_the_gauge_at_the_normal():
    L, V = th.sample_pairs((5, 10))
    f = th.target_brdf(L, V)
    a, b = th.factorize(L, V, f, 8), th.factorize(L, V, f, 8)
    assert a["P"].tobytes() == b["P"].tobytes() and a["Q"].tobytes() == b["Q"].tobytes()
    np.testing.assert_allclose(th.sample_cube(a["P"], np.array([0.0, 0.0, 1.0])), 1.0, rtol=1e-12)
    assert np.all(a["P"] > 0.0) and np.all(a["Q"] > 0.0)


def test_the_brick_tables_reduce_the_log_residual_and_approximate_the_albedo():
    """The fit of the brick's target (one cached solve for both tables) against the best constant, and the
    directional albedo ∫ f cos θ_i dω_i at normal view (the energy the factored BRDF reflects)."""
    sol = th.solved(SIZE)
    assert np.all(sol["residual"] < 0.1 * sol["baseline"]), (sol["residual"], sol["baseline"])
    p = tables.decoded(tables.baked("homomorphic_p", (SIZE, SIZE), "fp16"))
    q = tables.decoded(tables.baked("homomorphic_q", (SIZE, SIZE), "fp16"))
    assert p.shape == q.shape == (6, SIZE, SIZE, 4)
    L = th.hemisphere_grid(64, 128)
    V = np.broadcast_to([0.0, 0.0, 1.0], L.shape)
    ref = th.target_brdf(L, V)
    fit = th.sample_cube(p, L)[:, :3] * th.sample_cube(q, th.half_vectors(L, V))[:, :3] * th.sample_cube(p, V)[:, :3]
    albedo = [np.mean(x * L[:, 2:3], 0) * 2.0 * np.pi for x in (ref, fit)]
    assert np.all(np.abs(albedo[1] / albedo[0] - 1.0) < 0.12), albedo  # measured: 8.8–9.3 % low


def test_an_exactly_separable_brdf_is_recovered_to_the_cube_maps_interpolation_error():
    L, V = th.sample_pairs((8, 16))
    f, p, q = _separable(L, V)
    sol = th.factorize(L, V, f, SIZE)
    # the texels hold p and q up to the gauge (p(n) = 1 here): compare the product, at directions between texels
    Lt, Vt = th.sample_pairs((7, 13))
    want, _, _ = _separable(Lt, Vt)
    got = th.sample_cube(sol["P"], Lt) * th.sample_cube(sol["Q"], th.half_vectors(Lt, Vt)) * th.sample_cube(sol["P"], Vt)
    rel = np.abs(got / want - 1.0)
    # bilinear over a texel of ~2/16 rad, of factors whose log curves by ~1/0.2: ~1 % (median 0.9 %, 90th
    # percentile 2.9 %); 20 % at most where h grazes at an ±X/±Y face edge (q steep there, and clamped
    # within the face: the exp of a bilinear log against the bilinear of exps)
    assert np.median(rel) < 0.015 and np.percentile(rel, 90) < 0.05 and rel.max() < 0.25, rel.max()
    # and the factors themselves, gauge removed: P / p is one constant, Q / q its inverse square
    d = th.hemisphere_grid(6, 12)
    ratio = th.sample_cube(sol["P"], d) / p(d)
    dev = np.abs(ratio / ratio.mean(0) - 1.0)
    assert np.median(dev) < 0.01 and dev.max() < 0.08, dev.max()  # 6 % at most: grazing, at a face edge


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_the_brick_on_lavapipe_agrees_with_numpy(language):
    """The three cube look-ups on lavapipe against the NumPy target (the same fp16 texels), where every
    look-up is more than a texel from a face edge (Vulkan filters across edges, NumPy within a face)."""
    from generator.eval import accuracy
    from generator.eval.evaluate import evaluate
    from generator.library.bricks import load_library
    from generator.runtime.probe import lavapipe_present
    from tests.conftest import require

    require(lavapipe_present(), "no lavapipe Vulkan device")
    s = accuracy.hemisphere(6)
    lib = load_library()
    got = evaluate("homomorphic_factorization", s.L, s.V, s.N, s.T, target=language, lib=lib)
    want = evaluate("homomorphic_factorization", s.L, s.V, s.N, s.T, target="numpy", dtype="float32", lib=lib)
    B = np.cross(s.N, s.T)
    frame = np.stack([s.T, B, s.N], 1)  # rows t, b, n

    def local(w):
        return np.einsum("mij,mj->mi", frame, w)
    inner = np.ones(len(s.L), bool)
    for w in (local(s.L), local(s.V), th.half_vectors(local(s.L), local(s.V))):
        a = np.sort(np.abs(w), 1)
        inner &= a[:, 1] / a[:, 2] < 1.0 - 2.0 / SIZE
    assert inner.sum() > len(inner) // 8
    # lavapipe's bilinear weights carry 8 fractional bits: 1/512 of a texel step, relative to the texel value
    np.testing.assert_allclose(got[inner], want[inner], rtol=2e-2, atol=1e-7)
    assert np.all(np.isfinite(got))
