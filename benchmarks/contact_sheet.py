"""Contact sheet: every golden BRDF spec rendered as a lit sphere on lavapipe, beside its error map.

    .venv/bin/python benchmarks/contact_sheet.py [--size 160] [--target glsl] [--out benchmarks/results]

Each column is one spec of tests/golden/cases.toml at its bricks' default
parameters. Top row: a unit sphere seen from +z under one directional light
(DESIGN.md's point-light equation, L_o = π f_r c_light cos θ_l, c_light = 1),
with f_r from that language's eval kernel on lavapipe (float32), Reinhard
tone-mapped and sRGB-encoded for display only. Bottom row: the relative error
|f - f_ref| / max(f_ref, 1e-6) against the float64 reference, on a log scale.
A picture for a person checking the bricks by eye; the assertions live in tests/.
"""
from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "benchmarks"))

from cliargs import folder, positive  # noqa: E402
LIGHT = np.array([0.45, 0.55, 0.70])


def sphere(size: int):
    """Normals, view and light vectors of the visible hemisphere of a unit sphere (orthographic)."""
    y, x = np.mgrid[1:-1:size * 1j, -1:1:size * 1j]
    r2 = x * x + y * y
    mask = r2 < 1.0
    n = np.stack([x[mask], y[mask], np.sqrt(1.0 - r2[mask])], axis=-1)
    v = np.broadcast_to([0.0, 0.0, 1.0], n.shape)
    light = np.broadcast_to(LIGHT / np.linalg.norm(LIGHT), n.shape)
    return mask, np.ascontiguousarray(light), np.ascontiguousarray(v), n


def display(radiance: np.ndarray) -> np.ndarray:
    mapped = radiance / (1.0 + radiance)  # Reinhard, for display only
    return np.where(mapped <= 0.0031308, 12.92 * mapped, 1.055 * np.power(mapped, 1 / 2.4) - 0.055)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=positive, default=160, help="pixels per sphere (default 160)")
    ap.add_argument("--target", default="glsl", choices=("glsl", "hlsl", "wgsl", "numpy"),
                    help="the eval kernel's language, or numpy (default glsl)")
    ap.add_argument("--out", type=folder, default=str(REPO / "benchmarks" / "results"),
                    help="the folder contact_sheet_<target>.png goes into (default benchmarks/results)")
    args = ap.parse_args()

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from generator import evaluate

    specs = tomllib.loads((REPO / "tests" / "golden" / "cases.toml").read_text())["eval"]
    mask, L, V, N = sphere(args.size)
    cos = np.clip(np.sum(N * L, axis=-1), 0.0, None)[:, None]
    fig, axes = plt.subplots(2, len(specs), figsize=(2.2 * len(specs), 5.4), squeeze=False, layout="constrained")
    worst = []
    for col, spec in enumerate(specs):
        f = evaluate(spec, L, V, N, target=args.target)
        ref = evaluate(spec, L, V, N, target="reference")
        image = np.full((args.size, args.size, 3), 0.18)  # grey backdrop shows the silhouette
        image[mask] = display(np.pi * f * cos)
        rel = np.full((args.size, args.size), np.nan)
        err = np.max(np.abs(f - ref) / np.maximum(np.abs(ref), 1e-6), axis=-1)
        rel[mask] = np.maximum(err, 1e-9)
        worst.append(float(np.nanmax(rel)))
        axes[0, col].imshow(image, interpolation="nearest")
        axes[0, col].set_title(spec.replace("(", "(\n").replace(",", ",\n").replace("+", "+\n"), fontsize=7)
        im = axes[1, col].imshow(rel, norm=LogNorm(1e-9, 1e-3), cmap="magma", interpolation="nearest")
        axes[1, col].set_xlabel(f"max rel {worst[-1]:.1e}", fontsize=7)
        for ax in axes[:, col]:
            ax.set_xticks([])
            ax.set_yticks([])
    axes[0, 0].set_ylabel(f"{args.target} on lavapipe" if args.target != "numpy" else "numpy float64", fontsize=8)
    axes[1, 0].set_ylabel("relative error\nvs float64 reference", fontsize=8)
    fig.colorbar(im, ax=axes[1, -1], shrink=0.9, label="|f - f_ref| / f_ref")
    fig.suptitle("BRDF bricks at default parameters: one directional light, π f_r cos θ_l", fontsize=10)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"contact_sheet_{args.target}.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path.relative_to(REPO) if path.is_relative_to(REPO) else path}; "
          f"worst relative error {max(worst):.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
