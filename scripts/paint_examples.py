#!/usr/bin/env python3
"""Write the example hand-painted BRDF textures to bricks/brdf/painted/ (deterministic PNGs).

The "paintings" of Hoffman & Baker 2006's hand-painted BRDFs (NDF maps, Fresnel ramps, NDF + Fresnel
texture), drawn here from formulas so that they are small, reproducible and reviewable; the generator
normalizes them (generator/reference/tables_painted.py, which documents the axes). An artist's or an
engine's own PNG takes their place through tables_painted.bake_painted.

Each is painted on its table's axes (tables_painted.py): u = √(1 − cos θ_h), 1 − cos α_h, (h·t, h·b).

- ndf_map.png (64 × 1, RGB): p over u = √(1 − cos θ_h) from 0 (left) to 1 (θ_h = 90°): a sharp core
  exp(−(θ/0.12)²) and a broad bluish haze 0.15 exp(−(θ/0.5)²) (the notes' "colored facets").
- ndf_map_anisotropic.png (64 × 64, grey): p over (h·t, h·b) ∈ [−1, 1]²: a brushed lobe stretched
  along b, crossed by a weaker one along t (a four-pointed star highlight).
- ndf_fresnel_map.png (64 × 32, grey): T over u (x) and 1 − cos α_h (y, α_h = 0 at the top): a lobe that
  widens toward grazing (0.15 + 0.15 (α/90°)² rad) and brightens by Schlick's factor from f0 = 0.125
  to 1 (row 0, the NDF the generator normalizes, peaks at 0.125: 32 levels of 8 bits).
- fresnel_ramp.png (64 × 1, RGB): R_F over 1 − cos α_h of gold, the exact conductor Fresnel at n + ik =
  (0.18 + 3.42i, 0.42 + 2.35i, 1.37 + 1.77i) at 650, 550, 450 nm (Johnson & Christy 1972, as tabulated
  at refractiveindex.info) — "computed from material properties", a ramp an f0 cannot express.

Run: .venv/bin/python scripts/paint_examples.py  (rewrites the files; same bytes every run)
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from PIL import Image

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
OUT = REPO / "bricks" / "brdf" / "painted"


def _u8(a: np.ndarray) -> np.ndarray:
    return np.round(np.clip(a, 0.0, 1.0) * 255.0).astype(np.uint8)


def _save(name: str, a: np.ndarray) -> None:
    mode = "L" if a.ndim == 2 else "RGB"
    # no metadata chunks (no time, no text): the bytes depend on the pixels and Pillow's zlib only
    Image.fromarray(_u8(a), mode).save(OUT / name, format="PNG", optimize=False, compress_level=9)


def _theta(u):
    """θ_h at u = √(1 − cos θ_h)."""
    return np.arccos(1.0 - u * u)


def ndf_map() -> np.ndarray:
    t = _theta(np.linspace(0.0, 1.0, 64))
    core = np.exp(-(t / 0.12) ** 2)
    haze = 0.15 * np.exp(-(t / 0.5) ** 2)
    tint = np.array([0.55, 0.8, 1.0])  # the haze's facets reflect more blue
    return (core[:, None] + haze[:, None] * tint)[None]  # (1, 64, 3)


def ndf_map_anisotropic() -> np.ndarray:
    x, y = np.meshgrid(np.linspace(-1.0, 1.0, 64), np.linspace(-1.0, 1.0, 64))
    return np.exp(-(x / 0.1) ** 2 - (y / 0.45) ** 2) + 0.5 * np.exp(-(x / 0.45) ** 2 - (y / 0.1) ** 2)


def ndf_fresnel_map() -> np.ndarray:
    u, y = np.meshgrid(np.linspace(0.0, 1.0, 64), np.linspace(0.0, 1.0, 32))
    th, al = _theta(u), np.arccos(1.0 - y)
    width = 0.15 + 0.15 * (al / (0.5 * math.pi)) ** 2
    f0 = 0.125
    schlick = f0 + (1.0 - f0) * (1.0 - np.cos(al)) ** 5
    return schlick * np.exp(-(th / width) ** 2)


def fresnel_ramp() -> np.ndarray:
    from generator.reference.exact import fresnel_conductor
    c = 1.0 - np.linspace(0.0, 1.0, 64)
    eta, k = np.array([0.18, 0.42, 1.37]), np.array([3.42, 2.35, 1.77])
    return np.stack([fresnel_conductor(c, eta[i], k[i]) for i in range(3)], axis=-1)[None]


def main() -> int:
    OUT.mkdir(parents=True, exist_ok=True)
    _save("ndf_map.png", ndf_map())
    _save("ndf_map_anisotropic.png", ndf_map_anisotropic())
    _save("ndf_fresnel_map.png", ndf_fresnel_map())
    _save("fresnel_ramp.png", fresnel_ramp())
    for p in sorted(OUT.glob("*.png")):
        print(p.relative_to(REPO))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
