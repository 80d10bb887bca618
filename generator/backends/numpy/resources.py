"""Runtime helpers of the numpy target for arrays, buffers and textures (injected like runtime.py's).

Arrays. A value of array[T, N] is T's representation with one more axis, of length N,
just before T's own trailing axes: array[float, N] is (..., N), array[vec4, N] is
(..., N, 4), array[mat3, N] is (..., N, 3, 3); an array of structs is an instance
of the struct class whose every field carries that axis ("a struct of arrays").
Leading axes are sample axes, as for every value. `k` below is the element's
rank descriptor (emit.py's _rank): 0, 1, 2 trailing axes or ((field, k), ...).

Buffers. A buffer is an array without sample axes: an object with the element
struct's fields (attribute access), each an array whose first axis is the element
index, e.g. a storage_buffer[Light] of M lights has `color` (M, 4). unpack_buffer()
builds one from the bytes the GPU buffer holds (types.buffer_layout_error's rule:
each leaf member is 4 consecutive 32-bit words).

Textures. A texture2d is an array (H, W, C) of texel values, a texturecube (6, H, W, C)
with faces in Vulkan order +X, -X, +Y, -Y, +Z, -Z; C ≤ 4 channels, missing ones read
as 0 (alpha 1), as Vulkan expands formats with fewer components. Sampling is fixed:
bilinear, clamp-to-edge addressing, texel centres at (i + 0.5) / W, mip level 0 only —
a Vulkan sampler with VK_FILTER_LINEAR (min and mag), VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
unnormalizedCoordinates off, on a one-level image (where implicit-LOD `sample` and
any `sample_level` lod read level 0 too); a list of arrays given for a 2D or cube texture is a mip chain,
which `sample_level` reads at its lod, linear between levels (`_lod`: mipmapMode LINEAR). Weights are exact (float64); a GPU may round
them to its sub-texel precision (Vulkan requires ≥ 4 bits, subTexelPrecisionBits), so
compare with a tolerance of that fraction of the texel differences. lavapipe filters
float formats in float32: on R32G32B32A32_SFLOAT it agrees to ~1e-6
(tests/lang/test_lang_ext_textures.py).
A texture2d_shadow is an array (H, W) (or (H, W, C), channel 0 read) of depths, read by
sample_compare(t, uv, ref) as a linear comparison sampler with compareOp LESS_OR_EQUAL reads a
depth image (Vulkan, "Depth Compare Operation" then "Texel Filtering"): each texel of the
bilinear 2×2 footprint is compared first (1 where ref <= D, else 0) and the four results are
weighted by the bilinear weights (percentage-closer filtering of Reeves et al. 1987 over 2×2
texels, what lavapipe does); ref is not clamped, as the D32_SFLOAT depth format asks.
A texture2d_array is an array (L, H, W, C) of L layers, a texturecube_array (L, 6, H, W, C), a
texture2d_array_shadow (L, H, W) (or (L, H, W, C)); their int layer is clamped to [0, L-1] per lane,
as Vulkan clamps its rounded layer coordinate and WGSL its array index (generator/lang/sampling.py),
and the layer is then sampled as a texture2d, texturecube or texture2d_shadow is.
Cube maps pick the face by the major axis (ties: X over Y over Z) and then
filter within that face, clamped to its edge; Vulkan filters seamlessly across
faces, so values within half a texel of a face edge differ from a GPU's.
"""
from __future__ import annotations

import copy

import numpy as np


def _clampi(i, n):
    return np.clip(np.asarray(i), 0, n - 1)


# ---------------------------------------------------------------- arrays

def _aidx(a, i, k):
    """a[i] for an array (or buffer) whose element has rank k; i uniform or per-lane, clamped into range."""
    if isinstance(k, tuple):
        out = copy.copy(a)
        for f, kf in k:
            setattr(out, f, _aidx(getattr(a, f), i, kf))
        return out
    a = np.asarray(a)
    ax = a.ndim - 1 - k
    n = a.shape[ax]
    i = _clampi(i, n)
    if i.ndim == 0:
        return a[(slice(None),) * ax + (int(i),)]
    lead = np.broadcast_shapes(a.shape[:ax], i.shape)
    ab = np.broadcast_to(a, lead + a.shape[ax:])
    ii = np.broadcast_to(i, lead).reshape(lead + (1,) * (k + 1)).astype(np.intp)
    return np.squeeze(np.take_along_axis(ab, ii, axis=len(lead)), axis=len(lead))


