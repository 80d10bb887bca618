"""Float64 references of per-texel shading frames: tangent-space normal maps and twist maps.

- Tangent-space normal (Peercy, Airey & Cabral 1997): N' = normalize(t.x T + t.y B + t.z N), t the
  texel's unit normal in the (T, B, N) basis; two-channel maps store t.xy and the unit length gives
  t.z = sqrt(1 − t.x² − t.y²) (ATI 2005, "3Dc white paper"; Hoffman & Baker 2006, "store normals
  as only x and y").
- Twist map (Hoffman & Baker 2006, "Anisotropic BRDF with Normal and Twist Maps"): a texel gives the
  tangent direction d = w.x T + w.y B in the unperturbed tangent plane; the notes' shader
  ("Anisotropic BRDF with Normal Map") orthogonalizes it against the perturbed normal by
  Gram-Schmidt, T' = (d − (d·N') N') / |d − (d·N') N'|, and completes the frame with
  B' = N' × T' (`float3x3 inv = float3x3(T, cross(N,T), N)`).

Texels are decoded from unorm values c in [0, 1] as 2c − 1. Written from the notes, not from the
bricks (bricks/packing/normal/normal_twist_map.py, twist_map.py); the bricks' guards (xy beyond the
unit disc, an unpainted twist texel, d ∥ N') are not reproduced: tests check them on their own.
"""
from __future__ import annotations

import numpy as np


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def decode(c):
    """Signed components 2c − 1 of unorm texel values c."""
    return 2.0 * np.asarray(c, np.float64) - 1.0


def normal_from_xy(c_xy, N, T, B):
    """N' of a two-channel tangent-space normal texel (c_xy: (n, 2) unorm values), z = sqrt(1 − x² − y²)."""
    t = decode(c_xy)
    z = np.sqrt(1.0 - _dot(t, t))
    return _unit(t[:, :1] * T + t[:, 1:2] * B + z[:, None] * N)


def twist_tangent(c_w, Np, T, B):
    """T' of a twist texel (c_w: (n, 2) unorm values): the direction w.x T + w.y B, Gram-Schmidt against N'."""
    w = decode(c_w)
    d = w[:, :1] * T + w[:, 1:2] * B
    return _unit(d - _dot(d, Np)[:, None] * Np)


def twisted_frame(c_xy, c_w, N, T, B):
    """(N', T', B') of a normal + twist texel pair: the orthonormal frame the anisotropic BRDF is evaluated in."""
    Np = normal_from_xy(c_xy, N, T, B)
    Tp = twist_tangent(c_w, Np, T, B)
    return Np, Tp, np.cross(Np, Tp)
