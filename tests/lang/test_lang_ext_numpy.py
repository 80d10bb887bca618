"""The NumPy target runs switches, runtime loops, arrays, buffers and texture sampling lane-exact."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from generator.lang import parse_module
from generator.backends.numpy.emit import NumpyTarget

BRICKS = Path(__file__).parents[1] / "bricks" / "lang"
N = 301
T = NumpyTarget()


def load(name, dtype=np.float64, resources=None):
    path = BRICKS / name
    m = parse_module(path.read_text(), str(path))
    return m, T.load(T.emit(list(m.structs.values()), list(m.functions.values()), list(m.globals.values())),
                     dtype, resources)


@pytest.fixture(scope="module")
def ext():
    return load("ext_constructs.py")


@pytest.fixture(scope="module")
def edge():
    return load("ext_numpy.py")[1]


@pytest.fixture
def rng():
    return np.random.default_rng(7)


@pytest.fixture(autouse=True)
def no_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


# ---------------------------------------------------------------- switch

def classify_ref(k, x):
    y = x
    if k == 0:
        y = x * 2.0
    elif k in (1, 2):
        return x + 10.0
    elif k == -3:
        y = -x
        if x > 0.0:
            return 100.0
    else:
        y = x - 1.0
    return y


def test_switch_with_alternatives_negative_cases_default_and_returns(ext, rng):
    k = rng.integers(-4, 5, N).astype(np.int32)
    x = rng.uniform(-1, 1, N)
    got = ext[1]["classify"](k, x)
    np.testing.assert_array_equal(got, [classify_ref(a, b) for a, b in zip(k.tolist(), x.tolist())])
    assert set(k.tolist()) >= {-3, 0, 1, 2, 4}


def test_uint_switch_ending_a_function_and_switch_without_default(ext):
    fns = ext[1]
    assert fns["pick"](np.uint32([0, 7, 9, 3, 4294967295])).tolist() == [1.0, 2.0, 2.0, 3.0, 3.0]
    assert fns["no_default"](np.int32([1, 2, 0])).tolist() == [4.0, 0.5, 0.5]


# ---------------------------------------------------------------- loops and arrays

def test_runtime_loop_over_an_array_of_structs(ext, rng):
    fns = ext[1]
    c, k = rng.uniform(0, 1, (N, 4, 4)), rng.uniform(0.5, 4, (N, 4, 4))
    n, cos_t = rng.integers(-1, 5, N).astype(np.int32), rng.uniform(-0.2, 1, N)
    got = fns["sum_lobes"](fns["Lobe"](c, k), n, cos_t)
    want = np.zeros((N, 3))
    for s in range(N):
        for i in range(max(n[s], 0)):
            want[s] += c[s, i, :3] * max(cos_t[s], 0.0) ** k[s, i, 0]
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-15)
    # lobes shared by every lane: the array axis is the only one
    shared = fns["sum_lobes"](fns["Lobe"](c[0], k[0]), n, cos_t)
    want0 = [sum(c[0, i, :3] * max(ct, 0.0) ** k[0, i, 0] for i in range(max(m, 0))) + np.zeros(3)
             for m, ct in zip(n, cos_t)]
    np.testing.assert_allclose(shared, want0, rtol=1e-13, atol=1e-15)


def test_uint_loop_with_a_local_array_literal_and_element_writes(ext, rng):
    m, x = rng.integers(0, 9, N).astype(np.uint32), rng.uniform(-2, 2, N)

    def ref(m, x):
        w, acc = [x, 2.0 * x, 0.5], 0.0
        for i in range(m):
            w[i % 3] += 1.0
            acc += w[i % 3]
        return acc + w[0] + w[2]

    np.testing.assert_allclose(ext[1]["weights"](m, x), [ref(a, b) for a, b in zip(m.tolist(), x.tolist())],
                               rtol=1e-15)


def test_masked_element_writes_with_per_lane_indices(edge, rng):
    x, k = rng.uniform(-1, 1, N), rng.integers(0, 3, N).astype(np.int32)

    def ref(x, k):
        a = [[x, 0.0], [1.0, x], [-x, 2.0]]
        if x > 0.0:
            a[k][1] = 10.0 * x
            a[2] = [a[k][0], 7.0]
        return np.array(a[0]) + np.array(a[1]) * 2.0 + np.array(a[2]) * 3.0

    np.testing.assert_allclose(edge["masked_writes"](x, k), [ref(a, b) for a, b in zip(x.tolist(), k.tolist())],
                               rtol=1e-15)


def test_return_inside_a_runtime_loop_and_nested_loops_with_a_switch(edge, rng):
    vals, n, lim = rng.uniform(0, 1, (N, 4)), rng.integers(0, 5, N).astype(np.int32), rng.uniform(0, 1, N)
    want = [next((i for i in range(m) if v[i] > li), -1) for v, m, li in zip(vals, n, lim)]
    got = edge["first_over"](vals, n, lim)
    assert got.dtype == np.int32 and got.tolist() == want
    ni, mi = rng.integers(0, 6, N).astype(np.int32), rng.integers(0, 4, N).astype(np.uint32)

    def nested(n, m):
        acc = 0.0
        for i in range(n):
            for j in range(m):
                acc += 1.0 if i == 0 else float(j) if i in (1, 3) else -0.5
        return acc

    np.testing.assert_array_equal(edge["nested"](ni, mi), [nested(a, b) for a, b in zip(ni.tolist(), mi.tolist())])
    assert edge["nested"](np.int32(0), np.uint32(3)).tolist() == 0.0  # no lane iterates


def test_struct_with_an_array_field(edge, rng):
    w, n = rng.normal(size=(N, 3, 2)), rng.integers(0, 4, N).astype(np.int32)
    got = edge["bag_sum"](edge["Bag"](w, n))
    np.testing.assert_allclose(got, [w[s, :n[s]].sum(0) for s in range(N)], rtol=1e-14, atol=1e-15)
    b = edge["make_bag"](np.array([1.0, -2.0]))
    assert b.w.shape == (2, 3, 2) and b.n.tolist() == 2
    np.testing.assert_array_equal(edge["bag_sum"](b), [[3.0, 3.0], [-6.0, -6.0]])


@pytest.mark.parametrize("dtype", [np.float16, np.float32])
def test_new_constructs_keep_the_working_dtype(dtype, rng):
    _, fns = load("ext_constructs.py", dtype)
    x = rng.uniform(-1, 1, 16).astype(dtype)
    assert fns["classify"](np.int32(np.arange(16) % 5 - 3), x).dtype == dtype
    assert fns["weights"](np.uint32(np.arange(16)), x).dtype == dtype
    lobes = fns["Lobe"](np.ones((4, 4)), np.ones((4, 4)))
    assert fns["sum_lobes"](lobes, np.int32(np.arange(16) % 5), x).dtype == dtype


# ---------------------------------------------------------------- buffers

def light_words(rng, m):
    words = np.zeros((m, 12), np.float32)
    words[:, 0:8] = rng.uniform(0.1, 1, (m, 8))
    words[:, 8:12].view(np.int32)[:] = rng.integers(0, 3, (m, 4))
    return words


def test_buffers_from_gpu_bytes_and_their_length(rng):
    m, _ = load("ext_constructs.py")
    words = light_words(rng, 6)
    lights = T.unpack_buffer(m.structs["Light"], words)
    assert lights.color.shape == (6, 4) and lights.kind.dtype == np.int32
    np.testing.assert_array_equal(lights.kind, words[:, 8:12].view(np.int32))
    table_words = np.arange(8 * 16, dtype=np.float32)
    table = T.unpack_buffer(m.structs["Table"], table_words.tobytes())
    assert table.lobe.C.shape == (8, 4) and table.taps.shape == (8, 2, 4)
    np.testing.assert_array_equal(table.taps[3, 1], table_words[3 * 16 + 12:3 * 16 + 16])
    _, fns = load("ext_constructs.py", resources={"lights": lights, "table": table})
    p = rng.normal(size=(N, 3))
    want = np.zeros((N, 3))
    for i in range(6):
        if words[i, 8:12].view(np.int32)[0] == 1:
            d = words[i, 4:7] - p
            want += words[i, :3] / np.maximum((d * d).sum(1), 1e-4)[:, None]
        else:
            want += words[i, :3]
    np.testing.assert_allclose(fns["shade_lights"](p), want, rtol=1e-12)
    j = rng.integers(0, 8, N).astype(np.int32)
    rows = table_words.reshape(8, 16)
    np.testing.assert_array_equal(fns["read_table"](j), rows[j, 0:4] + rows[j, 12:16] + rows[0, 8:12] * 8.0)
    with pytest.raises(ValueError, match="whole number"):
        T.unpack_buffer(m.structs["Light"], np.zeros(13, np.float32))


def test_buffers_as_dicts_and_a_missing_buffer(rng):
    _, fns = load("ext_constructs.py", resources={"lights": {
        "color": [[1.0, 2.0, 3.0, 0.0]] * 3, "position": np.zeros((3, 4)), "kind": np.zeros((3, 4), np.int32)}})
    np.testing.assert_array_equal(fns["shade_lights"](np.zeros((2, 3))), [[3.0, 6.0, 9.0]] * 2)
    with pytest.raises(LookupError, match="uniform_buffer\\[Table, 8\\] 'table'.*resources="):
        fns["read_table"](np.int32([0]))


# ---------------------------------------------------------------- textures

def bilinear_ref(img, u, v):
    """Vulkan's linear filter with clamp-to-edge, written per sample."""
    h, w = img.shape[:2]
    x, y = u * w - 0.5, v * h - 0.5
    i0, j0 = int(np.floor(x)), int(np.floor(y))
    a, b = x - i0, y - j0

    def texel(i, j):
        return img[min(max(j, 0), h - 1), min(max(i, 0), w - 1)]

    return ((1 - a) * (1 - b) * texel(i0, j0) + a * (1 - b) * texel(i0 + 1, j0)
            + (1 - a) * b * texel(i0, j0 + 1) + a * b * texel(i0 + 1, j0 + 1))