def _aset(a, i, v, k):
    """A copy of array a with element i replaced by v (i uniform or per-lane)."""
    if isinstance(k, tuple):
        out = copy.copy(a)
        for f, kf in k:
            setattr(out, f, _aset(getattr(a, f), i, getattr(v, f), kf))
        return out
    a, v = np.asarray(a), np.asarray(v)
    ax = a.ndim - 1 - k
    n = a.shape[ax]
    i = _clampi(i, n)
    if i.ndim == 0:
        lead = np.broadcast_shapes(a.shape[:ax], v.shape[:v.ndim - k])
        out = np.array(np.broadcast_to(a, lead + a.shape[ax:]))
        out[(Ellipsis, int(i)) + (slice(None),) * k] = v
        return out
    sel = (np.arange(n) == i[..., None]).reshape(i.shape + (n,) + (1,) * k)
    return np.where(sel, np.expand_dims(v, v.ndim - k), a)


def _arr(k, *elems):
    """An array value from its elements (the array axis goes before each element's trailing axes)."""
    if isinstance(k, tuple):
        out = copy.copy(elems[0])
        for f, kf in k:
            setattr(out, f, _arr(kf, *(getattr(e, f) for e in elems)))
        return out
    es = [np.asarray(e) for e in elems]
    lead = np.broadcast_shapes(*(e.shape[:e.ndim - k] for e in es))
    return np.stack([np.broadcast_to(e, lead + e.shape[e.ndim - k:]) for e in es], axis=len(lead))


def _blen(b):
    """buffer_length of a storage buffer: the length of its element axis."""
    while not isinstance(b, np.ndarray):
        b = getattr(b, b._fields[0]) if hasattr(b, "_fields") else getattr(b, b.__slots__[0])
    return np.uint32(b.shape[0])


# ---------------------------------------------------------------- textures

def _image(t, cube: bool):
    img = np.asarray(t, np.float64)
    want = 4 if cube else 3
    if img.ndim == want - 1:
        img = img[..., None]
    if img.ndim != want or img.shape[-1] > 4 or (cube and img.shape[0] != 6):
        shape = "(6, H, W, C)" if cube else "(H, W, C)"
        raise ValueError(f"a {'texturecube' if cube else 'texture2d'} is an array {shape} with C ≤ 4, "
                         f"got shape {np.shape(t)}")
    return _rgba(img)


def _rgba(img):
    """Texels (..., C) with C ≤ 4 as (..., 4): missing channels 0, alpha 1 (Vulkan's format expansion)."""
    c = img.shape[-1]
    if c < 4:
        pad = np.zeros(img.shape[:-1] + (4 - c,))
        pad[..., -1] = 1.0  # alpha
        img = np.concatenate([img, pad], axis=-1)
    return img


def _footprint(h, w, s, t):
    """The bilinear clamp-to-edge footprint at normalized (s, t) of an H × W image: texel columns i0, i1,
    rows j0, j1 and the weights ax, ay of i1 and j1."""
    x = np.nan_to_num(s * w - 0.5)
    y = np.nan_to_num(t * h - 0.5)
    x0, y0 = np.floor(x), np.floor(y)
    i0, i1 = np.clip(x0, 0, w - 1).astype(np.intp), np.clip(x0 + 1, 0, w - 1).astype(np.intp)
    j0, j1 = np.clip(y0, 0, h - 1).astype(np.intp), np.clip(y0 + 1, 0, h - 1).astype(np.intp)
    return i0, i1, j0, j1, x - x0, y - y0


def _bilinear(img, face, s, t):
    """Bilinear clamp-to-edge fetch at normalized (s, t) of img[face] ((F, H, W, 4), face int array)."""
    i0, i1, j0, j1, ax, ay = _footprint(img.shape[1], img.shape[2], s, t)
    ax, ay = ax[..., None], ay[..., None]
    return ((img[face, j0, i0] * (1 - ax) + img[face, j0, i1] * ax) * (1 - ay)
            + (img[face, j1, i0] * (1 - ax) + img[face, j1, i1] * ax) * ay)


def _tex2d(t, uv):
    """sample / sample_level of a texture2d at uv (level 0; see the module docstring)."""
    uv = np.asarray(uv)
    img = _image(t, cube=False)[None]
    c = uv.astype(np.float64)
    face = np.zeros(c.shape[:-1], np.intp)
    return _bilinear(img, face, c[..., 0], c[..., 1]).astype(uv.dtype)


def _tex2d_compare(t, uv, ref):
    """sample_compare of a texture2d_shadow: the bilinear weights of the 2×2 footprint applied to the four
    compares (ref <= depth), level 0, clamp-to-edge (see the module docstring)."""
    uv = np.asarray(uv)
    depth = _image(t, cube=False)[..., 0]  # (H, W): the depth channel
    c = uv.astype(np.float64)
    i0, i1, j0, j1, ax, ay = _footprint(depth.shape[0], depth.shape[1], c[..., 0], c[..., 1])
    r = np.asarray(ref, np.float64)

    def lit(j, i):
        return (r <= depth[j, i]).astype(np.float64)

    out = (lit(j0, i0) * (1 - ax) + lit(j0, i1) * ax) * (1 - ay) + (lit(j1, i0) * (1 - ax) + lit(j1, i1) * ax) * ay
    return out.astype(uv.dtype)


