"""Float64 references of the output transforms: the sRGB encoding and the course's square-root gamma.

srgb_encode: IEC 61966-2-1:1999 (sRGB), the inverse of the display transfer function:
    V = 12.92 L                      for L ≤ 0.0031308
    V = 1.055 L^(1/2.4) − 0.055      otherwise,          L in [0, 1].
sqrt_gamma: Hoffman & Baker 2006, "Gamma Conversion": Gamma(linear) = sqrt(linear) ("not exactly
the transfer function, but close enough"), applied after saturate.
"""
from __future__ import annotations

import numpy as np

SRGB_THRESHOLD = 0.0031308  # IEC 61966-2-1, the linear segment's end (in linear light)


def srgb_encode(x):
    x = np.clip(np.asarray(x, np.float64), 0.0, 1.0)
    return np.where(x <= SRGB_THRESHOLD, 12.92 * x, 1.055 * x ** (1.0 / 2.4) - 0.055)


def sqrt_gamma(x):
    return np.sqrt(np.clip(np.asarray(x, np.float64), 0.0, 1.0))


def max_error_against_srgb(encode, samples: int = 1_000_001) -> tuple[float, float]:
    """(max |encode(x) − srgb_encode(x)|, the x where it is reached) over x uniform in [0, 1]."""
    x = np.linspace(0.0, 1.0, samples)
    e = np.abs(np.asarray(encode(x), np.float64) - srgb_encode(x))
    i = int(np.argmax(e))
    return float(e[i]), float(x[i])
