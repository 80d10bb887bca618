"""Float64 references of the environment bricks: the outgoing radiance image-based lighting adds.

Written from the sources, independent of the brick code (which multiplies the constants out):

- SH9 irradiance, Ramamoorthi & Hanrahan 2001, "An Efficient Representation for Irradiance Environment
  Maps": the real spherical harmonics of eq. 3 (their x, y, z = our x, z, y: their z is the world's +Y),
  E(n) = Σ Â_l L_lm Y_lm(n) with Â_0 = π, Â_1 = 2π/3, Â_2 = π/4 (eqs. 8, 12), floored at 0 as the brick does.
- The split sum, Karis 2013, "Real Shading in Unreal Engine 4": a prefiltered radiance cube read at
  r = reflect(−v, n), lod = √α (L − 1) (linear between levels, bilinear within a face, clamped at its edges:
  Vulkan's "Cube Map Face Selection"; a GPU filters across faces, so values within half a texel of a face
  edge differ), times f0 · R + G of the AmbientBRDF table (Gotanda 2014), read bilinearly at table
  coordinates (n·v, √α) with its nodes at texel centres (reference/tables.py's convention).

ENVIRONMENTS maps an environment brick id to its function.
"""
from __future__ import annotations

import numpy as np

from .tables import bilinear, texel_coordinate

SH_A = (np.pi, 2.0 * np.pi / 3.0, 2.0 * np.pi / 3.0, 2.0 * np.pi / 3.0) + (np.pi / 4.0,) * 5


def sh_basis(n) -> np.ndarray:
    """(..., 9) Y_00, Y_1-1, Y_10, Y_11, Y_2-2, Y_2-1, Y_20, Y_21, Y_22 (R&H 2001 eq. 3) of unit n, world +Y up."""
    n = np.asarray(n, np.float64)
    x, y, z = n[..., 0], n[..., 2], n[..., 1]  # R&H's axes: their z is our +Y
    return np.stack([np.full_like(x, 0.282095), 0.488603 * y, 0.488603 * z, 0.488603 * x, 1.092548 * x * y,
                     1.092548 * y * z, 0.315392 * (3.0 * z * z - 1.0), 1.092548 * x * z,
                     0.546274 * (x * x - y * y)], -1)


def sh9_irradiance(coeffs, n) -> np.ndarray:
    """(..., 3) E(n) = Σ Â_l L_lm Y_lm(n), coeffs (9, 3) the L_lm (R&H eq. 12), floored at 0."""
    e = np.einsum("...k,kc->...c", sh_basis(n) * np.array(SH_A), np.asarray(coeffs, np.float64))
    return np.maximum(e, 0.0)


def _face(d):
    """(face, s, t) of directions d (m, 3): Vulkan's cube map face selection (ties X over Y over Z)."""
    ax = np.abs(d)
    use_x = (ax[:, 0] >= ax[:, 1]) & (ax[:, 0] >= ax[:, 2])
    use_y = ~use_x & (ax[:, 1] >= ax[:, 2])
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    face = np.where(use_x, np.where(x >= 0, 0, 1), np.where(use_y, np.where(y >= 0, 2, 3), np.where(z >= 0, 4, 5)))
    sc = np.choose(face, [-z, z, x, x, x, -x])
    tc = np.choose(face, [-y, -y, z, -z, -y, -y])
    ma = np.choose(face, [ax[:, 0], ax[:, 0], ax[:, 1], ax[:, 1], ax[:, 2], ax[:, 2]])
    return face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0)


def cube_read(levels, d, lod) -> np.ndarray:
    """(m, C) a mip chain of cube levels ((6, s, s, C) each) read at directions d and level `lod`."""
    d = np.atleast_2d(np.asarray(d, np.float64))
    face, s, t = _face(d)
    lod = np.clip(np.broadcast_to(np.asarray(lod, np.float64), (len(d),)), 0.0, len(levels) - 1.0)
    k0 = np.floor(lod).astype(np.intp)
    f = (lod - k0)[:, None]

    def at(k):
        img = np.asarray(levels[k], np.float64)
        n = img.shape[1]
        x, y = s * n - 0.5, t * n - 0.5
        x0, y0 = np.floor(x), np.floor(y)
        i0, i1 = np.clip(x0, 0, n - 1).astype(np.intp), np.clip(x0 + 1, 0, n - 1).astype(np.intp)
        j0, j1 = np.clip(y0, 0, n - 1).astype(np.intp), np.clip(y0 + 1, 0, n - 1).astype(np.intp)
        a, b = (x - x0)[:, None], (y - y0)[:, None]
        return ((img[face, j0, i0] * (1 - a) + img[face, j0, i1] * a) * (1 - b)
                + (img[face, j1, i0] * (1 - a) + img[face, j1, i1] * a) * b)

    reads = [at(k) for k in range(len(levels))]
    out = np.zeros_like(reads[0])
    for k in range(len(levels)):
        lo, hi = k0 == k, np.minimum(k0 + 1, len(levels) - 1) == k
        out += np.where(lo[:, None], (1.0 - f) * reads[k], 0.0) + np.where(hi[:, None], f * reads[k], 0.0)
    return out


def table_read(texels, nv, alpha) -> np.ndarray:
    """(m, 4) the AmbientBRDF table (H, W, 4) at (n·v, √α), bilinear, its nodes at texel centres."""
    texels = np.asarray(texels, np.float64)
    h, w = texels.shape[:2]
    return bilinear(texels, texel_coordinate(np.clip(nv, 0.0, 1.0), w),
                    texel_coordinate(np.sqrt(np.clip(alpha, 0.0, 1.0)), h))


def split_sum(N, V, kd, f0, alpha, sh, intensity, levels, table) -> np.ndarray:
    """(m, 3) intensity · (kd · B · E(n)/π + C(r, √α (L − 1)) · (f0 R + G)) (Karis 2013; Gotanda 2014; R&H 2001).

    N, V: unit vectors (m, 3); kd, f0: (m, 3) or (3,); alpha: (m,) or a number; sh: (9, 3) the L_lm; levels:
    the radiance cube's mip chain; table: the AmbientBRDF texels (H, W, 4); n·v floored at 1e-4."""
    N, V = np.atleast_2d(np.asarray(N, np.float64)), np.atleast_2d(np.asarray(V, np.float64))
    m = len(N)
    alpha = np.broadcast_to(np.clip(np.asarray(alpha, np.float64), 0.0, 1.0), (m,))
    nv = np.clip(np.einsum("ij,ij->i", N, V), 1e-4, 1.0)
    t = table_read(table, nv, alpha)
    r = 2.0 * np.einsum("ij,ij->i", N, V)[:, None] * N - V
    c = cube_read(levels, r, np.sqrt(alpha) * (len(levels) - 1))[:, :3]
    kd, f0 = np.broadcast_to(kd, (m, 3)), np.broadcast_to(f0, (m, 3))
    diffuse = kd * t[:, 2:3] * sh9_irradiance(sh, N) / np.pi
    return intensity * (diffuse + c * (f0 * t[:, 0:1] + t[:, 1:2]))


ENVIRONMENTS = {"split_sum": split_sum}
