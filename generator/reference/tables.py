"""Lookup tables baked from the float64 references: the registry a brick's `"table"` texture names.

Hoffman & Baker 2006 ("Implementation Tradeoffs for Analytical BRDFs with Point Lights"): a BRDF can
be evaluated with ALU, or "factor[ed] into textures, use[d] as lookup table", or a mix. A brick that
samples a table declares it on the texture, with the size and format chosen by measured error:

    "textures": {"bp_pow": {"table": "blinn_phong_pow", "size": [256, 64], "format": "fp16",
                            "doc": "..."}}

and the generator bakes the texels here, from the reference, wherever the brick runs: eval kernels
and NumPy (accuracy), the renderer, and the build (the table is an artifact beside the shaders, with
its sha256, the reference it came from and its measured error). Bricks are parsed, never executed, so
the baking code lives in the generator and the brick only names it.

Conventions every table follows (so a brick can index it with one multiply-add):
- A table of W texels along an axis samples its coordinate x ∈ [0, 1] at the texel *centres*
  x_i = i / (W − 1) (`axis(W)`): the end points are exact. A brick reads it at
  u = x · (W − 1)/W + 0.5/W (`texel_coordinate`), which filters linearly between the baked samples and
  never reaches the clamp (or wrap) region, so the sampler's address mode does not matter.
- Texels are (H, W, 4) float64 from the baker (RGBA; unused channels 0, alpha 1), or (6, S, S, 4) for
  a cube map (faces +X, −X, +Y, −Y, +Z, −Z); `quantize` rounds them to the declared format:
  `unorm8` (values in [0, 1]), `fp16`, `fp32`.
- A baker may take a source image (a hand-painted table): bake(W, H, image=None); image is
  float64 (h, w, 4) in [0, 1] and the baker resamples and normalizes it.
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

FORMATS = {"unorm8": np.uint8, "fp16": np.float16, "fp32": np.float32}
FORMAT_NAMES = tuple(FORMATS)


@dataclass(frozen=True)
class TableDef:
    """One bakeable table: its baker, what it is baked from, and (for its error) the exact function."""

    name: str
    bake: Callable  # bake(W, H, image=None) -> float64 (H, W, 4), or (6, S, S, 4) for a cube
    reference: str  # what the texels are computed from (function, paper, equation)
    doc: str = ""
    cube: bool = False
    # exact(x, y) -> (..., 4) float64 at table coordinates x, y in [0, 1] (for 2D tables): what the
    # filtered table approximates; table_error() measures it between the texel centres. None: the table
    # is its own definition (a painted one), or its error is measured on the BRDF (accuracy).
    exact: Callable | None = None
    painted: bool = False  # takes a source image
    extra: dict = field(default_factory=dict)
    sources: tuple = ()  # files the baker reads beyond the generator's code (a painted example): see inputs()


TABLES: dict[str, TableDef] = {}


class TableError(LookupError):
    """A brick names a table the generator does not bake."""


def table(name: str, reference: str, *, cube: bool = False, exact: Callable | None = None,
          painted: bool = False, doc: str = "", sources: tuple = ()):
    """Register the baker of table `name` (a decorator)."""
    def register(fn):
        if name in TABLES:
            raise ValueError(f"two bakers for table '{name}'")
        TABLES[name] = TableDef(name, fn, reference, doc or (fn.__doc__ or "").strip().split("\n")[0], cube, exact,
                                painted, sources=tuple(sources))
        return fn
    return register


def inputs(name: str) -> str:
    """sha256 of the files table `name`'s baker reads beyond the generator's code (its declared sources);
    with the generator's own sources, what its texels depend on (the build's key for reusing them)."""
    h = hashlib.sha256()
    for path in lookup(name).sources:
        h.update(Path(path).read_bytes() + b"\0")
    return h.hexdigest()


def lookup(name: str) -> TableDef:
    """The table `name`; TableError (with the closest name) when there is none."""
    _load()
    if name not in TABLES:
        import difflib
        near = difflib.get_close_matches(name, sorted(TABLES), n=1)
        raise TableError(f"no table '{name}' is baked by the generator"
                         + (f" — did you mean '{near[0]}'?" if near else f" — tables: {', '.join(sorted(TABLES))}"))
    return TABLES[name]


def axis(n: int) -> np.ndarray:
    """The coordinates x_i = i / (n − 1) of an axis of n texels (texel centres; a 1-texel axis: 0)."""
    return np.linspace(0.0, 1.0, n) if n > 1 else np.zeros(1)


def texel_coordinate(x, n: int):
    """The texture coordinate of table coordinate x on an axis of n texels: x (n − 1)/n + 0.5/n."""
    return np.asarray(x, np.float64) * ((n - 1) / n) + 0.5 / n


def rgba(*channels, shape=None) -> np.ndarray:
    """Stack up to four channels into (..., 4), unused ones 0 and alpha 1."""
    chans = [np.asarray(c, np.float64) for c in channels]
    shape = shape or np.broadcast_shapes(*(c.shape for c in chans))
    out = np.zeros((*shape, 4))
    out[..., 3] = 1.0
    for i, c in enumerate(chans):
        out[..., i] = c
    return out


def quantize(texels: np.ndarray, fmt: str) -> np.ndarray:
    """The texels as stored in format `fmt`: uint8 (rounded, [0, 1] clipped), float16 or float32."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown table format {fmt!r}: use one of {', '.join(FORMAT_NAMES)}")
    a = np.asarray(texels, np.float64)
    if fmt == "unorm8":
        return np.round(np.clip(a, 0.0, 1.0) * 255.0).astype(np.uint8)
    if fmt == "fp16":
        if np.nanmax(np.abs(a), initial=0.0) > 65504.0:
            raise ValueError("a texel exceeds float16's 65504: bake it scaled or use fp32")
        return a.astype(np.float16)
    return a.astype(np.float32)


