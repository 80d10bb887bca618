"""The numpy target: emitted code runs bricks vectorized on the CPU, lane-exact against scalar Python."""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from generator.lang import parse_module
from generator.backends.numpy.emit import NumpyTarget

BRICKS = Path(__file__).parents[1] / "bricks" / "lang"
DTYPES = (np.float16, np.float32, np.float64)
N = 257


def emit(name: str):
    path = BRICKS / name
    module = parse_module(path.read_text(), str(path))
    target = NumpyTarget()
    return target, target.emit(list(module.structs.values()), list(module.functions.values()))


@pytest.fixture(scope="module")
def control():
    target, emitted = emit("numpy_control.py")
    return {np.dtype(d).name: target.load(emitted, d) for d in DTYPES}


@pytest.fixture(scope="module")
def intr():
    target, emitted = emit("numpy_intrinsics.py")
    return {np.dtype(d).name: target.load(emitted, d) for d in DTYPES}


@pytest.fixture
def rng():
    return np.random.default_rng(1234)


@pytest.fixture(autouse=True)
def no_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # masked-out lanes and IEEE specials must not warn
        yield


# ---------------------------------------------------------------- control flow

def classify_ref(x: float, y: float) -> float:
    a = x * y
    if x > 0.5:
        if y > 0.0:
            return a + 1.0
        a = a * 2.0
    elif x < -0.5:
        b = x - y
        if b > 0.25:
            return b
        a = a + b
    else:
        a = a - 3.0
    if a > 0.0 and not (y < -0.75):
        return math.sqrt(a)
    a += 0.5 if y > 0.0 else -0.5
    return a * 10.0


def test_if_elif_else_with_early_returns_matches_scalar_evaluation_per_lane(control, rng):
    x, y = rng.uniform(-1, 1, N), rng.uniform(-1, 1, N)
    got = control["float64"]["classify"](x, y)
    want = np.array([classify_ref(a, b) for a, b in zip(x, y)])
    assert got.shape == (N,) and got.dtype == np.float64
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=0)
    # every path of the function is taken by some lane
    paths = {(a > 0.5, a < -0.5, b > 0) for a, b in zip(x, y)}
    assert len(paths) == 6


def accumulate_ref(x, v):
    acc, s = [0.0, 0.0, 0.0], 0.0
    for i in range(4):
        s += i * 0.5
        if x > s:
            acc[0] += x
            acc[1] = acc[1] + s
        acc[2] = acc[2] + v[i % 3]
    return acc


def test_for_loop_with_masked_component_assignment(control, rng):
    x, v = rng.uniform(-0.5, 2.0, N), rng.normal(size=(N, 3))
    got = control["float64"]["accumulate"](x, v)
    want = np.array([accumulate_ref(a, b) for a, b in zip(x, v)])
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-15)


def test_parameters_are_copied_not_mutated(control, rng):
    fns = control["float64"]
    v, c, x = rng.normal(size=(N, 3)), rng.normal(size=(N, 3)), rng.normal(size=N)
    r, n = rng.uniform(0, 1, N), np.arange(N, dtype=np.int32)
    s = fns["Surface"](c, r, n)
    v0, c0, r0 = v.copy(), c.copy(), r.copy()
    got = fns["mutate"](v, s, x)
    assert np.array_equal(v, v0) and np.array_equal(c, c0) and np.array_equal(r, r0)
    assert s.albedo is c and s.rough is r  # the caller's struct is untouched
    w = v.copy()
    w[:, 0] = 7.0
    pos = x > 0
    w[pos] *= 2.0
    w[pos, 2] = -1.0
    alb = c.copy()
    alb[:, 1] = x
    np.testing.assert_allclose(got, w + alb * (2.0 * r)[:, None], rtol=1e-15)


