"""Tables of the factored specular forms of the course (Hoffman & Baker 2006, "BRDF Costs, Shift-Invariant":
Blinn-Phong factored 1 tex / 2 ALU, Banks factored 1 / 5, Ashikhmin/Shirley factored 4 / 10).

Each table is baked from the float64 expression it replaces, at texel centres (tables.py conventions:
x_i = i/(W − 1), read at u = x (W − 1)/W + 0.5/W), and none depends on a material's parameters, so
one table serves every material; the bricks that sample them (bricks/brdf/specular/*_factored.py)
are judged against the direct model's reference by `shadermatrix accuracy`.

- `blinn_phong_pow`: cos^n θ_h over (lobe coordinate, exponent). A table over (n·h, n) — the classic
  factored Blinn-Phong — cannot follow large n: the lobe of cos^n is ~1/n wide in n·h (1e-4 at
  n = 1e4), while the table's texels are 1/W apart. The u axis is therefore the lobe coordinate
  u = (1 − n·h) max(n, X)/X, X = `BP_LOBE` = 24: for n ≥ X it is n (1 − n·h)/X, in which
  cos^n θ_h = (1 − uX/n)^n → e^(−uX) has the same shape for every n (only a 1/n correction is left
  for the v axis to carry); for n < X it is 1 − n·h itself (the whole [0, 1], so cos θ_h = 0 is
  the table's edge, not a kink inside it). u = 1 is e^(−24) ≈ 4e−11 of the peak, below accuracy's
  1e−6 sr⁻¹ floor for every n ≤ 1e4 at f0 ≤ 0.04 (n = 1e5, f0 = 1: 1.5e−7 sr⁻¹); the brick clamps u
  at 1, and the last column is 0 (beyond the lobe; h = 0 of l = −v reads it). The v axis is
  v = (1/√n − 1/√N)/(1 − 1/√N), N = `BP_N_MAX` = 1e5 (the brick's range):
  rows dense at small n, where cos^n changes fastest with n (measured against log n and 1/n
  rows: 1/√n has the smallest error for n ≥ 4 at equal size).
- `banks_bracket`: Banks' kernel √(1 − a²) √(1 − b²) − ab at a = l·t, b = v·t in [−1, 1], signed; the
  brick clamps it at 0 after the filter (a filtered clamp leaks 3e-3 of the peak past the kink at n = 1)
  and raises it to n in ALU (the exponent is the material's). A table linear in a and b (the course's)
  cannot follow √(1 − a²), whose slope is infinite at a = ±1 (l or v along the thread): measured at n = 32
  on the hemisphere, a 256² table of it is 0.4 % off where |l·t|, |v·t| ≤ 0.9 but 67 % off beyond 0.999,
  and 41 % at 1024². So the axes are x = (1 + sign(a)(1 − √(1 − |a|)))/2 (`banks_coordinate`): with
  w = √(1 − |a|), √(1 − a²) = w √(2 − w²) is smooth in w, and so is the kernel across the table.
- `schlick_pow5`: Schlick's (1 − x)^5, x = k·h (Schlick 1994 eq. 15), a 1D table (H = 1).
- `ashikhmin_shirley_diffuse_factor`: (1 − (1 − x/2)^5)/(5x/2) (Ashikhmin & Shirley 2000 eq. 5), x = n·l
  or n·v, a 1D table read twice by the factored diffuse term, which multiplies by 5x/2 (values in
  [0.775, 1]: unorm8 can hold them).
"""
from __future__ import annotations

import numpy as np

from .tables import axis, rgba, table

BP_LOBE = 24.0  # X: the lobe coordinate's extent in units of 1/n (e^-24 ≈ 4e-11: below every floor)
BP_N_MAX = 1.0e5  # the largest exponent the v axis reaches (blinn_phong_normalized's range)
_R_LO = 1.0 / np.sqrt(BP_N_MAX)


def bp_exponent(y) -> np.ndarray:
    """The exponent n of the v coordinate y of `blinn_phong_pow`: 1/√n = 1/√N + y (1 − 1/√N)."""
    return 1.0 / (_R_LO + np.asarray(y, np.float64) * (1.0 - _R_LO)) ** 2


def bp_coordinates(cos_h, n) -> tuple[np.ndarray, np.ndarray]:
    """The table coordinates (x, y) of cos θ_h and n (what the brick computes in ALU), x clamped at 1."""
    c, n = np.asarray(cos_h, np.float64), np.asarray(n, np.float64)
    x = np.minimum((1.0 - c) * np.maximum(n, BP_LOBE) / BP_LOBE, 1.0)
    return x, (1.0 / np.sqrt(n) - _R_LO) / (1.0 - _R_LO)