def decoded(stored: np.ndarray) -> np.ndarray:
    """Stored texels as the sampler returns them (float64): unorm8 normalized, floats as they are."""
    a = np.asarray(stored)
    return a.astype(np.float64) / 255.0 if a.dtype == np.uint8 else a.astype(np.float64)


_BAKED: dict[tuple, np.ndarray] = {}


def baked(name: str, size, fmt: str, image: np.ndarray | None = None) -> np.ndarray:
    """The stored texels of table `name` at size (W, H) in format `fmt` (cached, read-only)."""
    d = lookup(name)
    w, h = (int(size[0]), int(size[1]) if len(size) > 1 else 1)
    # an image is keyed by its shape and dtype too: its bytes alone are the same for a 1 × 8 and a 2 × 4 image
    key = (name, w, h, fmt, None if image is None else
           (np.shape(image), str(np.asarray(image).dtype), hashlib.sha256(np.ascontiguousarray(image)).hexdigest()))
    if key not in _BAKED:
        t = d.bake(w, h, image) if d.painted else d.bake(w, h)
        want = (6, h, w, 4) if d.cube else (h, w, 4)
        if t.shape != want:
            raise ValueError(f"table '{name}' baked {t.shape}, expected {want}")
        q = quantize(t, fmt)
        q.setflags(write=False)
        _BAKED[key] = q
    return _BAKED[key]


def bilinear(texels: np.ndarray, u, v) -> np.ndarray:
    """Bilinear, clamp-to-edge sample of (H, W, 4) texels at texture coordinates (u, v) (float64)."""
    img = decoded(texels)
    h, w = img.shape[:2]
    x = np.asarray(u, np.float64) * w - 0.5
    y = np.asarray(v, np.float64) * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    ax, ay = (x - x0)[..., None], (y - y0)[..., None]
    i0, i1 = np.clip(x0, 0, w - 1).astype(np.intp), np.clip(x0 + 1, 0, w - 1).astype(np.intp)
    j0, j1 = np.clip(y0, 0, h - 1).astype(np.intp), np.clip(y0 + 1, 0, h - 1).astype(np.intp)
    return ((img[j0, i0] * (1 - ax) + img[j0, i1] * ax) * (1 - ay)
            + (img[j1, i0] * (1 - ax) + img[j1, i1] * ax) * ay)


def _error_axis(n: int, samples: int) -> np.ndarray:
    """Table coordinates at which an axis of n texels is checked: at least `samples` points, and at least the
    texel centres and the quarter points between each pair (4 (n − 1) + 1), so that a fine table is checked
    between all of its centres (a fixed grid aliases with the table: 257 points land within 1/65536 of the
    centres of a 256-texel axis and see none of the filter's error)."""
    if n <= 1:
        return np.zeros(1)
    return np.linspace(0.0, 1.0, max(samples, 4 * (n - 1) + 1))


def table_error(name: str, size, fmt: str, samples: int = 257) -> dict | None:
    """The filtered table against its exact function on a grid of table coordinates (between and on the
    texel centres, `_error_axis`): max absolute error, max relative error (to the channel's largest
    value) and the worst point; None for a table without an exact function (painted, cube)."""
    d = lookup(name)
    if d.exact is None or d.cube:
        return None
    w, h = (int(size[0]), int(size[1]) if len(size) > 1 else 1)
    stored = baked(name, (w, h), fmt)
    xs, ys = _error_axis(w, samples), _error_axis(h, samples)
    # rows in chunks (a 512² table is checked at 2045² points): per chunk and channel, the largest error and
    # where; the relative error divides by the channel's largest exact value over the whole grid
    chunk = max(1, 2 ** 20 // len(xs))
    err_max, where, scale = np.full(3, -1.0), [(0.0, 0.0)] * 3, np.zeros(3)
    for k in range(0, len(ys), chunk):
        x, y = np.meshgrid(xs, ys[k:k + chunk])
        got = bilinear(stored, texel_coordinate(x, w), texel_coordinate(y, h))
        want = np.asarray(d.exact(x, y), np.float64)
        err = np.abs(got - want)[..., :3].reshape(-1, 3)
        scale = np.maximum(scale, np.abs(want[..., :3]).reshape(-1, 3).max(axis=0))
        for c in range(3):
            m = int(np.argmax(err[:, c]))
            if err[m, c] > err_max[c]:
                err_max[c], where[c] = err[m, c], (float(x.flat[m]), float(y.flat[m]))
    rel = err_max / np.maximum(scale, 1e-30)
    c = int(np.argmax(rel))
    return {"max_abs": float(err_max.max()), "max_rel": float(rel.max()),
            "worst": {"x": where[c][0], "y": where[c][1], "channel": "rgb"[c]}}


def sha256(stored: np.ndarray) -> str:
    """sha256 of the stored texels' bytes (C order)."""
    return hashlib.sha256(np.ascontiguousarray(stored).tobytes()).hexdigest()


_LOADED = False


def _load() -> None:
    """Import the modules that register tables (once)."""
    global _LOADED
    if _LOADED:
        return
    _LOADED = True
    import importlib
    import pkgutil
    for m in sorted(pkgutil.iter_modules([str(Path(__file__).parent)]), key=lambda m: m.name):
        if m.name.startswith("tables_"):
            importlib.import_module(f"{__package__}.{m.name}")


def all_tables() -> dict[str, TableDef]:
    """Every registered table by name."""
    _load()
    return dict(TABLES)
