"""Shading geometry in float64, under the shading policy of docs/design/accuracy.md.

The references evaluate the BRDF on the same quantity the bricks compute, so
they apply the same documented policy (docs/design/accuracy.md, "Shading conventions"):

- f_r = 0 where n·l <= 0 (no light from below the horizon);
- n·v is clamped to [1e-4, 1]: a view below the horizon (normal mapping) shades
  as grazing;
- n·h, l·h, v·h and r·v are clamped to [0, 1];
- an undefined half vector (l = -v) is the zero vector: every cosine with it is 0.

Everything else is exact float64: h is normalized exactly, and sin²θ_h is
|n × h|² near h = n, where 1 - cos² would lose its digits (ACCURACY-FACTS pitfall 4).
The formulas are the inputs table's float64 column (generator/library/inputs.py):
the references share that table with the glue, never the bricks' code.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..library.inputs import INPUTS, NV_MIN, float64_geometry  # noqa: F401  (NV_MIN: re-exported by reference)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def _rows(x, name: str, n: int) -> np.ndarray:
    """x as an (n, 3) float64 array; a single (3,) vector is repeated."""
    a = np.asarray(x, dtype=np.float64)
    if a.shape == (3,):
        a = np.broadcast_to(a, (n, 3))
    if a.shape != (n, 3):
        raise ValueError(f"{name} must have shape ({n}, 3) or (3,), got {np.shape(x)}")
    return a


@dataclass
class Geometry:
    """The shading inputs of one batch of (l, v, n[, t]) samples, after the shading policy.

    Fields carry the names of the inputs table (generator/library/inputs.py); scalars are (N,).
    """

    lit: np.ndarray  # n·l > 0
    NdotL: np.ndarray  # min(n·l, 1); only meaningful where lit
    NdotV: np.ndarray  # clamp(n·v, 1e-4, 1)
    NdotH: np.ndarray  # clamp(n·h, 0, 1); 0 for l = -v
    NxH2: np.ndarray  # sin²θ_h = |n × h|² (1 where n·h <= 0 or h is undefined)
    VdotH: np.ndarray  # clamp(v·h, 0, 1) = l·h
    LdotH: np.ndarray
    LdotV: np.ndarray  # l·v (unclamped)
    RdotV: np.ndarray  # clamp(r·v, 0, 1), r = 2(n·l)n - l the mirror direction of l
    L: np.ndarray
    V: np.ndarray
    N: np.ndarray
    H: np.ndarray  # unit half vector, or 0 where l = -v
    T: np.ndarray | None = None
    tangent: dict = field(default_factory=dict)  # B, HdotT, HdotB, LdotT, VdotT, LdotB, VdotB when T is given

    @property
    def count(self) -> int:
        return self.lit.shape[0]

    def __getitem__(self, name: str) -> np.ndarray:
        """Any row of the inputs table by name."""
        if name in self.tangent:
            return self.tangent[name]
        return getattr(self, name)


def shading_geometry(L, V, N, T=None) -> Geometry:
    """The shading inputs of a BRDF in float64, from the inputs table's formulas (docs/design/accuracy.md's policy)."""
    n = max(np.shape(x)[0] if np.ndim(x) == 2 else 1 for x in (L, V, N))
    L, V, N = _rows(L, "L", n), _rows(V, "V", n), _rows(N, "N", n)
    T = None if T is None else _rows(T, "T", n)
    g = float64_geometry(L, V, N, T)
    fields = {f: g[f] for f in ("NdotL", "NdotV", "NdotH", "NxH2", "VdotH", "LdotH", "LdotV", "RdotV", "H")}
    tangent = {r.name: g[r.name] for r in INPUTS if r.tangent and r.name != "T" and r.name in g}
    return Geometry(lit=_dot(N, L) > 0.0, L=L, V=V, N=N, T=T, tangent=tangent, **fields)
