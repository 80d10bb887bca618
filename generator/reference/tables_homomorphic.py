"""Homomorphic factorization of a BRDF into cube maps: f(ω_i, ω_o) ≈ p(ω_i) q(ω_h) p(ω_o).

McCool, Ang & Ahmad 2001, "Homomorphic Factorization of BRDFs for High-Performance Rendering"
(SIGGRAPH 2001), as Hoffman & Baker 2006 show it ("Measured BRDFs - Factorization"; the HLSL of
"Implementation of Factorization": C = texCUBE(P, V) · texCUBE(Q, H) · texCUBE(P, L)). Taking
logarithms turns the product into a sum,

    log f(ω_i, ω_o) ≈ log p(ω_i) + log q(ω_h) + log p(ω_o),

which is linear in the unknown log-texels: a least-squares problem. McCool et al. solve it as a
sparse system with a smoothness (Laplacian) regularization; so do we, with these choices:

- What is factored: f itself (1/sr), not f·cos θ_i (the light loop multiplies by n·l), in the local
  frame (t, b, n) = (x, y, z): ω is (ω·t, ω·b, ω·n), which is why the brick needs the tangent frame.
  One p serves both directions (a reciprocal BRDF: f(ω_i, ω_o) = f(ω_o, ω_i)).
- Unknowns: the log of every texel of P and Q (two cube maps of S × S per face, faces +X, −X, +Y,
  −Y, +Z, −Z in Vulkan's face selection, as the NumPy target and the GPU sample them). A sample's row
  holds the bilinear weights of its three look-ups (clamp-to-edge within a face, as the NumPy target
  filters): the fit is of the log-texels, the brick interpolates the texels (exp of a bilinear mean
  against the bilinear mean of exps: second order in the texel step).
- Samples: ω_i, ω_o on a deterministic stratified grid of the upper hemisphere, uniform in solid
  angle (cell centres in (cos θ, φ)); log f floored at LOG_FLOOR (where f → 0, e.g. n·h → 0, the log
  diverges and would dominate the fit; below 1e-6 sr⁻¹ accuracy measures relative to 1e-6 too).
- Regularization: λ Σ (x_a − x_b)² over neighbouring texels (4-neighbours on the sphere: the step
  past a face edge lands on the next face), which also fills the texels no sample reaches (the lower
  hemisphere) smoothly, and ε Σ x² (ε tiny) for the one gauge freedom (p·c, q/c²) and a unique solve.
- Solver: the dense normal equations (AᵀA + λDᵀD + εI) x = Aᵀb, assembled with bincount and solved
  by LAPACK (numpy.linalg.solve; scipy is not a dependency): 2 · 6 · 16² = 3,072 unknowns, ~3 s for
  the 82,944 sample pairs, the same bytes every run. (A 32² cube would need a 1.2 GB dense matrix: an
  iterative solver then.) Afterwards the gauge is fixed so that p(n) = 1 as the brick samples it:
  P is dimensionless, Q carries 1/sr.

The target by default is the reference of the brick `homomorphic_factorization` (the BRDF it
approximates, generator/reference/specular.py), sampled on the grid above; or a measured BRDF, a file
of the MERL database (Matusik et al. 2003) read and sampled trilinearly by measured.py, whose
unmeasured samples are skipped (`shadermatrix tables --bake homomorphic_p --measured FILE`).
"""
from __future__ import annotations

import numpy as np

from ..backends.numpy.resources import cube_face, cube_texel_direction
from .tables import table

# log f is floored at log(1e-6) (accuracy.REL_FLOOR: 1e-3 of an 8-bit step at unit light): f → 0
# where n·h → 0, and an unbounded log would pull the whole fit toward the horizon.
LOG_FLOOR = float(np.log(1e-6))
# Smoothness weight per neighbour pair, relative to the mean number of sample look-ups per texel:
# small enough that the data dominates where samples fall, large enough to fill the rest smoothly.
SMOOTH = 0.05
# Ridge on every log-texel (fixes the gauge p·c, q/c² and makes the normal matrix definite).
RIDGE = 1e-6
# Hemisphere grid of the samples: cos θ × φ cells per direction (ω_i and ω_o: (12·24)² = 82,944 pairs).
GRID = (12, 24)


