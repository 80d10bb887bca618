"""Run time against error: every BRDF brick and slot filler, timed on lavapipe, against the exact model.

    .venv/bin/python benchmarks/runtime_vs_error.py [--samples 1048576] [--repeats 21]
        [--languages glsl,hlsl,wgsl] [--param NAME=VALUE ...] [--out benchmarks/results]

Kernels: each diffuse and specular brick alone, the microfacet brick with every
combination of its slot fillers (ndf × fresnel × vis), at the bricks' default
parameters (or --param). Each is the eval kernel of `shadermatrix eval`.

Time: device time of one dispatch over `--samples` samples (timestamp queries
around the dispatch), median over `--repeats` dispatches (default 31). Every dispatch of a
kernel is paired with one of the Lambert kernel of the same language (order
alternating), and the ratio to Lambert is the median of the pairs' ratios, so
drift of the machine cancels. Samples: L and V uniform over the hemisphere
around random normals (every sample lit, so the whole BRDF runs).

Error: against the *exact* model the kernel approximates, in float64, from
generator/reference/ (exact.py): the same NDF, the exact dielectric Fresnel
for the same f0 (Cook & Torrance 1982; Walter et al. 2007 eq. 22) in place of
Schlick or none, and the exact separable Smith G of that NDF (Walter et al.
2007 eqs. 23, 27, 34; Beckmann's Λ for the Blinn-Phong NDF, as Walter et al.
§5.2 do) in place of Smith-Schlick, Torrance-Sparrow or the implicit G. Bricks
that approximate nothing (Lambert, the normalized Phong lobes) are compared
with their own reference: their error is float32 arithmetic. Errors are over
a jittered, stratified k⁴ grid of (L, V) over the hemisphere (k = 12: 20736
pairs) of the GLSL kernel's output on lavapipe, with the exact model evaluated
at the float32-rounded vectors the kernel gets (as in generator/eval/accuracy.py):
- `rel_rms`: cosine-weighted relative RMS error over all samples and RGB
  channels, sqrt(Σ cosθ_l (f - f*)²) / sqrt(Σ cosθ_l f*²) — the error of the
  reflected radiance under uniform light;
- `max_rel`: max |f - f*| / max(|f*|, 1e-6 sr⁻¹).
The model error alone (NumPy float64 emission of the same IR) is reported too.

Writes runtime_vs_error.json, .md and .png (time ratio against error, Pareto
front marked) under --out. A progress bar is shown on a terminal only.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

from cliargs import folder, positive  # noqa: E402

from generator import GPU_TARGETS as LANGS  # noqa: E402 (after the path)
from generator.eval.accuracy import REL_FLOOR, default_specs, hemisphere, rounded_inputs  # noqa: E402

BASELINE = "lambert"


# ------------------------------------------------------------------ what is measured

def exact_model(node) -> str:
    """What a term is compared with (for the table)."""
    if node.brick.id != "microfacet":
        return f"reference {node.canonical()}"
    ndf = dict(node.fillers)["ndf"].brick.id
    lam = "GGX" if ndf == "ggx" else "Beckmann"
    return f"D {ndf}, exact dielectric F, exact Smith G ({lam} Λ)"


def _microfacet_factors(node, g, params: dict) -> dict:
    """D, and F and G both as the kernel's bricks define them and exact, float64 per sample."""
    from generator.reference import (fresnel_dielectric_f0, lambda_beckmann, lambda_ggx, lookup,
                                     smith_g_separable)

    fill = {slot: n.brick.id for slot, n in node.fillers}
    alpha, f0 = float(params["alpha"]), np.broadcast_to(np.asarray(params["f0"], np.float64), (g.count, 3))
    lam = lambda_ggx if fill["ndf"] == "ggx" else lambda_beckmann
    return {"D": lookup("ndf", fill["ndf"])(g.NdotH, g.NxH2, alpha),
            "F": lookup("fresnel", fill["fresnel"])(f0, g.VdotH), "F_exact": fresnel_dielectric_f0(f0, g.VdotH),
            "G": lookup("visibility", fill["vis"])(g, alpha),
            "G_exact": smith_g_separable(g.NdotL, g.NdotV, alpha, lam)}


