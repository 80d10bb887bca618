"""Runtime helpers of the numpy target, injected into the namespace of emitted code by load().

Values: a scalar is (N,) or 0-d, a vecK (..., K), a matK (..., K, K) with m[..., :, j] column j.
No helper mutates its inputs: component and field stores build new arrays and objects.
"""
from __future__ import annotations

import copy

import numpy as np

def _range(n, dtype=np.int32):
    return (dtype(i) for i in range(n))


def _bmax(b):
    """The iteration count of a loop with per-lane bound b: its largest value (0 if none is positive)."""
    b = np.asarray(b)
    return max(int(b.max()), 0) if b.size else 0


def _expand(x, k):
    x = np.asarray(x)
    return x.reshape(x.shape + (1,) * k) if k else x


def _sel(m, a, b, k):
    """where(m, a, b) for a value of rank k (0 scalar, 1 vector, 2 matrix) or struct ((field, k), ...)."""
    if isinstance(k, tuple):
        out = copy.copy(b)
        for f, kf in k:
            setattr(out, f, _sel(m, getattr(a, f), getattr(b, f), kf))
        return out
    return np.where(_expand(m, k), a, b)


def _retu(ret, done, m, val, k):
    """Record `val` as the return value of the lanes in m that have not returned yet."""
    if ret is None:
        return val
    return _sel(np.asarray(m) & ~np.asarray(done), val, ret, k)


def _fin(done, ret, val, k):
    return val if ret is None else _sel(done, ret, val, k)


def _cvt(x, dtype):
    x = np.asarray(x)
    return x != 0 if dtype is np.bool_ else x.astype(dtype)


def _splat(s, n):
    return np.repeat(np.asarray(s)[..., None], n, axis=-1)


def _vec(ranks, *parts):
    parts = [np.asarray(p)[..., None] if r == 0 else np.asarray(p) for r, p in zip(ranks, parts)]
    lead = np.broadcast_shapes(*(p.shape[:-1] for p in parts))
    return np.concatenate([np.broadcast_to(p, lead + p.shape[-1:]) for p in parts], axis=-1)


def _mat(*cols):
    cols = np.broadcast_arrays(*cols)
    return np.stack(cols, axis=-1)


def _clampi(i, n):
    return np.clip(np.asarray(i), 0, n - 1)


def _idx(v, i):
    """v[i] for a vector with a uniform or per-lane int index (clamped into range, like WGSL)."""
    v = np.asarray(v)
    n = v.shape[-1]
    i = _clampi(i, n)
    if i.ndim == 0:
        return v[..., int(i)]
    lead = np.broadcast_shapes(v.shape[:-1], i.shape)
    vb = np.broadcast_to(v, lead + (n,))
    return np.take_along_axis(vb, np.broadcast_to(i, lead)[..., None].astype(np.intp), -1)[..., 0]


def _col(m, i):
    """Column i of a matrix (m[i] in the brick language), i uniform or per-lane."""
    m = np.asarray(m)
    n = m.shape[-1]
    i = _clampi(i, n)
    if i.ndim == 0:
        return m[..., :, int(i)]
    mt = np.swapaxes(m, -1, -2)  # rows of mt are the columns of m
    lead = np.broadcast_shapes(mt.shape[:-2], i.shape)
    mb = np.broadcast_to(mt, lead + (n, n))
    return np.take_along_axis(mb, np.broadcast_to(i, lead)[..., None, None].astype(np.intp), -2)[..., 0, :]


def _setc(v, i, val):
    """A copy of vector v with component i replaced (i uniform or per-lane)."""
    v, val = np.asarray(v), np.asarray(val)
    n = v.shape[-1]
    i = _clampi(i, n)
    if i.ndim == 0:
        lead = np.broadcast_shapes(v.shape[:-1], val.shape)
        out = np.array(np.broadcast_to(v, lead + (n,)))
        out[..., int(i)] = val
        return out
    return np.where(np.arange(n) == i[..., None], val[..., None], v)


def _setcol(m, i, col):
    """A copy of matrix m with column i replaced."""
    mt = np.swapaxes(np.asarray(m), -1, -2)
    if np.ndim(i) == 0:
        n = mt.shape[-1]
        lead = np.broadcast_shapes(mt.shape[:-2], np.shape(col)[:-1])
        out = np.array(np.broadcast_to(mt, lead + (n, n)))
        out[..., int(_clampi(i, n)), :] = col
    else:
        sel = np.arange(mt.shape[-1]) == _clampi(i, mt.shape[-1])[..., None]
        out = np.where(sel[..., None], np.asarray(col)[..., None, :], mt)
    return np.swapaxes(out, -1, -2)


def _setf(s, name, val):
    out = copy.copy(s)
    setattr(out, name, val)
    return out


def _idiv(a, b):
    """Integer division truncating toward zero (GLSL/HLSL/WGSL), not Python's floor division."""
    q = a // b
    return np.where(((a % b) != 0) & ((a < 0) != (b < 0)), q + 1, q)


def _dot(a, b):
    s = a[..., 0] * b[..., 0]
    for k in range(1, np.shape(a)[-1]):
        s = s + a[..., k] * b[..., k]
    return s


def _length(v):
    return np.sqrt(_dot(v, v))


def _normalize(v):
    return v / _length(v)[..., None]


def _reflect(i, n):
    d = _dot(n, i)
    return i - d.dtype.type(2) * d[..., None] * n


def _fract(x):
    return x - np.floor(x)


def _mix(a, b, t):
    return a + (b - a) * t


def _clamp(x, lo, hi):
    return np.fmin(np.fmax(x, lo), hi)


def _smoothstep(e0, e1, x):
    t = (x - e0) / (e1 - e0)
    one = np.asarray(t).dtype.type(1)
    t = _clamp(t, one - one, one)
    return t * t * (one + one + one - (one + one) * t)


def _mv(m, v):
    """M * v with M columns m[..., :, j]."""
    r = m[..., :, 0] * v[..., 0:1]
    for j in range(1, np.shape(m)[-1]):
        r = r + m[..., :, j] * v[..., j:j + 1]
    return r


def _vm(v, m):
    """v * M (row vector): result_j = dot(v, column j)."""
    r = v[..., 0:1] * m[..., 0, :]
    for i in range(1, np.shape(m)[-1]):
        r = r + v[..., i:i + 1] * m[..., i, :]
    return r


def _mm(a, b):
    return np.stack([_mv(a, b[..., :, j]) for j in range(np.shape(b)[-1])], axis=-1)


def _coerce(a, spec, f):
    """A caller's argument in the brick's types: floats in the working dtype f, int32, uint32, bool."""
    if spec is None:
        return a
    if isinstance(spec, tuple):
        out = copy.copy(a)
        for name, s in spec:
            setattr(out, name, _coerce(getattr(a, name), s, f))
        return out
    return np.asarray(a, {"float": f, "int": np.int32, "uint": np.uint32, "bool": np.bool_}[spec])


def _struct(name, fields):
    def __init__(self, *args):
        if len(args) != len(fields):
            raise TypeError(f"{name}() takes {len(fields)} fields ({', '.join(fields)}), got {len(args)}")
        for f, a in zip(fields, args):
            setattr(self, f, a)

    def __repr__(self):
        return f"{name}(" + ", ".join(f"{f}={getattr(self, f)!r}" for f in fields) + ")"

    return type(name, (), {"__slots__": tuple(fields), "__init__": __init__, "__repr__": __repr__,
                           "_fields": tuple(fields)})


RUNTIME = {n: v for n, v in dict(globals()).items()
           if n.startswith("_") and not n.startswith("__") and callable(v)}
