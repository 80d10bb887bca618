"""Contact sheet: every BRDF spec rendered as a lit sphere on lavapipe, in every language, beside its error map.

    .venv/bin/python benchmarks/contact_sheet.py [--targets glsl,hlsl,wgsl] [--size 96]
        [--all-combinations] [--out benchmarks/results]

One sheet per language, `contact_sheet_<language>.png`. The specs are
`shadermatrix accuracy`'s default set: every diffuse and specular brick, each
slot filler at least once (`--all-combinations`: every combination), at the
bricks' default parameters. Per spec, two panels:

- top: a unit sphere seen from +z (orthographic) under one directional light,
  L_o = π f_r c_light cos θ_l with c_light = 1 (the punctual-light
  equation, c_light the game intensity), f_r from that language's eval kernel on lavapipe (float32). The
  radiance is multiplied by an exposure chosen per spec so that its 99.5th
  percentile maps to 0.8 after Reinhard tone mapping (x / (1 + x)), then
  sRGB-encoded — so a dim microfacet lobe (f0 = 0.04) is as visible as a
  Lambertian sphere. The exposure is printed under each sphere: images compare
  shapes, not brightness.
- bottom: the relative error |f - f_ref| / max(f_ref, 1e-6 sr⁻¹) against the
  float64 reference (the worst RGB channel), on a log scale from 1e-9 to 1e-3.

Tangent frame for the anisotropic bricks: T along the sphere's lines of
latitude around the y axis (T = normalize(n_z, 0, -n_x)). A picture for a
person checking the bricks by eye; the assertions live in tests/.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

from cliargs import folder, languages, positive  # noqa: E402

LIGHT = np.array([0.45, 0.55, 0.70])
COLUMNS = 8  # specs per row of the sheet
TARGET_WHITE = 0.8  # the tone-mapped value the 99.5th percentile of a sphere's radiance is exposed to


def sphere(size: int):
    """Normals, tangents, view and light vectors of the visible hemisphere of a unit sphere (orthographic)."""
    y, x = np.mgrid[1:-1:size * 1j, -1:1:size * 1j]
    r2 = x * x + y * y
    mask = r2 < 0.999
    n = np.stack([x[mask], y[mask], np.sqrt(1.0 - r2[mask])], axis=-1)
    t = np.stack([n[:, 2], np.zeros(len(n)), -n[:, 0]], axis=-1)
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    v = np.broadcast_to([0.0, 0.0, 1.0], n.shape)
    light = np.broadcast_to(LIGHT / np.linalg.norm(LIGHT), n.shape)
    return mask, np.ascontiguousarray(light), np.ascontiguousarray(v), n, t


def exposure(radiance: np.ndarray) -> float:
    """The factor that maps the 99.5th percentile of the radiance to TARGET_WHITE after Reinhard."""
    lit = radiance[radiance > 0.0]
    if lit.size == 0:
        return 1.0
    p = float(np.percentile(lit, 99.5))
    return TARGET_WHITE / (1.0 - TARGET_WHITE) / p if p > 0.0 else 1.0


def display(radiance: np.ndarray) -> np.ndarray:
    mapped = radiance / (1.0 + radiance)  # Reinhard, for display only
    return np.where(mapped <= 0.0031308, 12.92 * mapped, 1.055 * np.power(mapped, 1 / 2.4) - 0.055)


def title(spec: str) -> str:
    return spec.replace("(", "(\n").replace(",", ",\n").replace("+", "+\n")


def sheet(target: str, specs: list[str], size: int, lib, out: Path, progress) -> tuple[Path, float]:
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from generator import evaluate

    mask, L, V, N, T = sphere(size)
    cos = np.clip(np.sum(N * L, axis=-1), 0.0, None)[:, None]
    rows = math.ceil(len(specs) / COLUMNS)
    fig, axes = plt.subplots(2 * rows, COLUMNS, figsize=(1.9 * COLUMNS, 4.6 * rows), squeeze=False,
                             layout="constrained")
    worst = []
    im = None
    for i, spec in enumerate(specs):
        top, bottom = axes[2 * (i // COLUMNS), i % COLUMNS], axes[2 * (i // COLUMNS) + 1, i % COLUMNS]
        f = evaluate(spec, L, V, N, T, target=target, lib=lib)
        ref = evaluate(spec, L, V, N, T, target="reference", lib=lib)
        radiance = np.pi * f * cos
        k = exposure(radiance)
        image = np.full((size, size, 3), 0.18)  # grey backdrop shows the silhouette
        image[mask] = display(k * radiance)
        rel = np.full((size, size), np.nan)
        err = np.max(np.abs(f - ref) / np.maximum(np.abs(ref), 1e-6), axis=-1)
        rel[mask] = np.maximum(err, 1e-9)
        worst.append(float(np.nanmax(rel)))
        top.imshow(image, interpolation="nearest")
        top.set_title(title(spec), fontsize=6)
        top.set_xlabel(f"exposure ×{k:.3g}", fontsize=6)
        im = bottom.imshow(rel, norm=LogNorm(1e-9, 1e-3), cmap="magma", interpolation="nearest")
        bottom.set_xlabel(f"max rel {worst[-1]:.1e}", fontsize=6)
        progress.update(1)
    for ax in axes.flat:
        ax.set_xticks([])
        ax.set_yticks([])
        if not ax.images:
            ax.set_axis_off()
    for r in range(rows):
        axes[2 * r, 0].set_ylabel(f"{target} on lavapipe, π f_r cos θ_l", fontsize=7)
        axes[2 * r + 1, 0].set_ylabel("relative error\nvs float64 reference", fontsize=7)
    fig.colorbar(im, ax=axes[1::2, :].ravel().tolist(), shrink=0.6, label="|f - f_ref| / f_ref")
    fig.suptitle(f"BRDF bricks at default parameters in {target.upper()} on lavapipe (float32): one directional "
                 f"light; each sphere exposed so its 99.5th percentile reads {TARGET_WHITE} after Reinhard "
                 "(exposure under each)", fontsize=9)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"contact_sheet_{target}.png"
    tmp = path.with_suffix(".tmp.png")  # written whole, then renamed: an interrupted run leaves the old sheet
    fig.savefig(tmp, dpi=100)
    os.replace(tmp, path)
    plt.close(fig)
    return path, max(worst)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--targets", type=languages, default="glsl,hlsl,wgsl",
                    help="comma-separated eval kernel languages, one sheet each (default glsl,hlsl,wgsl)")
    ap.add_argument("--size", type=positive, default=96, help="pixels per sphere (default 96)")
    ap.add_argument("--all-combinations", action="store_true",
                    help="every combination of slot fillers, instead of each filler once")
    ap.add_argument("--out", type=folder, default=str(REPO / "benchmarks" / "results"),
                    help="the folder contact_sheet_<language>.png go into (default benchmarks/results)")
    args = ap.parse_args(argv)

    import matplotlib
    matplotlib.use("Agg")
    from tqdm import tqdm

    from generator.eval.accuracy import default_specs
    from generator.io import show_progress
    from generator.library.bricks import load_library

    lib = load_library()
    specs = default_specs(lib, full=args.all_combinations)
    with tqdm(total=len(specs) * len(args.targets), disable=not show_progress(), unit="sphere") as progress:
        for target in args.targets:
            path, worst = sheet(target, specs, args.size, lib, Path(args.out), progress)
            tqdm.write(f"wrote {path.relative_to(REPO) if path.is_relative_to(REPO) else path}: {len(specs)} specs; "
                       f"worst relative error {worst:.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