def _bp_pow(x, y) -> np.ndarray:
    """cos^n θ_h at lobe coordinate x and exponent row y: c = 1 − x X / max(n, X), c^n (from log1p)."""
    n = bp_exponent(y)
    one_minus_c = np.asarray(x, np.float64) * BP_LOBE / np.maximum(n, BP_LOBE)
    with np.errstate(divide="ignore"):
        v = np.exp(n * np.log1p(-np.minimum(one_minus_c, 1.0)))
    # the last column (x = 1, the clamp of everything beyond the lobe: e^-24 of the peak for n >= 24, cos θ_h = 0
    # below) is 0, so that the undefined h = 0 of l = -v, which the bricks send there, reflects nothing
    return np.where(np.asarray(x) >= 1.0, 0.0, v)


@table("blinn_phong_pow", "cos^n θ_h of Blinn-Phong (Hoffman & Baker 2006) at (lobe coordinate, 1/√n)",
       exact=lambda x, y: rgba(_bp_pow(x, y)))
def blinn_phong_pow(w: int, h: int) -> np.ndarray:
    """cos^n θ_h: x = (1 − n·h) max(n, 24)/24 along u, y = (1/√n − 1/√1e5)/(1 − 1/√1e5) along v."""
    x, y = np.meshgrid(axis(w), axis(h))
    return rgba(_bp_pow(x, y))


def banks_cosine(x) -> np.ndarray:
    """The cosine a = l·t (or v·t) of table coordinate x: s = 2x − 1, a = sign(s) (1 − (1 − |s|)²); the brick
    computes the inverse x = (1 + sign(a) (1 − √(1 − |a|)))/2 in ALU (banks_coordinate)."""
    s = 2.0 * np.asarray(x, np.float64) - 1.0
    return np.sign(s) * (1.0 - (1.0 - np.abs(s)) ** 2)


def banks_coordinate(a) -> np.ndarray:
    """The table coordinate of a cosine a in [−1, 1]: (1 + sign(a) (1 − √(1 − |a|)))/2."""
    a = np.asarray(a, np.float64)
    return 0.5 + 0.5 * np.sign(a) * (1.0 - np.sqrt(np.maximum(1.0 - np.abs(a), 0.0)))


def _banks(x, y) -> np.ndarray:
    a, b = banks_cosine(x), banks_cosine(y)
    k = np.sqrt(np.clip(1.0 - a * a, 0.0, 1.0)) * np.sqrt(np.clip(1.0 - b * b, 0.0, 1.0)) - a * b
    return np.clip(k, -1.0, 1.0)  # signed: the brick clamps at 0 after filtering (a filtered kink would leak)


@table("banks_bracket", "v·r' = √(1−(l·t)²) √(1−(v·t)²) − (l·t)(v·t) of Banks 1994 "
       "(Heidrich & Seidel 1998), at banks_coordinate(l·t), banks_coordinate(v·t)", exact=lambda x, y: rgba(_banks(x, y)))
def banks_bracket(w: int, h: int) -> np.ndarray:
    """Banks' kernel, signed (the brick takes max(0, ·) after the filter, so the table interpolates a smooth
    function and the clamp's kink stays exact): l·t = banks_cosine(x) along u, v·t = banks_cosine(y) along v."""
    x, y = np.meshgrid(axis(w), axis(h))
    return rgba(_banks(x, y))


def _pow5(x, y) -> np.ndarray:
    return (1.0 - np.asarray(x, np.float64) + 0.0 * np.asarray(y, np.float64)) ** 5


@table("schlick_pow5", "(1 − k·h)^5 of Schlick 1994 eq. 15, at k·h", exact=lambda x, y: rgba(_pow5(x, y)))
def schlick_pow5(w: int, h: int) -> np.ndarray:
    """(1 − x)^5 along u (every row the same; declare H = 1)."""
    x, y = np.meshgrid(axis(w), axis(h))
    return rgba(_pow5(x, y))


def _as_diffuse(x, y) -> np.ndarray:
    """(1 − (1 − x/2)^5)/(5x/2) = 1 − x + x²/2 − x³/8 + x⁴/80 (expanded: no 0/0 at x = 0), in [0.775, 1]."""
    x = np.asarray(x, np.float64) + 0.0 * np.asarray(y, np.float64)
    return 1.0 + x * (-1.0 + x * (0.5 + x * (-0.125 + x * 0.0125)))


@table("ashikhmin_shirley_diffuse_factor", "(1 − (1 − x/2)^5)/(5x/2) of Ashikhmin & Shirley 2000 eq. 5, at x = n·l or n·v",
       exact=lambda x, y: rgba(_as_diffuse(x, y)))
def ashikhmin_shirley_diffuse_factor(w: int, h: int) -> np.ndarray:
    """(1 − (1 − x/2)^5)/(5x/2) along u (every row the same; declare H = 1): the factor over its slope at 0,
    so that the brick's x · table(x) keeps its relative digits as x → 0 (a table of the factor itself is linear
    there and bilinear filtering is O(1/W) off relative to it: 1.0 % at W = 128)."""
    x, y = np.meshgrid(axis(w), axis(h))
    return rgba(_as_diffuse(x, y))