def test_struct_construction_member_access_and_masked_field_assignment(control, rng):
    fns = control["float64"]
    c, r, n = rng.normal(size=(N, 3)), rng.uniform(0, 1, N), rng.integers(-5, 5, N).astype(np.int32)
    s = fns["make_surface"](c, r, n)
    assert type(s).__name__ == "Surface"
    assert s.count.dtype == np.int32
    np.testing.assert_array_equal(s.count, np.where(r > 0.5, 2 * n + 1, n))
    np.testing.assert_array_equal(s.albedo, c)
    np.testing.assert_allclose(fns["surface_sum"](s), c.sum(axis=1) + r + s.count, rtol=1e-14)


def test_matrix_construction_and_products_match_einsum(control, rng):
    c0, c1, c2, v = (rng.normal(size=(N, 3)) for _ in range(4))
    got = control["float64"]["transform"](c0, c1, c2, v)
    m = np.stack([c0, c1, c2], axis=-1)  # columns
    w = np.einsum("nij,nj->ni", m, v)
    u = np.einsum("ni,nij->nj", v, m)
    p = np.einsum("nij,njk->nik", m, m)
    np.testing.assert_allclose(got, w + u[:, ::-1] + p[:, :, 1] + 0.5 * c2, rtol=1e-12, atol=1e-12)


def test_swizzles_and_vector_constructors(control, rng):
    v, a = rng.normal(size=(N, 4)), rng.normal(size=(N, 2))
    got = control["float64"]["swz"](v, a)
    b = v[:, ::-1]
    c = np.concatenate([a, v[:, :2]], axis=1)
    d = np.concatenate([a[:, 1:], v[:, 2:]], axis=1)
    want = b + c * d[:, :1] + np.concatenate([d, a[:, :1]], axis=1)
    np.testing.assert_allclose(got, want, rtol=1e-15)


def test_select_and_conditional_expression(control, rng):
    x, a, b = rng.uniform(-1, 1, N), rng.normal(size=(N, 3)), rng.normal(size=(N, 3))
    got = control["float64"]["choose"](x, a, b)
    want = np.where((x > 0)[:, None], a, b) + np.where((x < 0.5)[:, None], a, b)
    np.testing.assert_array_equal(got, want)


def test_int_division_truncates_toward_zero(control):
    i = np.array([-7, 7, -7, 7, 5, -1], np.int32)
    j = np.array([2, -2, -2, 2, 3, 4], np.int32)
    got = control["float64"]["ints"](i, j)
    assert got.dtype == np.int32

    def ref(a, b):
        k = int(a / b) + int(math.fmod(a, b))
        k -= abs(a) * 2
        return max(k, min(a, b)) + (b > 0) - (b < 0)

    assert got.tolist() == [ref(a, b) for a, b in zip(i.tolist(), j.tolist())]


@pytest.mark.parametrize("dtype", DTYPES)
def test_control_outputs_keep_the_working_dtype(control, rng, dtype):
    fns = control[np.dtype(dtype).name]
    x, y = rng.uniform(-1, 1, N).astype(dtype), rng.uniform(-1, 1, N).astype(dtype)
    v = rng.normal(size=(N, 3)).astype(dtype)
    assert fns["classify"](x, y).dtype == dtype
    assert fns["accumulate"](x, v).dtype == dtype
    assert fns["transform"](v, v, v, v).dtype == dtype
    assert fns["choose"](x, v, v).dtype == dtype
    assert fns["swz"](np.ones((N, 4), dtype), np.ones((N, 2), dtype)).dtype == dtype


# ---------------------------------------------------------------- intrinsics

def intrinsic_inputs(rng, dtype=np.float64):
    x = rng.uniform(-1, 1, N)
    x[:4] = [0.0, -0.0, 1.0, -1.0]
    y = rng.uniform(-2, 2, N)
    a, b = rng.normal(size=(N, 3)), rng.uniform(0.1, 2.0, size=(N, 3))
    i, j = rng.integers(-9, 9, N).astype(np.int32), rng.integers(-9, 9, N).astype(np.int32)
    return [x.astype(dtype), y.astype(dtype), a.astype(dtype), b.astype(dtype), i, j]