def test_texture2d_sampling_is_bilinear_clamp_to_edge_at_texel_centres(edge, rng):
    img = rng.uniform(0, 1, (5, 7, 4))
    uv = rng.uniform(-0.3, 1.3, (N, 2))
    got = edge["sampled"](img, uv, rng.uniform(0, 4, N))
    np.testing.assert_allclose(got, [bilinear_ref(img, u, v) for u, v in uv], rtol=1e-13, atol=1e-15)
    j, i = np.meshgrid(np.arange(5), np.arange(7), indexing="ij")
    centres = np.stack([(i.ravel() + 0.5) / 7, (j.ravel() + 0.5) / 5], axis=1)
    np.testing.assert_allclose(edge["sampled"](img, centres, 0.0), img.reshape(-1, 4), rtol=1e-14)
    # fewer channels read as (r, 0, 0, 1), as Vulkan expands an R format
    one = edge["sampled"](img[..., 0], centres, 0.0)
    np.testing.assert_allclose(one, np.stack([img[..., 0].ravel(), 0 * one[:, 0], 0 * one[:, 0],
                                              1 + 0 * one[:, 0]], 1), rtol=1e-14)
    assert load("ext_numpy.py", np.float32)[1]["sampled"](img, uv, 0.0).dtype == np.float32
    with pytest.raises(ValueError, match="texture2d is an array"):
        edge["sampled"](np.zeros((2, 2, 2, 4)), uv, 0.0)