def exact_brdf(spec: str, L, V, N, T, params: dict, lib, keep: str = "") -> np.ndarray:
    """f_r of the exact model a spec approximates, float64 (N, 3); see the module docstring.

    keep="F" or "G": the kernel's own Fresnel or geometry factor (float64) stays, the rest is
    exact, so the difference to the exact model is the error of the other approximation.
    """
    from generator.matrix.permutation import parse_brdf
    from generator.reference import reference_brdf, shading_geometry

    g = shading_geometry(L, V, N, T)
    total = np.zeros((g.count, 3))
    for node in parse_brdf(spec, lib):
        if node.brick.id != "microfacet":
            sub = {k: v for k, v in params.items() if k in node.brick.params}
            total += reference_brdf(node.canonical(), L, V, N, T, sub, lib=lib)
            continue
        f = _microfacet_factors(node, g, params)
        F = f["F"] if keep == "F" else f["F_exact"]
        G = f["G"] if keep == "G" else f["G_exact"]
        with np.errstate(divide="ignore", invalid="ignore"):
            term = F * (f["D"] * G / (4.0 * g.NdotL * g.NdotV))[:, None]
        total += np.where(g.lit[:, None], term, 0.0)
    return total


def timing_samples(n: int, seed: int) -> list[np.ndarray]:
    """float32 [L, V, N, T] (n, 3): L and V uniform over the hemisphere around random normals."""
    rng = np.random.default_rng(seed)
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    a = np.where(np.abs(N[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    T = np.cross(a, N)
    T /= np.linalg.norm(T, axis=1, keepdims=True)
    B = np.cross(N, T)

    def around():
        z, phi = rng.random(n), 2.0 * np.pi * rng.random(n)
        r = np.sqrt(1.0 - z * z)
        return (r * np.cos(phi))[:, None] * T + (r * np.sin(phi))[:, None] * B + z[:, None] * N

    return [x.astype(np.float32) for x in (around(), around(), N, T)]


# ------------------------------------------------------------------ measuring

def errors(spec: str, params: dict, lib, k: int) -> dict:
    """rel_rms and max_rel of the GLSL kernel and of the float64 model against the exact model."""
    from generator.eval.evaluate import evaluate

    # A jittered k⁴ grid (N = z, T = x) as rounded to float32: the very vectors the kernel gets, and
    # the ones the exact model is evaluated at, so the error is not that of the input rounding.
    L, V, N, T = rounded_inputs(hemisphere(k, seed=1, rotate=False), "float32")
    exact = exact_brdf(spec, L, V, N, T, params, lib)
    w = np.clip(np.sum(L * N, 1), 0.0, None)[:, None]

    def rel_rms(f, ref):
        if not np.isfinite(f).all():
            return math.inf
        return float(np.sqrt(np.sum(w * (f - ref) ** 2) / np.sum(w * ref * ref)))

    out = {}
    for name, target, dtype in (("gpu", "glsl", "float32"), ("model", "numpy", "float64")):
        f = evaluate(spec, L, V, N, T, params=params, target=target, dtype=dtype, lib=lib)
        finite = np.isfinite(f).all()
        out[name] = {
            "rel_rms": rel_rms(f, exact),
            "max_rel": float(np.max(np.abs(f - exact) / np.maximum(np.abs(exact), REL_FLOOR))) if finite else math.inf,
            "nonfinite": int(np.size(f) - np.count_nonzero(np.isfinite(f))),
        }
    if "microfacet" in spec:  # attribution: only the Fresnel, or only the geometry factor, approximated
        out["fresnel_only"] = rel_rms(exact_brdf(spec, L, V, N, T, params, lib, keep="F"), exact)
        out["geometry_only"] = rel_rms(exact_brdf(spec, L, V, N, T, params, lib, keep="G"), exact)
    return out


def time_pairs(kernel, baseline, repeats: int) -> tuple[list[float], list[float]]:
    """Device seconds of `repeats` dispatches of kernel and baseline, interleaved in alternating order."""
    kernel.time(2), baseline.time(2)  # warm-up: first dispatches pay for lazy set-up in the driver
    ts, tb = [], []
    for r in range(repeats):
        if r % 2:
            tb += baseline.time(1)
            ts += kernel.time(1)
        else:
            ts += kernel.time(1)
            tb += baseline.time(1)
    return ts, tb


def measure(specs, langs, params, samples, repeats, k, lib, progress) -> dict:
    from tqdm import tqdm

    from generator.eval.evaluate import _param_block, gpu_kernel, program, resolve_params
    from generator.runtime.eval_kernel import shared_device

    device = shared_device()
    vecs = timing_samples(samples, seed=2)
    rows = {s: {"spec": program(s, lib).spec, "time_ms": {}, "ratio": {}} for s in specs}
    bar = tqdm(total=len(specs) * len(langs) + len(specs), disable=not progress, unit="kernel")
    for lang in langs:
        base = gpu_kernel(BASELINE, lang, lib, device)
        bep = program(BASELINE, lib)
        base.load(vecs, _param_block(bep, resolve_params(bep, {})))
        for s in specs:
            ep = program(s, lib)
            bar.set_description(f"{lang} {s}")
            kern = gpu_kernel(s, lang, lib, device)
            own = {k_: v for k_, v in params.items() if k_ in ep.params}
            kern.load(vecs, _param_block(ep, resolve_params(ep, own)))
            ts, tb = time_pairs(kern, base, repeats)
            rows[s]["time_ms"][lang] = 1e3 * float(np.median(ts))
            ratios = np.asarray(ts) / np.asarray(tb)
            rows[s]["ratio"][lang] = float(np.median(ratios))
            rows[s].setdefault("ratio_quartiles", {})[lang] = [float(q) for q in np.percentile(ratios, [25, 75])]
            rows[s].setdefault("time_ms_min", {})[lang] = 1e3 * float(np.min(ts))
            if kern is not base:
                kern.release()
            bar.update()
        base.release()
    from generator.matrix.permutation import parse_brdf
    for s in specs:
        bar.set_description(f"error {s}")
        ep = program(s, lib)
        own = {k_: v for k_, v in params.items() if k_ in ep.params}
        rows[s]["params"] = {n: (v[0] if len(v) == 1 else v) for n, v in resolve_params(ep, own).items()}
        rows[s]["exact"] = "; ".join(exact_model(n) for n in parse_brdf(s, lib))
        rows[s]["error"] = errors(s, rows[s]["params"], lib, k)
        bar.update()
    bar.close()
    return {"device": device.name, "rows": list(rows.values())}


# ------------------------------------------------------------------ reporting

def pareto(points: list[tuple[float, float]]) -> list[bool]:
    """True for points no other point beats in both coordinates (lower is better in both)."""
    return [not any((q[0] <= p[0] and q[1] <= p[1]) and q != p for q in points) for p in points]


def term_label(spec: str) -> str:
    """'schlick / smith_schlick' for a microfacet spec: its Fresnel and geometry fillers."""
    fill = dict(part.split("=") for part in spec[spec.index("(") + 1: -1].split(",")) if "(" in spec else {}
    return f"{fill.get('fresnel', '?')} / {fill.get('vis', '?')}" if fill else spec


def mark_pareto(report: dict) -> None:
    """Pareto fronts within each group of kernels that approximate the same exact model.

    Only groups with more than one kernel have a front; a brick that approximates
    nothing (its error is float32 arithmetic) is compared with nothing.
    """
    lang = report["langs"][0]
    groups: dict[str, list[dict]] = {}
    for r in report["rows"]:
        groups.setdefault(r["exact"], []).append(r)
    for rows in groups.values():
        front = pareto([(r["ratio"][lang], r["error"]["gpu"]["rel_rms"]) for r in rows])
        for r, f in zip(rows, front):
            r["pareto"] = f and len(rows) > 1


def markdown(report: dict) -> str:
    langs = report["langs"]
    env = report["environment"]
    lines = [
        "# Run time against error (lavapipe)",
        "",
        f"Generated by `benchmarks/runtime_vs_error.py` on {env['device']} ({env['cpus']} CPUs, "
        f"LP_NUM_THREADS={env['lp_num_threads']}); {report['samples']:,} samples per dispatch, median of "
        f"{report['repeats']} dispatches (timestamp queries). `× Lambert`: median ratio of paired dispatches "
        f"with the Lambert kernel of the same language. Error: the GLSL kernel on lavapipe against the exact "
        f"model in float64 at the kernel's float32 inputs over {report['error_samples']:,} stratified "
        f"hemisphere pairs (cosine-weighted relative RMS; max relative with a floor of {REL_FLOOR:g} sr⁻¹); `model`: the float64 emission of "
        f"the same IR, i.e. the approximation alone; `F alone` / `G alone`: float64 error when only the "
        f"kernel's Fresnel / only its geometry factor is approximated and the rest is exact. Pareto: among the kernels approximating the same "
        f"exact model, no other is both faster ({langs[0].upper()} ratio) and more accurate. Load average "
        f"(1 min) at start / end: {env['load_average'][0]:.2f} / {env['load_average'][1]:.2f}. Parameters: the bricks' defaults"
        + (f" with {report['params']}" if report["params"] else "") + ".",
        "",
        "| kernel | exact model | " + " | ".join(f"{l.upper()} ms" for l in langs) + " | "
        + " | ".join(f"× Lambert {l.upper()}" for l in langs)
        + " | rel RMS (GPU) | max rel (GPU) | rel RMS (model) | F alone | G alone | Pareto |",
        "|---|---|" + "---:|" * (2 * len(langs) + 5) + ":---:|",
    ]
    for r in report["rows"]:
        e = r["error"]
        errs = ([f"{e['gpu']['rel_rms']:.2e}", f"{e['gpu']['max_rel']:.2e}", f"{e['model']['rel_rms']:.2e}"]
                + [f"{e[k]:.2e}" if k in e else "" for k in ("fresnel_only", "geometry_only")])
        lines.append(f"| `{r['spec']}` | {r['exact']} | "
                     + " | ".join(f"{r['time_ms'][l]:.2f}" for l in langs) + " | "
                     + " | ".join(f"{r['ratio'][l]:.2f}" for l in langs) + " | "
                     + " | ".join(errs) + f" | {'●' if r.get('pareto') else ''} |")
    iqr = [q[1] - q[0] for r in report["rows"] for q in r["ratio_quartiles"].values()]
    lines += ["", f"Spread of the paired ratios: median interquartile range {np.median(iqr):.2f} "
              f"(max {np.max(iqr):.2f}); differences in the `× Lambert` columns smaller than that are noise. "
              "Absolute times follow the machine's load; the ratios are paired to cancel it."]
    return "\n".join(lines) + "\n"


def plot(report: dict, path: Path) -> None:
    """One panel per exact model with approximations (the microfacet NDFs): time ratio against error."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lang = report["langs"][0]
    groups: dict[str, list[dict]] = {}
    for r in report["rows"]:
        groups.setdefault(r["exact"], []).append(r)
    multi = {k: v for k, v in groups.items() if len(v) > 1}
    if not multi:
        return
    fig, axes = plt.subplots(1, len(multi), figsize=(5.2 * len(multi), 5.4), dpi=120, sharey=True, squeeze=False)
    for ax, (exact, members) in zip(axes[0], sorted(multi.items())):
        x = np.array([r["ratio"][lang] for r in members])
        y = np.array([max(r["error"]["gpu"]["rel_rms"], 1e-9) for r in members])
        front = np.array([bool(r.get("pareto")) for r in members])
        ax.scatter(x[~front], y[~front], s=30, color="tab:gray", zorder=3, label="kernel")
        ax.scatter(x[front], y[front], s=45, color="tab:red", zorder=4, label="Pareto front")
        order = np.argsort(x[front])
        ax.step(x[front][order], y[front][order], where="post", color="tab:red", lw=1.2, zorder=2)
        for xi, yi, r in zip(x, y, members):
            ax.annotate(term_label(r["spec"]), (xi, yi), textcoords="offset points", xytext=(4, 3), fontsize=7)
        ndf, rest = exact.split(", ", 1)
        ax.set_title(f"microfacet, {ndf.replace('D ', 'D = ')}\nagainst {rest}", fontsize=9)
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlabel(f"time × Lambert ({lang.upper()}, lavapipe)")
    axes[0][0].set_ylabel("error vs exact model (cosine-weighted relative RMS)")
    axes[0][0].legend(loc="lower left", fontsize=8)
    exact_only = [r for r in report["rows"] if len(groups[r["exact"]]) == 1]
    note = "Bricks without approximation (float32 error only): " + ", ".join(
        f"{r['spec']} ×{r['ratio'][lang]:.2f} ({r['error']['gpu']['rel_rms']:.0e})" for r in exact_only)
    fig.text(0.01, 0.01, note + f". Labels: Fresnel / geometry factor. {report['samples']:,} samples per dispatch.",
             fontsize=7)
    fig.suptitle("Run time against error: microfacet approximations on lavapipe", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    tmp = path.with_suffix(".tmp.png")
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--samples", type=positive, default=1 << 20, help="samples per dispatch (default 2^20)")
    ap.add_argument("--repeats", type=positive, default=31, help="timed dispatches per kernel (default 31)")
    ap.add_argument("--languages", default=",".join(LANGS), help="comma-separated, first one is plotted")
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE", help="as in shadermatrix eval")
    ap.add_argument("--grid", type=positive, default=12, help="k of the k⁴ error grid (default 12)")
    ap.add_argument("--out", type=folder, default=str(REPO / "benchmarks" / "results"),
                    help="the folder the table, JSON and plot go into (default benchmarks/results)")
    args = ap.parse_args(argv)

    from generator import __version__
    from generator.library.bricks import load_library
    from generator.io import atomic_write
    from generator.cli.commands.eval import parse_params

    lib = load_library()
    langs = tuple(args.languages.split(","))
    params = parse_params(args.param)
    specs = default_specs(lib)
    load_start = os.getloadavg()[0]
    measured = measure(specs, langs, params, args.samples, args.repeats, args.grid, lib, sys.stderr.isatty())
    report = {
        "generator": __version__,
        "environment": {"device": measured["device"], "cpus": os.cpu_count(),
                        "lp_num_threads": os.environ.get("LP_NUM_THREADS", "default"),
                        "python": platform.python_version(), "numpy": np.__version__,
                        "load_average": [load_start, os.getloadavg()[0]]},
        "samples": args.samples, "repeats": args.repeats, "error_samples": args.grid ** 4,
        "langs": list(langs), "params": params, "rows": measured["rows"],
    }
    mark_pareto(report)
    out = Path(args.out)
    atomic_write(out / "runtime_vs_error.json", (json.dumps(report, indent=2) + "\n").encode())
    atomic_write(out / "runtime_vs_error.md", markdown(report).encode())
    plot(report, out / "runtime_vs_error.png")
    print(markdown(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
