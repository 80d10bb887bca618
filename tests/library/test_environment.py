"""The environment kind and its brick, split_sum: the contract, and the brick against its float64 reference.

- split_sum on the NumPy target (float64, a mip chain of random cube levels and a random AmbientBRDF table)
  equals generator/reference/environment.py's split_sum to 1e-6 relative to the largest value (the brick's
  constants are the products Â_l · Y_lm's to 6 digits; measured 2.2e-7).
- An environment brick declares the contract's textures with their dimensions (kinds.ENVIRONMENT_TEXTURES):
  another name or a 2D radiance is a located error.
"""
from __future__ import annotations

import numpy as np
import pytest

from generator.lang import SourceError


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _inputs(rng, m=400):
    N = rng.normal(size=(m, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    V = rng.normal(size=(m, 3))
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    V = np.where((np.einsum("ij,ij->i", N, V) < 0)[:, None], -V, V)
    return N, V


def test_split_sum_equals_its_float64_reference_in_numpy(lib):
    from generator.backends import get_target
    from generator.reference.environment import ENVIRONMENTS

    b = lib.get("environment", "split_sum")
    nt = get_target("numpy")
    fns = nt.load(nt.emit([], list(b.module.functions.values())), np.float64)
    rng = np.random.default_rng(5)
    N, V = _inputs(rng)
    kd, f0, alpha = rng.uniform(0, 1, (len(N), 3)), rng.uniform(0, 1, (len(N), 3)), rng.uniform(0, 1, len(N))
    sh = rng.normal(size=(9, 3))
    levels = [rng.uniform(0, 2, (6, s, s, 4)) for s in (8, 4, 2, 1)]
    table = rng.uniform(0, 1, (32, 32, 4))
    got = fns["ambient"](N, V, kd, f0, alpha, *sh, 0.7, float(len(levels)), levels, table)
    want = ENVIRONMENTS["split_sum"](N, V, kd, f0, alpha, sh, 0.7, levels, table)
    assert np.abs(got - want).max() <= 1e-6 * np.abs(want).max()
    # a constant environment: E = π L_00 Y_00 · … = π L (the SH9 of a constant L is L_00 = L · 2 √π)
    flat = np.zeros((9, 3))
    flat[0] = 2.0 * np.sqrt(np.pi)
    one = [np.ones((6, s, s, 4)) for s in (4, 2, 1)]
    white = np.ones((32, 32, 4))
    got = fns["ambient"](N, V, np.ones(3), np.zeros(3), 0.5, *flat, 1.0, 3.0, one, white)
    np.testing.assert_allclose(got, 2.0, rtol=1e-5)  # kd B E/π = 1, plus the cube's 1 × (0 · R + G = 1)


def test_the_numpy_target_reads_a_mip_chain_at_its_lod(lib):
    """sample_level of a list of levels: linear between the two levels around the lod (mipmapMode LINEAR)."""
    from generator.backends.numpy.resources import _lod, _texcube

    levels = [np.full((6, 4, 4, 4), 1.0), np.full((6, 2, 2, 4), 3.0), np.full((6, 1, 1, 4), 7.0)]
    d = np.array([[0.3, 0.8, -0.2]] * 5)
    got = _lod(_texcube, levels, d, np.array([0.0, 0.5, 1.0, 1.75, 9.0]))[:, 0]
    np.testing.assert_allclose(got, [1.0, 2.0, 3.0, 6.0, 7.0])
    assert _lod(_texcube, levels[1], d, np.full(5, 2.0))[0, 0] == 3.0  # one array: one level, whatever the lod


def _brick(tmp_path, textures: str, sig: str):
    from generator.library.bricks import load_brick
    p = tmp_path / "env.py"
    p.write_text('"""An environment."""\nBRICK = {"kind": "environment", "cite": "x 2000",\n'
                 f'         "textures": {textures}}}\n\n\n'
                 f"def ambient(N: vec3, V: vec3, {sig}) -> vec3:\n    return N\n")
    return load_brick(p)


def test_an_environment_brick_declares_the_contract_textures(tmp_path):
    ok = _brick(tmp_path, '{"radiance": {}, "ambient_brdf": {}}', "radiance: texturecube, ambient_brdf: texture2d")
    assert ok.kind == "environment"
    with pytest.raises(SourceError) as e:
        _brick(tmp_path, '{"radiance": {}, "sky": {}}', "radiance: texturecube, sky: texture2d")
    assert "env.py:3:" in str(e.value) and "'radiance' (cube), 'ambient_brdf' (2d)" in str(e.value)
    with pytest.raises(SourceError) as e:
        _brick(tmp_path, '{"radiance": {}, "ambient_brdf": {}}', "radiance: texture2d, ambient_brdf: texture2d")
    assert "env.py:6:" in str(e.value) and "texturecube" in str(e.value)