def test_cube_sampling_picks_the_vulkan_face_and_texel(edge):
    h = w = 4
    cube = np.zeros((6, h, w, 4))
    for f in range(6):
        for j in range(h):
            for i in range(w):
                cube[f, j, i] = [f, i, j, 1.0]
    # Vulkan cube face selection: direction = ma-axis ± 1 with (sc, tc) in [-1, 1]
    sc_tc = {0: lambda s, t: (1.0, -t, -s), 1: lambda s, t: (-1.0, -t, s), 2: lambda s, t: (s, 1.0, t),
             3: lambda s, t: (s, -1.0, -t), 4: lambda s, t: (s, -t, 1.0), 5: lambda s, t: (-s, -t, -1.0)}
    dirs, want = [], []
    for f, make in sc_tc.items():
        for j in range(h):
            for i in range(w):
                s, t = 2 * (i + 0.5) / w - 1, 2 * (j + 0.5) / h - 1
                dirs.append(np.array(make(s, t)) * 3.0)  # any length
                want.append([f, i, j, 1.0])
    np.testing.assert_allclose(edge["env"](cube, np.array(dirs)), want, atol=1e-12)
    with pytest.raises(ValueError, match="texturecube is an array"):
        edge["env"](np.zeros((5, 2, 2, 4)), np.array(dirs))
