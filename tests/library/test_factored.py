"""Factored (lookup-table) specular bricks: blinn_phong_factored, banks_factored,
ashikhmin_shirley_factored and the diffuse half ashikhmin_shirley_diffuse_factored, against their direct
references within their declared tolerances; the remap constants at texel centres; reciprocity; the GPU
languages on lavapipe against NumPy."""
from __future__ import annotations

import numpy as np
import pytest

from generator.eval import accuracy
from generator.eval.evaluate import evaluate
from generator.library.bricks import load_library
from generator.reference import tables
from generator.reference.tables_specular import banks_coordinate, bp_coordinates, bp_exponent

LIB = load_library()
FACTORED = {"blinn_phong_factored": "blinn_phong_normalized", "banks_factored": "banks",
            "ashikhmin_shirley_factored": "ashikhmin_shirley",
            "ashikhmin_shirley_diffuse_factored": "ashikhmin_shirley_diffuse"}


def _brick(spec):
    return LIB.bricks[("diffuse" if "diffuse" in spec else "specular", spec)]


def _rel(got, ref):
    return float((np.abs(got - ref) / np.maximum(np.abs(ref), accuracy.REL_FLOOR)).max())


@pytest.mark.parametrize("spec", sorted(FACTORED))
def test_factored_brick_is_within_its_tolerance_of_the_direct_model(spec):
    s = accuracy.hemisphere(8)
    tol = _brick(spec).tolerance
    assert 0.0 < tol < 0.5
    got = evaluate(spec, s.L, s.V, s.N, s.T, target="numpy", dtype="float64", lib=LIB)
    ref = evaluate(FACTORED[spec], s.L, s.V, s.N, s.T, target="reference", lib=LIB)
    assert _rel(got, ref) <= tol, spec


def test_blinn_phong_table_is_exact_at_texel_centres_up_to_its_format():
    """At the table's texel centres the brick's remap lands on a texel: only fp32 rounding is left."""
    w, h = _brick("blinn_phong_factored").textures["bp_pow"]["size"]
    j = np.array([0, 17, 64, h - 1])
    ns = np.minimum(bp_exponent(tables.axis(h)[j]), 1e5)
    i = np.array([0, 5, 100, w - 2])
    for n in ns:
        x = tables.axis(w)[i]
        cos_h = 1.0 - x * 24.0 / max(n, 24.0)
        xb, yb = bp_coordinates(cos_h, n)
        assert np.allclose(xb, x, atol=1e-12)
        N = np.tile([0.0, 0.0, 1.0], (len(i), 1))
        st = np.sqrt(np.maximum(1.0 - cos_h ** 2, 0.0))
        H = np.stack([st, np.zeros_like(st), cos_h], -1)
        L = V = H  # l = v = h: n·h = cos_h
        p = {"n": float(n), "f0": [1.0, 1.0, 1.0]}
        got = evaluate("blinn_phong_factored", L, V, N, None, p, target="numpy", dtype="float64", lib=LIB)[:, 0]
        ref = (n + 4.0) / (8.0 * np.pi) * np.maximum(cos_h, 0.0) ** n
        # float32 storage: 2^-24 relative per texel, and cos_h computed from x carries ~1e-16·n
        assert np.all(np.abs(got - ref) <= 2e-7 * ref + 1e-12 * n), (n, got, ref)


def test_banks_and_as_diffuse_tables_are_exact_at_texel_centres_up_to_their_format():
    w = _brick("banks_factored").textures["banks_kernel"]["size"][0]
    x = tables.axis(w)[[3, 60, 128, 200, w - 1]]
    a = np.sign(2 * x - 1) * (1 - (1 - np.abs(2 * x - 1)) ** 2)
    assert np.allclose(banks_coordinate(a), x, atol=1e-12)
    got = tables.bilinear(tables.baked("banks_bracket", (w, w), "fp32"),
                          tables.texel_coordinate(x, w), tables.texel_coordinate(x[::-1], w))[:, 0]
    want = tables.lookup("banks_bracket").exact(x, x[::-1])[:, 0]
    assert np.abs(got - want).max() <= 1e-7
    t = _brick("ashikhmin_shirley_diffuse_factored").textures["as_factor"]
    wd = t["size"][0]
    xd = tables.axis(wd)
    got = tables.bilinear(tables.baked(t["table"], t["size"], t["format"]), tables.texel_coordinate(xd, wd),
                          np.full_like(xd, 0.5))[:, 0]
    poly = (1.0 - (1.0 - xd / 2.0) ** 5) / np.maximum(2.5 * xd, 1e-300)
    poly[0] = 1.0
    assert np.abs(got - poly).max() <= 2.0 ** -11  # fp16: half an ulp of values in [0.5, 1]


@pytest.mark.parametrize("spec", sorted(FACTORED))
def test_factored_brick_is_reciprocal(spec):
    s = accuracy.hemisphere(6)
    a = evaluate(spec, s.L, s.V, s.N, s.T, target="numpy", dtype="float64", lib=LIB)
    b = evaluate(spec, s.V, s.L, s.N, s.T, target="numpy", dtype="float64", lib=LIB)
    keep = (np.einsum("ij,ij->i", s.L, s.N) > 1e-3) & (np.einsum("ij,ij->i", s.V, s.N) > 1e-3)  # glue clamps
    assert _rel(a[keep], b[keep]) <= 1e-9, spec


@pytest.mark.toolchain
@pytest.mark.lavapipe
@pytest.mark.parametrize("target", ["glsl", "hlsl", "wgsl"])
def test_gpu_languages_agree_with_numpy(target):
    """The GPU samples the same texels (bilinear; its filter weights have a few bits less than NumPy's)."""
    s = accuracy.hemisphere(5)
    for spec in sorted(FACTORED):
        want = evaluate(spec, s.L, s.V, s.N, s.T, target="numpy", dtype="float32", lib=LIB)
        got = evaluate(spec, s.L, s.V, s.N, s.T, target=target, dtype="float32", lib=LIB)
        assert _rel(got, want) <= _brick(spec).tolerance, (spec, target)
