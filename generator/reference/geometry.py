"""Shading geometry in float64, under the shading policy of NOTES.md.

The references evaluate the BRDF on the same quantity the bricks compute, so
they apply the same documented policy (NOTES.md, "Shading conventions"):

- f_r = 0 where n·l <= 0 (no light from below the horizon);
- n·v is clamped to [1e-4, 1]: a view below the horizon (normal mapping) shades
  as grazing;
- n·h, l·h, v·h and r·v are clamped to [0, 1];
- an undefined half vector (l = -v) is the zero vector: every cosine with it is 0.

Everything else is exact float64: h is normalized exactly, and sin²θ_h is
|n × h|² near h = n, where 1 - cos² would lose its digits (ACCURACY-FACTS pitfall 4).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NV_MIN = 1e-4  # the n·v clamp of the policy (Filament's clampNoV)


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
    """Cosines of one batch of (l, v, n[, t]) samples, after the shading policy; arrays of shape (N,)."""

    lit: np.ndarray  # n·l > 0
    NdotL: np.ndarray  # min(n·l, 1); only meaningful where lit
    NdotV: np.ndarray  # clamp(n·v, 1e-4, 1)
    NdotH: np.ndarray  # clamp(n·h, 0, 1); 0 for l = -v
    sin2_h: np.ndarray  # sin²θ_h = |n × h|² (1 where n·h <= 0 or h is undefined)
    VdotH: np.ndarray  # clamp(v·h, 0, 1) = l·h
    LdotH: np.ndarray
    LdotV: np.ndarray  # l·v (unclamped)
    RdotV: np.ndarray  # clamp(r·v, 0, 1), r = 2(n·l)n - l the mirror direction of l
    L: np.ndarray
    V: np.ndarray
    N: np.ndarray
    H: np.ndarray  # unit half vector, or 0 where l = -v
    T: np.ndarray | None = None

    @property
    def count(self) -> int:
        return self.lit.shape[0]


def shading_geometry(L, V, N, T=None) -> Geometry:
    """The geometric inputs of a BRDF, in float64, under the NOTES.md shading policy."""
    n = max(np.shape(x)[0] if np.ndim(x) == 2 else 1 for x in (L, V, N))
    L, V, N = _rows(L, "L", n), _rows(V, "V", n), _rows(N, "N", n)
    T = None if T is None else _rows(T, "T", n)
    nl = _dot(N, L)
    nv = _dot(N, V)
    s = L + V
    s2 = _dot(s, s)
    ok = s2 > 0.0
    H = np.where(ok[:, None], s / np.sqrt(np.where(ok, s2, 1.0))[:, None], 0.0)
    nh = _dot(N, H)
    # sin²θ_h in its well-conditioned form: |n × h|² near h = n, (1 - c)(1 + c) elsewhere.
    cross = np.cross(N, H)
    sin2 = np.where(nh * nh > 0.5, _dot(cross, cross), (1.0 - nh) * (1.0 + nh))
    sin2 = np.where(ok & (nh > 0.0), sin2, 1.0)
    R = 2.0 * nl[:, None] * N - L
    return Geometry(
        lit=nl > 0.0,
        NdotL=np.minimum(nl, 1.0),
        NdotV=np.clip(nv, NV_MIN, 1.0),
        NdotH=np.clip(nh, 0.0, 1.0),
        sin2_h=np.minimum(sin2, 1.0),
        VdotH=np.clip(_dot(V, H), 0.0, 1.0),
        LdotH=np.clip(_dot(L, H), 0.0, 1.0),
        LdotV=_dot(L, V),
        RdotV=np.clip(_dot(R, V), 0.0, 1.0),
        L=L, V=V, N=N, H=H, T=T,
    )
