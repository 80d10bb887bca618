"""Tables of the factored forms of the course's analytic BRDFs (Hoffman & Baker 2006, "BRDF Costs").

Each is baked from the float64 expression it replaces, at texel centres (tables.py conventions);
the brick that samples it cites the model, and its accuracy against the direct model's reference is
what `shadermatrix accuracy` reports for it.
"""
from __future__ import annotations

import numpy as np

from .tables import axis, rgba, table


def _sin_sin(x, y):
    """sin θ_i sin θ_r = sqrt(1 − x²) sqrt(1 − y²) for x = cos θ_i, y = cos θ_r in [0, 1]."""
    return np.sqrt(np.clip(1.0 - x * x, 0.0, 1.0)) * np.sqrt(np.clip(1.0 - y * y, 0.0, 1.0))


@table("oren_nayar_sin_sin", "sin α sin β = sin θ_i sin θ_r of Oren & Nayar 1994 eq. 30, at (n·l, n·v)",
       exact=lambda x, y: rgba(_sin_sin(x, y)))
def oren_nayar_sin_sin(w: int, h: int) -> np.ndarray:
    """sin α tan β's bounded factor: x = n·l along u, y = n·v along v."""
    x, y = np.meshgrid(axis(w), axis(h))
    return rgba(_sin_sin(x, y))
