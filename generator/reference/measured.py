"""Measured BRDFs in the MERL database's binary format: the reader and the sampler the factorization uses.

Matusik, Pfister, Brand & McMillan 2003, "A Data-Driven Reflectance Model" (SIGGRAPH 2003): 100
isotropic materials, each a table of f_r over Rusinkiewicz's half/difference angles (Rusinkiewicz 1998,
"A New Change of Variables for Efficient BRDF Representation"). The format, as the reference reader
distributed with the database describes it (MERL's BRDFRead.cpp: `read_brdf`, `lookup_brdf_val`,
`theta_half_index`, `theta_diff_index`, `phi_diff_index`; e.g. the copy in github.com/nbonneel/pathtracer
MERLBRDFRead.cpp, and A. Fichet's merl.py, maverick.inria.fr/Members/Alban.Fichet/code/merl):

- a header of three int32 n_θh, n_θd, n_φd — (90, 90, 180) for the database (the reference reader
  checks only their product; we accept any positive dims with the same parameterization, so a test
  can write a small file) — then 3 · n_θh n_θd n_φd float64, channel-major: the R block, the G block,
  the B block; within a block the index is (i_θh · n_θd + i_θd) · n_φd + i_φd (φ_d fastest).
  Both little-endian (the files were written on x86 and are read with fread there).
- f_r (1/sr) = stored value × (1/1500, 1.15/1500, 1.66/1500) for R, G, B (RED_SCALE, GREEN_SCALE,
  BLUE_SCALE of the reference reader).
- A negative value is "not measured" (below the horizon: the reference lookup prints "Below
  horizon."). Here it reads NaN and the factorization skips the sample.
- Angles (local frame, n = z, t = x): h = (l + v)/|l + v|, θ_h = acos(h_z), φ_h = atan2(h_y, h_x)
  (ignored: the data is isotropic); the difference vector d = R_y(−θ_h) R_z(−φ_h) l, θ_d = acos(d_z),
  φ_d = atan2(d_y, d_x).
- Index maps: θ_h non-linearly, i = sqrt(θ_h / (π/2)) · n_θh (dense near the specular peak, θ_h = 0);
  θ_d linearly, i = θ_d / (π/2) · n_θd; φ_d over [0, π) only, i = φ_d / π · n_φd, a negative φ_d
  moved up by π — reciprocity: swapping l and v turns d into (−d_x, −d_y, d_z), φ_d into φ_d + π.

Lookup: **trilinear** in those index coordinates, the sample of index i at coordinate i (θ_h,i =
(i/n)² π/2, θ_d,j = j/n · π/2, φ_d,k = k/n · π: the angles at which the reference lookup's truncation
to an int starts returning sample i), clamped to the first and last sample along θ_h and θ_d and
periodic along φ_d (φ_d = π is φ_d = 0). Next to unmeasured samples the weights are renormalized
over the measured corners, and the value is not measured (NaN) where those hold less than half the
weight (MIN_MEASURED). `mode="floor"` reproduces the reference lookup (the sample whose cell holds
the point; NaN where that is not measured) for comparison.
"""
from __future__ import annotations

import hashlib
import os
import stat
from dataclasses import dataclass

import numpy as np

from ..lang.errors import SourceError

# Per-channel scale from the stored values to f_r in 1/sr (the reference reader's RED_SCALE,
# GREEN_SCALE, BLUE_SCALE).
SCALE = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
DATABASE_DIMS = (90, 90, 180)  # n_θh, n_θd, n_φd of every file of the MERL database (33.4 MiB each)
HEADER_BYTES = 12  # three int32
# The trilinear lookup renormalizes over the measured corners of its cell and reads "not measured"
# where they hold less than this weight: at most half a cell of extrapolation into the unmeasured
# region (near grazing θ_d), and a point on a measured sample reads that sample even where rounding
# gives a tiny weight to an unmeasured neighbour.
MIN_MEASURED = 0.5
# The largest file read: four times a database file (e.g. a 180 × 180 × 360 resampling), 134 MiB of
# float64 held in memory while the factorization samples it. A larger header is a corrupt file, not data.
MAX_VALUES = 4 * 3 * DATABASE_DIMS[0] * DATABASE_DIMS[1] * DATABASE_DIMS[2]


@dataclass(frozen=True, eq=False)
class MeasuredBRDF:
    """A measured isotropic BRDF on the half/difference grid: f (3, n_θh, n_θd, n_φd) in 1/sr, NaN where
    not measured; `path` as given (for messages), `sha256` of the file's bytes (a cache key)."""

    path: str
    dims: tuple[int, int, int]
    f: np.ndarray
    sha256: str

    @property
    def measured_fraction(self) -> float:
        """The fraction of grid samples measured (all three channels)."""
        return float(np.mean(np.all(np.isfinite(self.f), 0)))

    def __call__(self, L, V, mode: str = "trilinear") -> np.ndarray:
        """f_r (M, 3) at local directions L, V (M, 3) (n = z): NaN where not measured (module docstring)."""
        return lookup(self, L, V, mode)