def _layers(t, per_layer: int, what: str, shape: str):
    """A texture array as (L · per_layer, H, W, 4) texels (per_layer: 6 for a cube array) and its L."""
    a = np.asarray(t, np.float64)
    want = 4 if per_layer == 1 else 5
    if a.ndim == want - 1 and what.endswith("_shadow"):
        a = a[..., None]
    if a.ndim != want or a.shape[0] < 1 or a.shape[-1] > 4 or (per_layer == 6 and a.shape[1] != 6):
        raise ValueError(f"a {what} is an array {shape} with L ≥ 1 and C ≤ 4, got shape {np.shape(t)}")
    return _rgba(a.reshape((-1,) + a.shape[-3:])), a.shape[0]


def _layer_index(layer, n, shape):
    """The layer of each lane, clamped to [0, n - 1], broadcast to the coordinate's sample axes."""
    return np.broadcast_to(np.clip(np.asarray(layer).astype(np.int64), 0, n - 1), shape).astype(np.intp)


def _tex2d_array(t, uv, layer):
    """sample / sample_level of a texture2d_array (L, H, W, C) at uv in layer `layer` (clamped; level 0)."""
    uv = np.asarray(uv)
    img, n = _layers(t, 1, "texture2d_array", "(L, H, W, C)")
    c = uv.astype(np.float64)
    return _bilinear(img, _layer_index(layer, n, c.shape[:-1]), c[..., 0], c[..., 1]).astype(uv.dtype)


def _texcube_array(t, d, layer):
    """sample / sample_level of a texturecube_array (L, 6, H, W, C) in direction d, layer `layer` (clamped)."""
    d = np.asarray(d)
    img, n = _layers(t, 6, "texturecube_array", "(L, 6, H, W, C)")
    face, s, tt = cube_face(d)
    return _bilinear(img, 6 * _layer_index(layer, n, face.shape) + face.astype(np.intp), s, tt).astype(d.dtype)


def _tex2d_array_compare(t, uv, layer, ref):
    """sample_compare of a texture2d_array_shadow (L, H, W): _tex2d_compare in layer `layer` (clamped)."""
    uv = np.asarray(uv)
    img, n = _layers(t, 1, "texture2d_array_shadow", "(L, H, W)")
    depth = img[..., 0]
    c = uv.astype(np.float64)
    k = _layer_index(layer, n, c.shape[:-1])
    i0, i1, j0, j1, ax, ay = _footprint(depth.shape[1], depth.shape[2], c[..., 0], c[..., 1])
    r = np.asarray(ref, np.float64)

    def lit(j, i):
        return (r <= depth[k, j, i]).astype(np.float64)

    out = (lit(j0, i0) * (1 - ax) + lit(j0, i1) * ax) * (1 - ay) + (lit(j1, i0) * (1 - ax) + lit(j1, i1) * ax) * ay
    return out.astype(uv.dtype)


def cube_face(d) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(face, s, t) of directions d (..., 3), float64: Vulkan "Cube Map Face Selection" (the major axis,
    ties to X over Y over Z; faces +X, -X, +Y, -Y, +Z, -Z) and the face's normalized coordinates
    s = (s_c / |m_a| + 1) / 2, t = (t_c / |m_a| + 1) / 2. Shared by _texcube and the homomorphic
    factorization's cube maps (generator/reference/tables_homomorphic.py)."""
    r = np.asarray(d, np.float64)
    rx, ry, rz = r[..., 0], r[..., 1], r[..., 2]
    ax, ay, az = np.abs(rx), np.abs(ry), np.abs(rz)
    use_x = (ax >= ay) & (ax >= az)
    use_y = ~use_x & (ay >= az)
    face = np.where(use_x, np.where(rx >= 0, 0, 1), np.where(use_y, np.where(ry >= 0, 2, 3), np.where(rz >= 0, 4, 5)))
    # Vulkan "Cube Map Face Selection": (sc, tc, ma) per face
    sc = np.choose(face, [-rz, rz, rx, rx, rx, -rx])
    tc = np.choose(face, [-ry, -ry, rz, -rz, -ry, -ry])
    ma = np.choose(face, [ax, ax, ay, ay, az, az])
    return face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0)


