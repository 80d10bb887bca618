"""Chi-square goodness-of-fit of a direction sampler against its pdf (the method of Mitsuba's and pbrt's tests).

The upper hemisphere of the shading frame is cut into a (θ, φ) grid; samples are histogrammed over it, plus
one cell for the samples the sampler sends below the horizon. The expected count of a cell is the sample count
times the pdf integrated over the cell by Gauss-Legendre quadrature (the below-horizon cell: the mass the pdf
does not hold, 1 - ∫ pdf). Cells expected to hold fewer than 5 samples are pooled; a sample in a cell where
the pdf integrates to 0 fails outright. The p-value is the chi-square survival function, computed here from
the regularized upper incomplete gamma function (no SciPy in the environment).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MIN_EXPECTED = 5.0


def gamma_q(a: float, x: float) -> float:
    """Q(a, x) = Γ(a, x) / Γ(a): the series below a + 1, Lentz's continued fraction above (Numerical Recipes §6.2)."""
    if x <= 0.0:
        return 1.0
    lg = math.lgamma(a)
    if x < a + 1.0:
        term = total = 1.0 / a
        ap = a
        for _ in range(10000):
            ap += 1.0
            term *= x / ap
            total += term
            if abs(term) < abs(total) * 1e-15:
                break
        return max(0.0, 1.0 - total * math.exp(-x + a * math.log(x) - lg))
    tiny = 1e-300
    b = x + 1.0 - a
    c = 1.0 / tiny
    d = 1.0 / b
    h = d
    for i in range(1, 10000):
        an = -i * (i - a)
        b += 2.0
        d = an * d + b
        d = tiny if abs(d) < tiny else d
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        d = 1.0 / d
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < 1e-15:
            break
    return math.exp(-x + a * math.log(x) - lg) * h


def chi2_sf(stat: float, dof: int) -> float:
    """P(X >= stat) for X chi-square with `dof` degrees of freedom."""
    return gamma_q(dof / 2.0, stat / 2.0)


@dataclass
class Frame:
    V: np.ndarray
    N: np.ndarray
    T: np.ndarray

    @property
    def B(self) -> np.ndarray:
        return np.cross(self.N, self.T)

    def world(self, x, y, z) -> np.ndarray:
        return x[..., None] * self.T + y[..., None] * self.B + z[..., None] * self.N

    def angles(self, L) -> tuple[np.ndarray, np.ndarray]:
        z = np.clip(L @ self.N, -1.0, 1.0)
        phi = np.mod(np.arctan2(L @ self.B, L @ self.T), 2 * math.pi)
        return np.arccos(z), phi


def expected(pdf, frame: Frame, n_theta: int, n_phi: int, q: int = 8) -> np.ndarray:
    """∫ pdf over each (θ, φ) cell of the upper hemisphere, (n_theta, n_phi), by q × q Gauss-Legendre per cell."""
    x, w = np.polynomial.legendre.leggauss(q)
    dt, dp = (math.pi / 2) / n_theta, 2 * math.pi / n_phi
    t = ((np.arange(n_theta)[:, None] + (x[None, :] + 1) / 2) * dt).reshape(-1)  # n_theta * q
    p = ((np.arange(n_phi)[:, None] + (x[None, :] + 1) / 2) * dp).reshape(-1)
    wt = np.tile(w * dt / 2, n_theta) * np.sin(t)
    wp = np.tile(w * dp / 2, n_phi)
    T, P = np.meshgrid(t, p, indexing="ij")
    L = frame.world((np.sin(T) * np.cos(P)).reshape(-1), (np.sin(T) * np.sin(P)).reshape(-1), np.cos(T).reshape(-1))
    dens = pdf(L).reshape(T.shape) * wt[:, None] * wp[None, :]
    return dens.reshape(n_theta, q, n_phi, q).sum(axis=(1, 3))


@dataclass
class Result:
    p_value: float
    stat: float
    dof: int
    mass: float  # ∫ pdf over the upper hemisphere (quadrature)
    below: float  # the fraction of samples below the horizon
    reason: str = ""


def chi2_test(sample, pdf, frame: Frame, n_samples: int, seed: int, n_theta: int = 16, n_phi: int = 32,
              q: int = 8, dims: int = 2) -> Result:
    """Histogram `sample(u)` (u uniform (n, dims): 3 for a mixture, whose third picks the term) against `pdf(L)`
    over the grid, q × q quadrature nodes a cell (lobes narrow in φ near the horizon need more); see the module
    docstring."""
    u = np.random.default_rng(seed).random((n_samples, dims))
    L = sample(u)
    up = L @ frame.N > 0.0
    theta, phi = frame.angles(L[up])
    it = np.minimum((theta / (math.pi / 2) * n_theta).astype(int), n_theta - 1)
    ip = np.minimum((phi / (2 * math.pi) * n_phi).astype(int), n_phi - 1)
    observed = np.zeros((n_theta, n_phi))
    np.add.at(observed, (it, ip), 1.0)
    cells = expected(pdf, frame, n_theta, n_phi, q)
    mass = float(cells.sum())
    obs = np.append(observed.reshape(-1), float((~up).sum()))
    exp = np.append(cells.reshape(-1), max(1.0 - mass, 0.0)) * n_samples
    below = float((~up).mean())
    if np.any((exp == 0.0) & (obs > 0.0)):
        return Result(0.0, math.inf, 0, mass, below, "samples where the pdf is 0")
    order = np.argsort(exp)
    stat, dof, pool_e, pool_o = 0.0, 0, 0.0, 0.0
    for i in order:
        if exp[i] == 0.0:
            continue
        if exp[i] < MIN_EXPECTED:
            pool_e += exp[i]
            pool_o += obs[i]
            continue
        stat += (obs[i] - exp[i]) ** 2 / exp[i]
        dof += 1
    if pool_e > 0.0:
        stat += (pool_o - pool_e) ** 2 / pool_e
        dof += 1
    dof -= 1
    return Result(chi2_sf(stat, dof), stat, dof, mass, below)


def sidak(alpha: float, tests: int) -> float:
    """The per-test significance that keeps the family-wise error at `alpha` over `tests` independent tests."""
    return 1.0 - (1.0 - alpha) ** (1.0 / tests)