def intrinsic_reference(x, y, a, b, i, j):
    ax = np.abs(x)
    col = lambda s: s[:, None]  # noqa: E731
    smooth = lambda e0, e1, v: (lambda t: t * t * (3 - 2 * t))(np.clip((v - e0) / (e1 - e0), 0, 1))  # noqa: E731
    n = b / np.linalg.norm(b, axis=1, keepdims=True)
    return dict(
        f_abs=ax, f_sign=np.sign(x), f_floor=np.floor(3 * x), f_fract=3 * x - np.floor(3 * x),
        f_saturate=np.clip(2 * x, 0, 1), f_sqrt=np.sqrt(ax), f_rsqrt=1 / np.sqrt(ax + 0.1), f_exp=np.exp(x),
        f_exp2=2.0 ** x, f_log=np.log(ax + 0.01), f_log2=np.log2(ax + 0.01), f_sin=np.sin(x), f_cos=np.cos(x),
        f_tan=np.tan(x), f_asin=np.arcsin(x), f_acos=np.arccos(x), f_atan=np.arctan(x), f_atan2=np.arctan2(y, x),
        f_pow=ax ** y, f_step=(x >= 0.1).astype(float), f_min=np.minimum(x, y), f_max=np.maximum(x, y),
        f_clamp=np.clip(x, -0.25, 0.5), f_smooth=smooth(-0.5, 0.5, x), f_mix=x + (y - x) * 0.25,
        f_select=np.where(x > y, x, y), v_dot=(a * b).sum(1), v_length=np.linalg.norm(a, axis=1),
        v_cross=np.cross(a, b), v_normalize=a / np.linalg.norm(a, axis=1, keepdims=True),
        v_reflect=a - 2 * col((n * a).sum(1)) * n, v_mix=a + (b - a) * col(x), v_clamp=np.clip(a, 0, 0.5),
        v_step=(a >= b).astype(float), v_smooth=smooth(0.0, 1.0, a), v_select=np.where(col(x > 0), a, b),
        v_abs=np.abs(a), v_max=np.maximum(a, b), v_pow=np.abs(a) ** b,
        i_abs=np.abs(i), i_sign=np.sign(i), i_min=np.minimum(i, j), i_max=np.maximum(i, j),
        iv_max=np.maximum(np.stack([i, j, np.full_like(i, 3)], 1), j[:, None]))


def test_every_intrinsic_matches_numpy_in_float64(intr, rng):
    args = intrinsic_inputs(rng)
    got = intr["float64"]["intrinsics"](*args)
    want = intrinsic_reference(*args)
    assert set(want) == set(type(got)._fields)
    for name, w in want.items():
        g = getattr(got, name)
        assert g.shape == w.shape, name
        if name.startswith("i"):
            assert g.dtype == np.int32, name
            np.testing.assert_array_equal(g, w, err_msg=name)
        else:
            np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-14, err_msg=name)


@pytest.mark.parametrize("dtype", DTYPES)
def test_intrinsics_compute_in_the_working_dtype(intr, rng, dtype):
    got = intr[np.dtype(dtype).name]["intrinsics"](*intrinsic_inputs(rng, dtype))
    for name in type(got)._fields:
        want = np.int32 if name.startswith("i") else dtype
        assert getattr(got, name).dtype == want, name
    # float16 really computes in float16: 1000 * 1000 * x overflows to inf there, not in float32
    x = np.array([100.0, 0.01], dtype)
    out = intr[np.dtype(dtype).name]["overflow"](x)
    assert out.dtype == dtype
    if dtype is np.float16:
        assert np.isinf(out[0])
    else:
        np.testing.assert_allclose(out, [100.0, 0.01], rtol=1e-6)