def cube_texel_direction(face, i, j, size: int) -> np.ndarray:
    """Unit direction (..., 3) through the centre of texel (face, i, j) (column i, row j) of an S × S cube:
    the inverse of cube_face there (s = (i + 0.5) / S, t = (j + 0.5) / S). i and j may be fractional or
    past the face's edge (i = S is one texel step beyond it: a direction onto the adjacent face)."""
    sc = (np.asarray(i, np.float64) + 0.5) / size * 2.0 - 1.0
    tc = (np.asarray(j, np.float64) + 0.5) / size * 2.0 - 1.0
    face, sc, tc = np.broadcast_arrays(np.asarray(face), sc, tc)
    one = np.ones_like(sc)
    # the (s_c, t_c, m_a) table of cube_face solved for (rx, ry, rz) at |m_a| = 1, per face
    d = np.stack([np.choose(face, [one, -one, sc, sc, sc, -sc]),
                  np.choose(face, [-tc, -tc, one, -one, -tc, -tc]),
                  np.choose(face, [-sc, sc, tc, -tc, one, -one])], -1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _texcube(t, d):
    """sample / sample_level of a texturecube in direction d (Vulkan face selection, level 0)."""
    d = np.asarray(d)
    img = _image(t, cube=True)
    face, s, tt = cube_face(d)
    return _bilinear(img, face.astype(np.intp), s, tt).astype(d.dtype)


def _lod(fetch, t, c, lod):
    """sample_level of a 2D or cube texture: an array is one level (read there whatever the lod); a list or tuple
    of arrays is a mip chain, level 0 first, read at `lod` clamped to [0, levels − 1], linear between the two
    levels around it and bilinear within each (a Vulkan sampler with mipmapMode LINEAR and maxLod ≥ levels − 1:
    d = floor(lod), (1 − frac) · level d + frac · level d + 1)."""
    if not isinstance(t, (list, tuple)):
        return fetch(t, c)
    c = np.asarray(c)
    lod = np.clip(np.nan_to_num(np.asarray(lod, np.float64)), 0.0, len(t) - 1.0)
    k0 = np.floor(lod)
    f = (lod - k0)[..., None]
    k1 = np.minimum(k0 + 1.0, len(t) - 1.0)
    out = None
    for k, level in enumerate(t):
        v = np.asarray(fetch(level, c), np.float64)
        w = np.where((k0 == k)[..., None], 1.0 - f, 0.0) + np.where((k1 == k)[..., None], f, 0.0)
        out = v * w if out is None else out + v * w
    return out.astype(c.dtype)


# ---------------------------------------------------------------- buffers from GPU bytes

def value_rank(t):
    """The rank descriptor of a type's NumPy value: trailing axes (0, 1, 2, +1 per array) or ((field, k), ...)."""
    if t.kind == "struct":
        return tuple((f, value_rank(ft)) for f, ft in t.fields)
    if t.kind == "array":
        inner = value_rank(t.elem)
        return _plus(inner)
    return {"vector": 1, "matrix": 2}.get(t.kind, 0)


def _plus(k):
    return tuple((f, _plus(kf)) for f, kf in k) if isinstance(k, tuple) else k + 1


def unpack_buffer(elem, data, struct_class):
    """A buffer value (struct of arrays, leading axis = element) from the bytes of its GPU buffer.

    elem: the element struct Type (buffer_layout_error holds); data: anything whose bytes
    are the buffer (a NumPy array of any dtype, bytes); struct_class(name, fields) builds
    the attribute holders (runtime._struct). Floats stay float32 (the loader
    converts them to the working dtype).
    """
    raw = bytes(data) if isinstance(data, (bytes, bytearray, memoryview)) else np.ascontiguousarray(data).tobytes()
    words = np.frombuffer(raw, np.uint32)
    per = elem.components
    if words.size % per:
        raise ValueError(f"{words.size} words is not a whole number of {elem} elements ({per} words each)")
    rows = words.reshape(-1, per)
    dtypes = {"float": np.float32, "int": np.int32, "uint": np.uint32}

    def build(t, start):
        """The value of type t whose first word is column `start` of rows, and the next column."""
        if t.kind == "struct":
            values = []
            for _, ft in t.fields:
                v, start = build(ft, start)
                values.append(v)
            return struct_class(t.name, tuple(f for f, _ in t.fields))(*values), start
        if t.kind == "array":
            parts = []
            for _ in range(t.size):
                p, start = build(t.elem, start)
                parts.append(p)
            return _arr(value_rank(t.elem), *parts), start
        return rows[:, start:start + 4].view(dtypes[t.scalar]), start + 4

    value, _ = build(elem, 0)
    return value


RESOURCE_RUNTIME = {n: v for n, v in dict(globals()).items()
                    if n.startswith("_") and not n.startswith("__") and callable(v)}
