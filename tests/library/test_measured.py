"""Measured BRDFs (MERL binary, generator/reference/measured.py) as the source of the homomorphic factorization:
the reader against files this test writes itself from an analytic BRDF, the factorization of such a file
against that of the model, malformed files, and `shadermatrix tables --bake … --measured`."""
from __future__ import annotations

import struct
import subprocess
import sys

import numpy as np
import pytest

from generator.lang import SourceError
from generator.reference import measured as me
from generator.reference import tables_homomorphic as th

DIMS = (40, 36, 72)  # n_θh, n_θd, n_φd: small, and all different, so a transposed axis cannot pass
F0 = np.array([0.95, 0.64, 0.54])  # copper-like, as HOMOMORPHIC_TARGET: the three channels differ
# Written here, not by measured.py: the format as MERL's reference reader states it (module docstring).
SCALE = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)


def _model(L, V):
    """An isotropic Ashikhmin-Shirley (n_u = n_v = 8): the reference of HOMOMORPHIC_TARGET's model, made
    isotropic because the MERL parameterization ignores φ_h."""
    from generator.reference.geometry import shading_geometry
    from generator.reference.specular import ashikhmin_shirley
    n = len(L)
    g = shading_geometry(L, V, np.broadcast_to([0.0, 0.0, 1.0], (n, 3)), np.broadcast_to([1.0, 0.0, 0.0], (n, 3)))
    return np.asarray(ashikhmin_shirley(g, {"n_u": 8.0, "n_v": 8.0, "f0": np.broadcast_to(F0, (n, 3))}, {}))


def _grid_directions(dims, offset=0.0):
    """L, V (n_θh · n_θd · n_φd, 3) at the grid angles θ_h = (i/n)² π/2, θ_d = j/n · π/2, φ_d = k/n · π
    (φ_h = 0), offset in index units: h = (sin θ_h, 0, cos θ_h), l = R_y(θ_h) d, v = l reflected about h."""
    nh, nd, n_p = dims
    th_, td, pd = np.meshgrid(((np.arange(nh) + offset) / nh) ** 2 * np.pi / 2,
                              (np.arange(nd) + offset) / nd * np.pi / 2,
                              (np.arange(n_p) + offset) / n_p * np.pi, indexing="ij")
    th_, td, pd = th_.ravel(), td.ravel(), pd.ravel()
    d = np.stack([np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)], -1)
    c, s = np.cos(th_), np.sin(th_)
    L = np.stack([d[:, 0] * c + d[:, 2] * s, d[:, 1], -d[:, 0] * s + d[:, 2] * c], -1)
    H = np.stack([s, np.zeros_like(s), c], -1)
    return L, 2.0 * np.sum(L * H, -1, keepdims=True) * H - L, (th_, td, pd)


def _write(path, dims, brdf, unmeasured=None):
    """A MERL file of brdf(L, V) at the grid; -1 (not measured) below the horizon and where unmeasured(θ_d)."""
    L, V, (_, td, _) = _grid_directions(dims)
    ok = (L[:, 2] > 0.0) & (V[:, 2] > 0.0)
    if unmeasured is not None:
        ok &= ~unmeasured(td)
    f = np.full((len(L), 3), -1.0)
    f[ok] = brdf(L[ok], V[ok]) / np.array(SCALE)
    path.write_bytes(struct.pack("<3i", *dims) + np.ascontiguousarray(f.T).astype("<f8").tobytes())
    return f * np.array(SCALE), ok


@pytest.fixture(scope="module")
def merl_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("merl") / "copper_as8.binary"
    f, ok = _write(path, DIMS, _model)
    return path, f, ok


def test_the_file_reads_back_at_its_grid_points(merl_file):
    path, f, ok = merl_file
    m = me.read_merl(path)
    assert m.dims == DIMS and m.f.shape == (3, *DIMS)
    # the layout: channel-major, θ_h slowest, φ_d fastest; scaled to 1/sr; unmeasured samples NaN
    grid = m.f.reshape(3, -1).T
    np.testing.assert_allclose(grid[ok], f[ok], rtol=1e-15, atol=0.0)
    assert np.all(np.isnan(grid[~ok]))
    # the half/difference angles of the grid's directions are the grid's angles (φ_d modulo π)
    L, V, (th_, td, pd) = _grid_directions(DIMS)
    gh, gd, gp = me.half_diff(L, V)
    assert np.abs(gh - th_).max() < 1e-12 and np.abs(gd - td).max() < 1e-7  # arccos near θ_d = 0: √ε
    dp = np.abs(np.mod(gp - pd + np.pi / 2, np.pi) - np.pi / 2)
    assert dp[td > 1e-3].max() < 1e-9  # φ_d is undefined at θ_d = 0
    # trilinear at the grid points, and the reference reader's truncation in the middle of each cell
    np.testing.assert_allclose(m(L[ok], V[ok]), f[ok], rtol=1e-6)
    Lm, Vm, _ = _grid_directions(DIMS, offset=0.5)
    floor = m(Lm, Vm, mode="floor")
    np.testing.assert_allclose(floor[ok], f[ok], rtol=1e-12)
    # and between them the lookup follows the model (a lobe on 40 samples of √θ_h)
    Lt, Vt = th.sample_pairs((7, 13))
    rel = np.abs(m(Lt, Vt) / _model(Lt, Vt) - 1.0)
    assert np.median(rel) < 0.02, np.median(rel)  # measured 0.7 %