def test_normalized_blinn_phong_matches_direct_formula(intr, rng):
    ndoth, n = rng.uniform(-0.2, 1.0, N), rng.uniform(1.0, 10000.0, N)
    f0 = rng.uniform(0.02, 0.1, (N, 3))
    got = intr["float64"]["blinn_phong"](ndoth, n, f0)
    want = f0 * ((n + 4.0) / (8.0 * np.pi))[:, None] * (np.maximum(ndoth, 0.0) ** n)[:, None]
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    for dtype in (np.float16, np.float32):
        fns = intr[np.dtype(dtype).name]
        assert fns["blinn_phong"](ndoth.astype(dtype), n.astype(dtype), f0.astype(dtype)).dtype == dtype


def test_division_by_zero_is_ieee(intr):
    got = intr["float32"]["divide"](np.float32([1, -1, 0]), np.float32([0, 0, 0]))
    assert got[0] == np.inf and got[1] == -np.inf and np.isnan(got[2])


def test_per_lane_indices_into_vectors_and_matrices(intr, rng):
    v, m = rng.normal(size=(N, 4)), rng.normal(size=(N, 4, 4))
    i = rng.integers(0, 4, N).astype(np.int32)
    m0, v0 = m.copy(), v.copy()
    got = intr["float64"]["lanes"](v, m, i)
    assert np.array_equal(m, m0) and np.array_equal(v, v0)
    lanes = np.arange(N)
    w = v.copy()
    w[lanes, i] = v[lanes, 3 - i] * 2.0
    c = m[lanes, :, i]
    m2 = m.copy()
    m2[lanes, :, i] = c * 3.0
    want = w + c + m2[lanes, :, i] * 0.5 + np.einsum("nij,nj->ni", m2, v)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def test_names_that_collide_with_the_runtime_are_renamed(intr):
    got = intr["float32"]["reserved_names"](np.float32([2.0]), np.ones((1, 3), np.float32))
    np.testing.assert_array_equal(got, [[2.0, 2.0, 2.0]])


# ---------------------------------------------------------------- emitted text

def test_line_map_points_at_brick_lines():
    _, emitted = emit("numpy_control.py")
    lines = emitted.text.splitlines()
    brick = (BRICKS / "numpy_control.py").read_text().splitlines()
    assert emitted.line_map == sorted(emitted.line_map)
    for gen_line, path, src_line in emitted.line_map:
        assert path.endswith("numpy_control.py")
        if lines[gen_line - 1].lstrip().startswith("def "):
            assert brick[src_line - 1].startswith("def ")
    (gl,) = [n for n, text in enumerate(lines, 1) if text.strip() == "_ret = _retu(_ret, _done, _m9, b, 0)"]
    (entry,) = [e for e in emitted.line_map if e[0] == gl]
    assert brick[entry[2] - 1].strip() == "return b"


def test_float_literals_are_created_in_the_working_dtype():
    _, emitted = emit("numpy_intrinsics.py")
    assert "F(8.0)" in emitted.text and "F(3.141592653589793)" in emitted.text
    assert "import" not in emitted.text and "np.pi" not in emitted.text


def test_textures_are_arrays_of_texels_sampled_bilinearly(tmp_path):
    text = '''"""Samples."""
BRICK = {"kind": "test"}


def passes(t: texture2d, x: float) -> float:
    return x * 2.0


def samples(t: texture2d, uv: vec2) -> vec4:
    return sample(t, uv)
'''
    module = parse_module(text, "tex.py")
    target = NumpyTarget()
    fns = target.load(target.emit([], list(module.functions.values())), np.float64)
    assert fns["passes"](None, np.array([1.5])).tolist() == [3.0]
    img = np.arange(16.0).reshape(2, 2, 4)
    np.testing.assert_array_equal(fns["samples"](img, np.array([[0.25, 0.25]])), [img[0, 0]])