# ------------------------------------------------------------------ cube maps (Vulkan face selection)

def _texel_grid(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(face, i, j) of every texel of an S × S cube, broadcasting to (6, S, S) in [face, j, i] order."""
    k = np.arange(size)
    return np.arange(6)[:, None, None], k[None, None, :], k[None, :, None]


def cube_directions(size: int) -> np.ndarray:
    """(6, S, S, 3) unit directions of the texel centres, faces +X, −X, +Y, −Y, +Z, −Z (Vulkan "Cube Map
    Face Selection": the inverse of (s_c, t_c, m_a) per face), indexed [face, row j, column i]."""
    return cube_texel_direction(*_texel_grid(size), size)


def cube_footprint(d, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Flat texel indices (…, 4) into a (6, S, S) cube and their bilinear weights (…, 4) at directions d:
    level 0, clamp-to-edge within the face (what the NumPy target samples)."""
    face, s, t = cube_face(d)
    x, y = s * size - 0.5, t * size - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    ax, ay = x - x0, y - y0
    i0, i1 = (np.clip(x0 + k, 0, size - 1).astype(np.intp) for k in (0, 1))
    j0, j1 = (np.clip(y0 + k, 0, size - 1).astype(np.intp) for k in (0, 1))
    base = face * size * size
    idx = np.stack([base + j0 * size + i0, base + j0 * size + i1, base + j1 * size + i0, base + j1 * size + i1], -1)
    w = np.stack([(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay], -1)
    return idx, w


def sample_cube(texels: np.ndarray, d) -> np.ndarray:
    """Bilinear sample (…, C) of (6, S, S, C) float texels at directions d (as cube_footprint)."""
    size = texels.shape[1]
    idx, w = cube_footprint(d, size)
    flat = np.asarray(texels, np.float64).reshape(6 * size * size, -1)
    return np.einsum("...k,...kc->...c", w, flat[idx])


def _neighbour_pairs(size: int) -> np.ndarray:
    """(M, 2) flat texel index pairs of 4-neighbours on the sphere (each pair once): a step of one texel
    in s or t, past a face edge onto the adjacent face (the nearest texel there)."""
    f, i, j = _texel_grid(size)
    pairs = []
    for di, dj in ((1, 0), (0, 1)):
        face, s, t = cube_face(cube_texel_direction(f, i + di, j + dj, size))
        ni = np.clip(np.floor(s * size), 0, size - 1).astype(np.intp)
        nj = np.clip(np.floor(t * size), 0, size - 1).astype(np.intp)
        pairs.append(np.stack([np.arange(6 * size * size), (face * size * size + nj * size + ni).ravel()], -1))
    p = np.concatenate(pairs)
    p = np.sort(p[p[:, 0] != p[:, 1]], axis=1)
    return np.unique(p, axis=0)


# ------------------------------------------------------------------ the least-squares solve

def hemisphere_grid(n_theta: int, n_phi: int) -> np.ndarray:
    """(n_θ·n_φ, 3) directions at the cell centres of a (cos θ, φ) grid of the upper hemisphere (equal
    solid angle per cell), local frame z = n, x = t."""
    ct = (np.arange(n_theta) + 0.5) / n_theta
    ph = (np.arange(n_phi) + 0.5) / n_phi * 2.0 * np.pi
    ct, ph = np.meshgrid(ct, ph, indexing="ij")
    st = np.sqrt(1.0 - ct * ct)
    return np.stack([st * np.cos(ph), st * np.sin(ph), ct], -1).reshape(-1, 3)


def sample_pairs(grid=GRID) -> tuple[np.ndarray, np.ndarray]:
    """Every (ω_i, ω_o) pair of the hemisphere grid, as (M, 3) arrays L, V (local frame)."""
    d = hemisphere_grid(*grid)
    i, o = np.meshgrid(np.arange(len(d)), np.arange(len(d)), indexing="ij")
    return d[i.ravel()], d[o.ravel()]


def half_vectors(L, V) -> np.ndarray:
    """Unit h = (l + v)/|l + v| (both in the upper hemisphere here, so |l + v| > 0)."""
    s = np.asarray(L) + np.asarray(V)
    return s / np.linalg.norm(s, axis=-1, keepdims=True)


def _normal_matrix(idx: np.ndarray, w: np.ndarray, n: int) -> np.ndarray:
    """AᵀA (n, n) of a sparse A given per row by column indices idx (M, K) and weights w (M, K)."""
    flat = (idx[:, :, None] * n + idx[:, None, :]).ravel()
    ww = (w[:, :, None] * w[:, None, :]).ravel()
    return np.bincount(flat, ww, minlength=n * n).reshape(n, n)


def _rows_transpose(idx: np.ndarray, w: np.ndarray, r: np.ndarray, n: int) -> np.ndarray:
    """Aᵀr (n, C) for the sparse A of (idx, w) and residuals r (M, C)."""
    return np.stack([np.bincount(idx.ravel(), (w * r[:, c, None]).ravel(), minlength=n)
                     for c in range(r.shape[1])], 1)


def factorize(L, V, f, size: int, smooth: float = SMOOTH) -> dict:
    """Log-space least-squares factorization f ≈ P(l) Q(h) P(v) of samples f (M, C) at local directions
    L, V (M, 3): {"P", "Q": (6, S, S, C) texels, "residual": RMS log residual per channel, "baseline":
    the RMS log residual of the best constant (P = 1, Q = the geometric mean of f), "samples": M, "used":
    the rows fitted}. A row with a NaN (a measured BRDF's unmeasured sample, measured.py) is skipped."""
    f = np.asarray(f, np.float64)
    f = f[:, None] if f.ndim == 1 else f
    samples = len(f)
    keep = np.all(np.isfinite(f), 1)
    if not keep.all():
        L, V, f = np.asarray(L)[keep], np.asarray(V)[keep], f[keep]
    b = np.maximum(np.log(np.maximum(f, 1e-300)), LOG_FLOOR)  # 1e-300: log(0) is -inf before the floor
    n_tex = 6 * size * size
    il, wl = cube_footprint(L, size)
    ih, wh = cube_footprint(half_vectors(L, V), size)
    iv, wv = cube_footprint(V, size)
    idx = np.concatenate([il, ih + n_tex, iv], 1)  # unknowns: log P texels, then log Q texels
    w = np.concatenate([wl, wh, wv], 1)
    n = 2 * n_tex
    pairs = _neighbour_pairs(size)
    pairs = np.concatenate([pairs, pairs + n_tex])
    lam = smooth * 3.0 * len(f) / n  # relative to the mean look-ups per unknown (3 per sample over 2·6S²)
    M = _normal_matrix(idx, w, n)
    lap = np.zeros((n, n))  # DᵀD of the differences x_a − x_b over neighbour pairs: a graph Laplacian
    np.add.at(lap, (pairs[:, 0], pairs[:, 0]), 1.0)
    np.add.at(lap, (pairs[:, 1], pairs[:, 1]), 1.0)
    np.add.at(lap, (pairs[:, 0], pairs[:, 1]), -1.0)
    np.add.at(lap, (pairs[:, 1], pairs[:, 0]), -1.0)
    M += lam * lap + RIDGE * np.eye(n)
    x = np.linalg.solve(M, _rows_transpose(idx, w, b, n))
    resid = np.einsum("mk,mkc->mc", w, x[idx]) - b
    P, Q = np.exp(x[:n_tex]).reshape(6, size, size, -1), np.exp(x[n_tex:]).reshape(6, size, size, -1)
    centre = sample_cube(P, np.array([0.0, 0.0, 1.0]))  # p(n) as the brick samples it
    return {"P": P / centre, "Q": Q * centre * centre,  # gauge: p(n) = 1 (the product is unchanged)
            "residual": np.sqrt(np.mean(resid ** 2, 0)),
            "baseline": np.sqrt(np.mean((b - b.mean(0)) ** 2, 0)), "samples": samples, "used": len(f)}


# ------------------------------------------------------------------ the tables the brick samples

def target_brdf(L, V) -> np.ndarray:
    """f (M, 3) of the BRDF the brick approximates (its reference) at local directions L, V (n = z, t = x)."""
    from .geometry import shading_geometry
    from .models import lookup
    n = len(L)
    g = shading_geometry(L, V, np.broadcast_to([0.0, 0.0, 1.0], (n, 3)), np.broadcast_to([1.0, 0.0, 0.0], (n, 3)))
    return np.asarray(lookup("specular", "homomorphic_factorization")(g, {}, {}), np.float64)


_SOLVED: dict[tuple, dict] = {}
# The largest cube side the dense solve takes: its normal matrix is (2 · 6 S²)² float64, 184 MB at S = 20
# (about four such arrays at the peak); S = 32 would need 1.2 GB each and S = 64 19 GB (an iterative
# solver then, module docstring). Refused with a ValueError before anything is allocated.
MAX_CUBE = 20


def solved(size: int, target=None, key=None) -> dict:
    """The factorization of the target BRDF at cube size S (one solve per size, shared by P and Q). target:
    another tabulated BRDF f(L, V) -> (M, 3), NaN where it has no data (a measured file, measured.py),
    cached under `key` (its file's sha256); None: the brick's reference."""
    if not 1 <= size <= MAX_CUBE:
        raise ValueError(f"a homomorphic factorization cube of {size} × {size} texels per face is beyond the dense "
                         f"solve's {MAX_CUBE} (its normal matrix grows as S⁴): declare a size of at most {MAX_CUBE}")
    if target is not None and key is None:
        raise ValueError("a tabulated target needs a cache key (its file's sha256)")
    ck = (size,) if target is None else (size, key)
    if ck not in _SOLVED:
        L, V = sample_pairs()
        _SOLVED[ck] = factorize(L, V, (target_brdf if target is None else target)(L, V), size)
    return _SOLVED[ck]


def _factor_cube(factor: str, w: int, h: int) -> np.ndarray:
    """The (6, S, S, 4) RGBA texels (alpha 1) of factor "P" or "Q" of the solve at S = w = h."""
    if w != h:
        raise ValueError(f"a cube map's faces are square, not {w} × {h}: declare [S, S]")
    t = solved(w)[factor]
    out = np.ones(t.shape[:-1] + (4,))
    out[..., :3] = t[..., :3]
    return out


@table("homomorphic_p", "p(ω) of f ≈ p(ω_i) q(ω_h) p(ω_o), log-space least squares (McCool et al. 2001) "
       "of the reference of `homomorphic_factorization`", cube=True)
def homomorphic_p(w: int, h: int) -> np.ndarray:
    """P: the direction factor (RGB, dimensionless, p(n) = 1), indexed by l or v in the (t, b, n) frame."""
    return _factor_cube("P", w, h)


@table("homomorphic_q", "q(ω_h) of f ≈ p(ω_i) q(ω_h) p(ω_o), log-space least squares (McCool et al. 2001) "
       "of the reference of `homomorphic_factorization`", cube=True)
def homomorphic_q(w: int, h: int) -> np.ndarray:
    """Q: the half-vector factor (RGB, 1/sr), indexed by h in the (t, b, n) frame."""
    return _factor_cube("Q", w, h)