def _read_bytes(path) -> bytes:
    """The file's bytes; a SourceError naming it when it is missing, not a regular file or too large."""
    shown = str(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO opens without waiting
    except OSError as e:
        raise SourceError(shown, 1, 1, f"cannot read the measured BRDF: {e.strerror}", "check the path") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise SourceError(shown, 1, 1, "the measured BRDF is not a regular file",
                              "give a MERL .binary file")
        limit = HEADER_BYTES + 8 * MAX_VALUES
        if st.st_size > limit:
            raise SourceError(shown, 1, 1, f"the file is {st.st_size} bytes, more than the {limit} of the largest "
                              "measured BRDF read", "give a MERL .binary file (33.4 MiB for the database's)")
        chunks, size = [], 0
        while True:
            part = os.read(fd, 1 << 22)
            if not part:
                break
            size += len(part)
            if size > limit:
                raise SourceError(shown, 1, 1, f"the file is more than {limit} bytes", "give a MERL .binary file")
            chunks.append(part)
        return b"".join(chunks)
    except OSError as e:
        raise SourceError(shown, 1, 1, f"cannot read the measured BRDF: {e.strerror}", "check the path") from None
    finally:
        os.close(fd)


def read_merl(path) -> MeasuredBRDF:
    """Read a MERL .binary file (module docstring), validating the header and the length; every problem is
    a SourceError `path:1:1: what — what to do`."""
    shown = str(path)
    data = _read_bytes(path)
    hint = "give a MERL BRDF database file: three int32 dims (90 90 180), then 3 × their product float64"
    if len(data) < HEADER_BYTES:
        raise SourceError(shown, 1, 1, f"the file is {len(data)} bytes, shorter than the 12-byte header", hint)
    dims = tuple(int(d) for d in np.frombuffer(data, "<i4", 3))
    if any(d < 1 for d in dims):
        raise SourceError(shown, 1, 1, f"the header's dims {dims} are not all positive "
                          "(n_θh, n_θd, n_φd)", hint)
    n = dims[0] * dims[1] * dims[2]
    if 3 * n > MAX_VALUES:
        raise SourceError(shown, 1, 1, f"the header's dims {dims} ask for {3 * n} values, more than the "
                          f"{MAX_VALUES} read (the database's are {DATABASE_DIMS})", hint)
    want = HEADER_BYTES + 24 * n
    if len(data) != want:
        what = "truncated" if len(data) < want else "longer than its header says"
        raise SourceError(shown, 1, 1, f"the file is {what}: {len(data)} bytes, but dims {dims} make "
                          f"12 + 3 × {n} × 8 = {want}", hint)
    raw = np.frombuffer(data, "<f8", 3 * n, HEADER_BYTES).reshape(3, *dims)
    bad = ~np.isfinite(raw)
    if bad.any():
        c, i, j, k = (int(x[0]) for x in np.nonzero(bad))
        raise SourceError(shown, 1, 1, f"value {raw[c, i, j, k]} (channel {'RGB'[c]}, sample θ_h {i}, θ_d {j}, "
                          f"φ_d {k}) is not a finite number", "negative values mark unmeasured samples; "
                          "NaN and infinities are not data")
    f = raw * SCALE[:, None, None, None]
    f[:, np.any(raw < 0.0, 0)] = np.nan  # not measured in some channel: the sample is not measured
    if not np.isfinite(f).any():
        raise SourceError(shown, 1, 1, "no sample is measured (every value is negative)", hint)
    return MeasuredBRDF(shown, dims, f, hashlib.sha256(data).hexdigest())


# ------------------------------------------------------------------ the half/difference parameterization

def half_diff(L, V) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(θ_h, θ_d, φ_d) of local directions L, V (M, 3) (n = z, t = x), φ_d in [0, π) (module docstring)."""
    L = np.asarray(L, np.float64)
    s = L + np.asarray(V, np.float64)
    h = s / np.maximum(np.linalg.norm(s, axis=-1, keepdims=True), 1e-300)  # l = −v: h = 0, θ_h = π/2 below
    th = np.arccos(np.clip(h[:, 2], -1.0, 1.0))
    ph = np.arctan2(h[:, 1], h[:, 0])
    cp, sp, ct, st = np.cos(ph), np.sin(ph), np.cos(th), np.sin(th)
    x = L[:, 0] * cp + L[:, 1] * sp  # R_z(−φ_h) l
    y = -L[:, 0] * sp + L[:, 1] * cp
    z = L[:, 2]
    dx, dz = x * ct - z * st, x * st + z * ct  # then R_y(−θ_h)
    td = np.arccos(np.clip(dz, -1.0, 1.0))
    pd = np.arctan2(y, dx)
    pd = np.where(pd < 0.0, pd + np.pi, pd)
    return th, td, np.where(pd >= np.pi, 0.0, pd)  # pd + π may round to π: that is φ_d = 0


def index_coordinates(th, td, pd, dims) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Continuous grid coordinates of (θ_h, θ_d, φ_d): sample i sits at coordinate i (module docstring)."""
    return (np.sqrt(np.clip(th, 0.0, None) / (np.pi / 2)) * dims[0],
            np.asarray(td) / (np.pi / 2) * dims[1], np.asarray(pd) / np.pi * dims[2])


def lookup(m: MeasuredBRDF, L, V, mode: str = "trilinear") -> np.ndarray:
    """f_r (M, 3) of measured BRDF m at local directions L, V: trilinear (NaN where the measured corners hold
    less than MIN_MEASURED of the weight) or "floor" (the reference reader's truncation)."""
    xh, xd, xp = index_coordinates(*half_diff(L, V), m.dims)
    nh, nd, n_p = m.dims
    if mode == "floor":
        i = np.clip(xh.astype(np.intp), 0, nh - 1)
        j = np.clip(xd.astype(np.intp), 0, nd - 1)
        k = np.clip(xp.astype(np.intp), 0, n_p - 1)
        return m.f[:, i, j, k].T
    if mode != "trilinear":
        raise ValueError(f"unknown lookup mode {mode!r}: 'trilinear' or 'floor'")

    def clamped(x, n):  # the two samples around x and the weight of the second, held at the ends
        x = np.clip(x, 0.0, n - 1.0)
        i0 = np.minimum(np.floor(x).astype(np.intp), n - 1)
        return i0, np.minimum(i0 + 1, n - 1), x - i0
    i0, i1, a = clamped(xh, nh)
    j0, j1, b = clamped(xd, nd)
    xp = np.mod(xp, n_p)  # periodic: φ_d = π is φ_d = 0
    k0 = np.minimum(np.floor(xp).astype(np.intp), n_p - 1)
    k1, c = (k0 + 1) % n_p, xp - k0
    out, held = np.zeros((len(xh), 3)), np.zeros(len(xh))
    for i, wi in ((i0, 1.0 - a), (i1, a)):
        for j, wj in ((j0, 1.0 - b), (j1, b)):
            for k, wk in ((k0, 1.0 - c), (k1, c)):
                w = wi * wj * wk
                v = m.f[:, i, j, k].T
                ok = np.isfinite(v[:, 0])  # a sample is measured in all three channels or in none (read_merl)
                out += np.where(ok[:, None], w[:, None] * v, 0.0)
                held += np.where(ok, w, 0.0)
    # renormalized over the measured corners; NaN where they hold less than half the weight (MIN_MEASURED)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where((held >= MIN_MEASURED)[:, None], out / held[:, None], np.nan)


# ------------------------------------------------------------------ factorizing a measured file

MEASURED_TABLES = ("homomorphic_p", "homomorphic_q")


def bake_measured(name: str, path, size, fmt: str) -> tuple[np.ndarray, dict]:
    """The stored texels of homomorphic_p or homomorphic_q factored from the MERL file at `path` (the same
    log-space least squares as the reference target's, tables_homomorphic.factorize, over the same sample
    pairs; the unmeasured ones skipped), and a summary {samples, used, residual, baseline}. Errors name
    the file."""
    from . import tables_homomorphic as th
    from .tables import quantize, rgba

    if name not in MEASURED_TABLES:
        raise ValueError(f"table '{name}' is not factored from a measured BRDF: {', '.join(MEASURED_TABLES)} are")
    w, h = int(size[0]), int(size[1])
    if w != h:
        raise ValueError(f"a cube map's faces are square, not {w} × {h}: give --size SxS")
    m = read_merl(path)
    sol = th.solved(w, target=m, key=("merl", m.sha256))
    if sol["used"] == 0:
        raise SourceError(m.path, 1, 1, "no sample pair of the upper hemisphere falls on measured data",
                          "check that the file is a MERL BRDF")
    t = sol["P" if name == "homomorphic_p" else "Q"]
    texels = rgba(t[..., 0], t[..., 1], t[..., 2])
    try:
        stored = quantize(texels, fmt)
    except ValueError as e:  # fp16's 65504: a very sharp measured highlight
        raise SourceError(m.path, 1, 1, f"the factor does not fit {fmt}: {e}",
                          "bake it as fp32 (--texel-format fp32)") from None
    return stored, {"samples": sol["samples"], "used": sol["used"], "residual": sol["residual"],
                    "baseline": sol["baseline"]}