def test_factorizing_the_file_matches_factorizing_the_model(merl_file):
    path, _, _ = merl_file
    m = me.read_merl(path)
    L, V = th.sample_pairs((8, 16))
    from_file, from_model = th.factorize(L, V, m(L, V), 8), th.factorize(L, V, _model(L, V), 8)
    assert from_file["used"] == from_file["samples"] == len(L)  # the upper hemisphere is measured here
    np.testing.assert_allclose(from_file["residual"], from_model["residual"], rtol=0.05)

    def product(s, L, V):
        return th.sample_cube(s["P"], L) * th.sample_cube(s["Q"], th.half_vectors(L, V)) * th.sample_cube(s["P"], V)
    Lt, Vt = th.sample_pairs((7, 13))
    a, b = product(from_file, Lt, Vt), product(from_model, Lt, Vt)
    rel = np.abs(a / b - 1.0)
    w = Lt[:, 2:3] * Vt[:, 2:3]  # cos θ_i cos θ_o: where the light is
    l2 = np.sqrt(np.sum(w * (a - b) ** 2, 0) / np.sum(w * b * b, 0))
    assert np.median(rel) < 0.03 and np.all(l2 < 0.02), (np.median(rel), l2)  # measured 1.1 %, 0.56–0.66 %


def test_unmeasured_samples_are_skipped(tmp_path):
    """A file measured only where θ_d ≤ 60° (and above the horizon): the lookup is NaN beyond, as the file
    without the cut within, and the solve fits the measured pairs only."""
    dims, cell = (12, 10, 16), np.pi / 2 / 10  # one θ_d cell
    _write(tmp_path / "all.binary", dims, _model)
    _write(tmp_path / "cut.binary", dims, _model, unmeasured=lambda td: td > np.pi / 3)
    full, m = me.read_merl(tmp_path / "all.binary"), me.read_merl(tmp_path / "cut.binary")
    assert 0.3 < m.measured_fraction < full.measured_fraction
    L, V = th.sample_pairs((6, 12))
    f, f_full = m(L, V), full(L, V)
    _, td, _ = me.half_diff(L, V)
    assert np.all(np.isnan(f[td > np.pi / 3 + cell]))
    inner = td < np.pi / 3 - cell
    assert np.array_equal(np.isnan(f[inner]), np.isnan(f_full[inner])) and np.isfinite(f[inner]).all(1).mean() > 0.8
    sol = th.factorize(L, V, f, 4)
    assert 0 < sol["used"] < sol["samples"] == len(L)
    assert sol["used"] == int(np.isfinite(f).all(1).sum()) and np.all(np.isfinite(sol["P"]))


def _header(*dims):
    return struct.pack("<3i", *dims)


@pytest.mark.parametrize("content, words", [
    (b"\x5a\x00\x00", "shorter than the 12-byte header"),
    (_header(0, 90, 180), "not all positive"),
    (_header(-90, 90, 180), "not all positive"),
    (_header(100000, 100000, 100000), "more than the"),
    (_header(2, 2, 2) + b"\0" * (24 * 8 - 8), "truncated"),
    (_header(2, 2, 2) + b"\0" * (24 * 8 + 1), "longer than its header says"),
    (_header(1, 1, 1) + struct.pack("<3d", 1.0, float("nan"), 1.0), "not a finite number"),
    (_header(1, 1, 2) + struct.pack("<6d", *[-1.0] * 6), "no sample is measured"),
])
def test_a_malformed_file_is_an_error_naming_it(content, words, tmp_path):
    path = tmp_path / "bad.binary"
    path.write_bytes(content)
    with pytest.raises(SourceError, match=words) as e:
        me.read_merl(path)
    assert str(e.value).startswith(f"{path}:1:1: ") and " — " in str(e.value)


def test_a_missing_file_or_a_directory_is_an_error_naming_it(tmp_path):
    for path, words in ((tmp_path / "none.binary", "cannot read"), (tmp_path, "not a regular file")):
        with pytest.raises(SourceError, match=words) as e:
            me.read_merl(path)
        assert str(e.value).startswith(f"{path}:1:1: ")


def test_the_cli_bakes_both_factors_from_a_measured_file(merl_file, tmp_path):
    from generator.io.ktx2 import decode

    path, _, _ = merl_file

    def cli(*a):
        return subprocess.run([sys.executable, "-m", "generator.cli", "tables", *a], capture_output=True, text=True,
                              timeout=120)
    for name in me.MEASURED_TABLES:
        out = tmp_path / f"{name}.ktx2"
        r = cli("--bake", name, "--measured", str(path), "--out", str(out), "--size", "8x8")
        assert r.returncode == 0, r.stderr
        assert f"{len(th.sample_pairs()[0])} of {len(th.sample_pairs()[0])} sample pairs measured" in r.stdout
        texels, fmt, cube = decode(out.read_bytes(), str(out))
        assert cube and fmt == "fp16" and texels.shape == (6, 8, 8, 4)
        want, info = me.bake_measured(name, path, (8, 8), "fp16")  # the same bytes in this process
        assert np.array_equal(texels, want) and np.all(np.isfinite(texels.astype(np.float64)))
    r = cli("--bake", "oren_nayar_sin_sin", "--measured", str(path), "--out", str(tmp_path / "x.ktx2"))
    assert r.returncode == 2 and "--measured goes with --bake homomorphic_p or homomorphic_q" in r.stderr
    bad = tmp_path / "short.binary"
    bad.write_bytes(_header(90, 90, 180) + b"\0" * 64)
    r = cli("--bake", "homomorphic_q", "--measured", str(bad), "--out", str(tmp_path / "y.ktx2"), "--size", "8x8")
    assert r.returncode == 1 and r.stderr.startswith(f"error: {bad}:1:1: the file is truncated")
    assert "Traceback" not in r.stderr and not (tmp_path / "y.ktx2").exists()
    assert cli("--measured", str(path)).returncode == 2  # without --bake