# ---------------------------------------------------------------- corner cases

@pytest.fixture(scope="module")
def edge():
    target, emitted = emit("numpy_edge.py")
    return {np.dtype(d).name: target.load(emitted, d) for d in DTYPES}


def loop_return_ref(x):
    acc = 0.0
    for i in range(5):
        acc += x
        if acc > 2.0:
            return acc + i * 100.0
        if i == 3:
            acc = acc * 0.5
    if x < 0.0:
        return -1.0
    return acc if x < 0.25 else acc * 2.0


def test_return_inside_loop_inside_branch_and_all_paths_returning_if(edge, rng):
    x = rng.uniform(-1, 3, N)
    got = edge["float64"]["loop_return"](x)
    np.testing.assert_allclose(got, [loop_return_ref(v) for v in x], rtol=1e-15)
    assert edge["float64"]["first_iteration"](x).tolist() == x.tolist()


def test_constant_only_function_broadcasts(edge):
    got = edge["float32"]["constant"]()
    assert got.dtype == np.float32 and got.shape == (3,)
    np.testing.assert_allclose(got, np.float32(np.pi) * np.float32([0.25, 0.5, 1.0]))


def test_nested_struct_stores_under_nested_masks(edge, rng):
    fns = edge["float64"]
    v, k = rng.normal(size=(N, 3)), rng.normal(size=N)
    flag, x = rng.uniform(size=N) > 0.5, rng.normal(size=N)
    o = fns["Outer"](fns["Inner"](v, k), flag)
    v0 = v.copy()
    got = fns["nested_store"](o, x)
    assert np.array_equal(v, v0) and o.inner.v is v and o.flag is flag
    want_v = v.copy()
    want_v[x > 0, 1] = x[x > 0]
    np.testing.assert_array_equal(got.inner.v, want_v)
    np.testing.assert_array_equal(got.inner.k, np.where((x > 0) & flag, -x, k))
    np.testing.assert_array_equal(got.flag, ~flag)
    p, q = fns["Inner"](v, k), fns["Inner"](-v, -k)
    c = fns["choose_struct"](x, p, q)
    np.testing.assert_array_equal(c.v, np.where((x > 0)[:, None], v, -v))
    np.testing.assert_array_equal(c.k, np.where(x > 0, k, -k))


def test_matrix_scalar_and_matrix_matrix_arithmetic(edge, rng):
    m, s, v = rng.normal(size=(N, 3, 3)), rng.normal(size=N), rng.normal(size=(N, 3))
    got = edge["float64"]["matrices"](m, s, v)
    a = m * s[:, None, None] * 2 - m
    want = np.einsum("nij,nj->ni", a, -v) + np.einsum("nij,njk,nk->ni", m, m, v)
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-12)


def test_uint_arithmetic_wraps(edge):
    a, b = np.array([1, 10], np.uint32), np.array([3, 4], np.uint32)
    got = edge["float64"]["uints"](a, b)
    assert got.dtype == np.uint32
    assert got.tolist() == [((1 - 3) % 2**32) // 2 + 1, 6 // 2 + 2]


def test_arguments_are_converted_to_the_working_dtype(intr, control):
    got = intr["float16"]["blinn_phong"](0.9, [64.0, 8.0], [[0.04, 0.04, 0.04]])
    assert got.dtype == np.float16 and got.shape == (2, 3)
    want = intr["float16"]["blinn_phong"](np.float16(0.9), np.float16([64.0, 8.0]), np.full((1, 3), 0.04, np.float16))
    np.testing.assert_array_equal(got, want)
    fns = control["float32"]
    s = fns["Surface"]([[1.0, 2.0, 3.0]], [0.5], [2])
    assert fns["surface_sum"](s).dtype == np.float32 and fns["surface_sum"](s).tolist() == [8.5]
    with pytest.raises(TypeError, match="takes 2 arguments"):
        fns["classify"](1.0)
