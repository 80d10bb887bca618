"""Run time against error: every approximation a brick makes, timed on lavapipe against the exact model it approximates.

    .venv/bin/python benchmarks/runtime_vs_error.py [--samples 1048576] [--repeats 31]
        [--languages glsl,hlsl,wgsl] [--grid 12] [--out benchmarks/results]

Two parts.

**Approximations against their exact model** (the plot). A study holds the
kernels that approximate one exact model, with everything else held fixed, so
the error on the y-axis is the approximation's and never a choice between
models (an implicit or Kelemen geometry term is another model, not an
approximation of Smith's; it appears in the second part only):

- Fresnel: Schlick (Schlick 1994 eq. 15) and the spherical Gaussian
  (Gotanda 2014 eq. 3) against the exact dielectric Fresnel written with f0
  (Gotanda eq. 2), inside microfacet(ndf=ggx, vis=smith_ggx_height_correlated);
- Smith for GGX: Smith-Schlick with k = α/2 (Karis) and with k = α·sqrt(2/π)
  (Schlick's Beckmann match) against the exact separable Smith G of GGX
  (Walter et al. 2007 eq. 34), inside microfacet(ndf=ggx, fresnel=schlick);
- Smith for Beckmann: Smith-Schlick (k = α·sqrt(2/π)) and the `smith_beckmann`
  brick against the exact Beckmann Λ with erfc (Walter et al. 2007 eq. 27),
  inside microfacet(ndf=beckmann, fresnel=schlick);
- diffuse: Lambert, the Oren-Nayar family and Gotanda's fit (eq. 8) against the
  microfacet diffuse model Gotanda integrates (his eq. 4 and footnote 3: GGX D,
  Schlick-type F_diff, height-correlated Smith G on Lambertian facets),
  computed by quadrature (generator/reference/diffuse.py), at σ = α = 0.5 (Gotanda's fit reads α),
  f0 = 0.04, ρ_d = 1.

Time: device time of one dispatch over `--samples` samples (timestamp queries),
each dispatch of a kernel paired with one of the study's exact kernel (order
alternating; for the diffuse study, with Lambert: its exact model has no
kernel), and the ratio is the median of the pairs' ratios, so drift of the
machine cancels; the error bar is the pairs' interquartile range. Error: the
cosine-weighted relative RMS sqrt(Σ cosθ_l (f − f*)²) / sqrt(Σ cosθ_l f*²) of the
first language's kernel on lavapipe against the exact model in float64, over a
jittered stratified k⁴ grid of (L, V) (at the kernel's float32 inputs); `model`
is the same for the float64 emission of the kernel (the approximation alone,
without float32 arithmetic). Pareto front: a kernel is dominated when another
is more accurate and not slower beyond the noise (their interquartile ranges
overlap or it is faster); the front is drawn only when two or more kernels are
on it, that is, when speed really buys error.

**Every brick** (the table): each spec of `shadermatrix accuracy`'s default set,
timed paired with Lambert, with its float32 error against its own float64
reference (the arithmetic alone).

Writes runtime_vs_error.json, .md and .png under --out. A progress bar is shown on a terminal only.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

from cliargs import folder, languages, positive  # noqa: E402

from generator import GPU_TARGETS  # noqa: E402 (after the path)
from generator.eval.accuracy import REL_FLOOR, default_specs, hemisphere, rounded_inputs  # noqa: E402

LAMBERT = "lambert"
DIFFUSE_SIGMA = 0.5


@dataclass
class Study:
    """Kernels that approximate one exact model; `exact` is a spec whose float64 reference is that model, or
    None where the model is the quadrature of `exact_fn`."""

    name: str
    title: str
    kernels: dict[str, str]  # label -> spec
    exact: str | None = None
    exact_label: str = ""
    params: dict = field(default_factory=dict)
    exact_fn: object = None  # (L, V, N) -> (n, 3) float64, for models without a brick

    @property
    def baseline(self) -> str:
        return self.exact or LAMBERT


def _microfacet(ndf: str, fresnel: str, vis: str) -> str:
    return f"microfacet(ndf={ndf},fresnel={fresnel},vis={vis})"


def _diffuse_exact(L, V, N, params: dict) -> np.ndarray:
    """Gotanda's microfacet diffuse model at the study's roughness (α = σ) and f0, times ρ_d."""
    from generator.reference.diffuse import microfacet_diffuse
    nl, nv = np.sum(L * N, 1), np.clip(np.sum(V * N, 1), 1e-4, 1.0)
    lp, vp = L - nl[:, None] * N, V - np.sum(V * N, 1)[:, None] * N
    d = np.sqrt(np.sum(lp * lp, 1) * np.sum(vp * vp, 1))
    cp = np.where(d > 0, np.sum(lp * vp, 1) / np.where(d > 0, d, 1.0), 0.0)
    f = np.where(nl > 0, microfacet_diffuse(np.clip(nl, 1e-6, 1.0), nv, cp, params["alpha"], params["f0"][0]), 0.0)
    return f[:, None] * np.asarray(params["rho_d"], np.float64)[None, :]


def studies(lib) -> tuple[list[Study], list[str]]:
    """The studies whose bricks the library holds, and a note per study left out (a brick missing)."""
    s = [
        Study("fresnel", "Fresnel, in microfacet(ndf=ggx, vis=smith_ggx_height_correlated)",
              {"schlick": _microfacet("ggx", "schlick", "smith_ggx_height_correlated"),
               "spherical_gaussian": _microfacet("ggx", "spherical_gaussian", "smith_ggx_height_correlated")},
              exact=_microfacet("ggx", "dielectric_exact", "smith_ggx_height_correlated"),
              exact_label="exact dielectric Fresnel (dielectric_exact)"),
        Study("smith_ggx", "Smith G for GGX, in microfacet(ndf=ggx, fresnel=schlick)",
              {"smith_schlick_ggx (k = α/2)": _microfacet("ggx", "schlick", "smith_schlick_ggx"),
               "smith_schlick (k = α√(2/π))": _microfacet("ggx", "schlick", "smith_schlick")},
              exact=_microfacet("ggx", "schlick", "smith_ggx_separable"),
              exact_label="exact separable Smith G (smith_ggx_separable)"),
        Study("smith_beckmann", "Smith G for Beckmann, in microfacet(ndf=beckmann, fresnel=schlick)",
              {"smith_schlick (k = α√(2/π))": _microfacet("beckmann", "schlick", "smith_schlick")},
              exact=_microfacet("beckmann", "schlick", "smith_beckmann"),
              exact_label="exact Beckmann Λ with erfc (the reference of smith_beckmann)"),
        Study("diffuse", f"Diffuse at σ = α = {DIFFUSE_SIGMA}, f0 = 0.04, ρ_d = 1",
              {"lambert": "lambert", "oren_nayar": "oren_nayar", "oren_nayar_simplified": "oren_nayar_simplified",
               "oren_nayar_improved": "oren_nayar_improved", "oren_nayar_fresnel": "oren_nayar_fresnel",
               "gotanda_fitted": "gotanda_fitted"},
              exact_label="Gotanda's microfacet diffuse model (eq. 4, quadrature)",
              params={"sigma": DIFFUSE_SIGMA, "alpha": DIFFUSE_SIGMA, "f0": [0.04] * 3, "rho_d": [1.0] * 3},
              exact_fn=_diffuse_exact),
    ]
    from generator.matrix.permutation import SpecError, parse_brdf
    have, notes = [], []
    for st in s:
        specs = list(st.kernels.values()) + ([st.exact] if st.exact else [])
        missing = []
        for spec in specs:
            try:
                parse_brdf(spec, lib)
            except SpecError:  # a brick this checkout lacks
                missing.append(spec)
        if missing:
            notes.append(f"{st.name}: left out, no brick for {', '.join(missing)}")
        else:
            have.append(st)
    return have, notes


def _once(fn):
    """fn(L, V, N) computed on its first call only: every kernel of a study is measured on the same grid."""
    memo: dict = {}

    def exact(L, V, N):
        if "f" not in memo:
            memo["f"] = fn(L, V, N)
        return memo["f"]
    return exact


def own_params(spec: str, params: dict, lib) -> dict:
    from generator.eval.accuracy import declared_params
    declared = declared_params(spec, lib)
    return {k: v for k, v in params.items() if k in declared}


# ------------------------------------------------------------------ timing

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


class Timer:
    """Paired timing of kernels against baselines, kernels compiled once per language."""

    def __init__(self, lib, samples: int, repeats: int):
        from generator.runtime.eval_kernel import shared_device
        self.lib, self.repeats = lib, repeats
        self.device = shared_device()
        self.vecs = timing_samples(samples, seed=2)

    def kernel(self, spec: str, lang: str, params: dict):
        from generator.eval.evaluate import _param_block, gpu_kernel, program, resolve_params
        ep = program(spec, self.lib)
        k = gpu_kernel(spec, lang, self.lib, self.device)
        k.load(self.vecs, _param_block(ep, resolve_params(ep, own_params(spec, params, self.lib))))
        return k

    def ratio(self, spec: str, baseline: str, lang: str, params: dict) -> dict:
        base = self.kernel(baseline, lang, params)
        kern = base if spec == baseline else self.kernel(spec, lang, params)
        ts, tb = time_pairs(kern, base, self.repeats)
        ratios = np.asarray(ts) / np.asarray(tb)
        out = {"ratio": float(np.median(ratios)), "q25": float(np.percentile(ratios, 25)),
               "q75": float(np.percentile(ratios, 75)), "ms": 1e3 * float(np.median(ts))}
        if kern is not base:
            kern.release()
        base.release()
        return out


# ------------------------------------------------------------------ errors

def _rel_rms(f, ref, w) -> float:
    if not np.isfinite(f).all():
        return math.inf
    return float(np.sqrt(np.sum(w * (f - ref) ** 2) / np.sum(w * ref * ref)))


def _max_rel(f, ref) -> float:
    if not np.isfinite(f).all():
        return math.inf
    return float(np.max(np.abs(f - ref) / np.maximum(np.abs(ref), REL_FLOOR)))


def errors(spec: str, exact, params: dict, lib, k: int, lang: str) -> dict:
    """The kernel (lavapipe, float32) and its float64 emission against `exact`: a spec whose reference is the
    exact model, or a function (L, V, N) -> f."""
    from generator.eval.evaluate import evaluate
    from generator.reference import reference_brdf

    # A jittered k⁴ grid (N = z, T = x) as rounded to float32: the very vectors the kernel gets, and
    # the ones the exact model is evaluated at, so the error is not that of the input rounding.
    L, V, N, T = rounded_inputs(hemisphere(k, seed=1, rotate=False), "float32")
    if callable(exact):
        ref = exact(L, V, N)
    else:
        ref = reference_brdf(exact, L, V, N, T, own_params(exact, params, lib), lib=lib)
    w = np.clip(np.sum(L * N, 1), 0.0, None)[:, None]
    mine = own_params(spec, params, lib)
    out = {}
    for name, target, dtype in (("gpu", lang, "float32"), ("model", "numpy", "float64")):
        f = evaluate(spec, L, V, N, T, params=mine, target=target, dtype=dtype, lib=lib)
        out[name] = {"rel_rms": _rel_rms(f, ref, w), "max_rel": _max_rel(f, ref)}
    return out


# ------------------------------------------------------------------ the front

def dominated(p: dict, q: dict) -> bool:
    """q dominates p: more accurate, and not slower beyond the noise (interquartile ranges overlap, or faster)."""
    return q["error"] < p["error"] and q["q25"] <= p["q75"]


def front(points: list[dict]) -> list[bool]:
    return [not any(dominated(p, q) for q in points if q is not p) for p in points]


# ------------------------------------------------------------------ measuring

def measure(lib, langs, samples, repeats, k, progress) -> dict:
    from tqdm import tqdm

    found, notes = studies(lib)
    every = default_specs(lib)
    timer = Timer(lib, samples, repeats)
    total = sum((len(s.kernels) + (1 if s.exact else 0)) * len(langs) for s in found) + len(every) * len(langs)
    bar = tqdm(total=total, disable=not progress, unit="kernel")
    out_studies = []
    for st in found:
        rows = []
        exact = st.exact if st.exact_fn is None else _once(lambda L, V, N, st=st: st.exact_fn(L, V, N, st.params))
        members = list(st.kernels.items()) + ([("exact model's kernel", st.exact)] if st.exact else [])
        for label, spec in members:
            row = {"label": label, "spec": spec, "exact_kernel": spec == st.exact, "time": {}}
            for lang in langs:
                bar.set_description(f"{st.name} {lang} {label}")
                row["time"][lang] = timer.ratio(spec, st.baseline, lang, st.params)
                bar.update()
            row["errors"] = errors(spec, exact, st.params, lib, k, langs[0])
            rows.append(row)
        pts = [{"error": r["errors"]["gpu"]["rel_rms"], **r["time"][langs[0]]} for r in rows]
        for r, on in zip(rows, front(pts)):
            r["front"] = on
        out_studies.append({"name": st.name, "title": st.title, "exact": st.exact_label, "baseline": st.baseline,
                            "params": st.params, "rows": rows})
    bricks = []
    for spec in every:
        row = {"spec": spec, "time": {}}
        for lang in langs:
            bar.set_description(f"{lang} {spec}")
            row["time"][lang] = timer.ratio(spec, LAMBERT, lang, {})
            bar.update()
        row["errors"] = errors(spec, spec, {}, lib, k, langs[0])
        bricks.append(row)
    bar.close()
    return {"device": timer.device.name, "studies": out_studies, "bricks": bricks, "notes": notes}


# ------------------------------------------------------------------ reporting

def markdown(report: dict) -> str:
    langs = report["langs"]
    env = report["environment"]
    lines = [
        "# Run time against error (lavapipe)", "",
        f"Generated by `benchmarks/runtime_vs_error.py` on {env['device']} ({env['cpus']} CPUs, "
        f"LP_NUM_THREADS={env['lp_num_threads']}); {report['samples']:,} samples per dispatch, "
        f"{report['repeats']} paired dispatches per kernel and language (timestamp queries). Time: the median ratio "
        "of paired dispatches with the study's exact kernel (× exact; diffuse: × Lambert), in brackets the "
        "pairs' interquartile range — two kernels whose ranges overlap are equally fast as far as this machine "
        f"can tell. Error: cosine-weighted relative RMS against the exact model in float64 over "
        f"{report['error_samples']:,} stratified hemisphere pairs, of the {langs[0].upper()} kernel on lavapipe "
        "(float32) and of the float64 emission (`model`: the approximation alone); max rel with a floor of "
        f"{REL_FLOOR:g} sr⁻¹. Front ●: no other kernel is more accurate without being slower beyond the noise. "
        f"Load average (1 min) at start / end: {env['load_average'][0]:.2f} / {env['load_average'][1]:.2f}.", ""]
    for st in report["studies"]:
        unit = "× exact" if st["baseline"] != LAMBERT else "× Lambert"
        lines += [f"## {st['title']}", "", f"Exact model: {st['exact']}."
                  + (f" Parameters: {', '.join(f'{k} = {v}' for k, v in st['params'].items())}." if st["params"]
                     else " Parameters: the bricks' defaults."), "",
                  "| kernel | " + " | ".join(f"{l.upper()} {unit}" for l in langs)
                  + " | rel RMS (GPU) | max rel (GPU) | rel RMS (model) | front |",
                  "|---|" + "---:|" * (len(langs) + 3) + ":---:|"]
        for r in st["rows"]:
            e = r["errors"]
            lines.append(f"| {r['label']} | " + " | ".join(
                f"{r['time'][l]['ratio']:.2f} [{r['time'][l]['q25']:.2f}–{r['time'][l]['q75']:.2f}]" for l in langs)
                + f" | {e['gpu']['rel_rms']:.2e} | {e['gpu']['max_rel']:.2e} | {e['model']['rel_rms']:.2e} | "
                + ("●" if r["front"] else "") + " |")
        lines.append("")
    for note in report["notes"]:
        lines += [f"Left out: {note}.", ""]
    lines += ["## Every brick: time × Lambert and float32 error against its own reference", "",
              "Each spec of `shadermatrix accuracy`'s default set at its bricks' defaults; the error is float32 "
              "arithmetic alone (the model is its own reference), so it measures the brick's implementation, not "
              "its choice of model.", "",
              "| spec | " + " | ".join(f"{l.upper()} × Lambert" for l in langs) + " | rel RMS (GPU) | max rel (GPU) |",
              "|---|" + "---:|" * (len(langs) + 2)]
    for r in report["bricks"]:
        e = r["errors"]["gpu"]
        lines.append(f"| `{r['spec']}` | " + " | ".join(
            f"{r['time'][l]['ratio']:.2f} [{r['time'][l]['q25']:.2f}–{r['time'][l]['q75']:.2f}]" for l in langs)
            + f" | {e['rel_rms']:.2e} | {e['max_rel']:.2e} |")
    iqr = [t["q75"] - t["q25"] for r in report["bricks"] for t in r["time"].values()]
    lines += ["", f"Paired-ratio interquartile range over every brick and language: median {np.median(iqr):.3f}, "
              f"max {np.max(iqr):.3f}. Absolute times follow the machine's load; the ratios are paired to cancel it."]
    return "\n".join(lines) + "\n"


def plot(report: dict, path: Path) -> None:
    """One panel per study: time ratio (error bar: the pairs' interquartile range) against error, log scale."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lang = report["langs"][0]
    sts = report["studies"]
    cols = min(2, len(sts))
    rows_n = math.ceil(len(sts) / cols)
    fig, axes = plt.subplots(rows_n, cols, figsize=(7.0 * cols, 5.0 * rows_n), dpi=110, squeeze=False)
    for ax, st in zip(axes.flat, sts):
        rs = st["rows"]
        x = np.array([r["time"][lang]["ratio"] for r in rs])
        lo = x - np.array([r["time"][lang]["q25"] for r in rs])
        hi = np.array([r["time"][lang]["q75"] for r in rs]) - x
        y = np.array([max(r["errors"]["gpu"]["rel_rms"], 1e-9) for r in rs])
        on = np.array([r["front"] for r in rs])
        ex = np.array([r["exact_kernel"] for r in rs])
        for sel, color, label in ((~on & ~ex, "tab:gray", "approximation"), (on & ~ex, "tab:red", "on the front"),
                                  (ex, "tab:blue", "exact model's kernel (float32 error only)")):
            if sel.any():
                ax.errorbar(x[sel], y[sel], xerr=[lo[sel], hi[sel]], fmt="o", ms=6, color=color, capsize=3,
                            label=label, zorder=3)
        if on.sum() >= 2:  # a front is drawn only where speed buys error beyond the noise
            order = np.argsort(x[on])
            ax.step(x[on][order], y[on][order], where="post", color="tab:red", lw=1.0, zorder=2)
        else:
            ax.text(0.02, 0.02, "no front: the more accurate kernels are not slower beyond the noise",
                    transform=ax.transAxes, fontsize=7, color="0.3")
        # points that coincide on the plot (equal to 2 % in time and error) share one label; labels alternate
        # sides down the error axis, so close points stay legible
        groups: list[list[int]] = []
        for i in np.argsort(y):
            near = next((g for g in groups if abs(x[g[0]] - x[i]) < 0.02 * max(x[g[0]], 1e-9)
                         and abs(np.log10(y[g[0]] / y[i])) < 0.01), None)
            (near.append(i) if near is not None else groups.append([i]))
        placed = []  # the labels' boxes so far: a label takes the first offset whose box overlaps none
        renderer = fig.canvas.get_renderer()
        offsets = [(8, 4, "left"), (-8, -10, "right"), (8, -12, "left"), (-8, 6, "right"), (8, 14, "left"),
                   (-8, -20, "right"), (8, -22, "left"), (-8, 16, "right")]
        for rank, g in enumerate(groups):
            for k in range(len(offsets)):
                dx, dy, ha = offsets[(rank + k) % len(offsets)]
                a = ax.annotate(" = ".join(rs[i]["label"] for i in g), (x[g[0]], y[g[0]]), textcoords="offset points",
                                xytext=(dx, dy), ha=ha, fontsize=7)
                box = a.get_window_extent(renderer)
                if not any(box.overlaps(b) for b in placed) or k == len(offsets) - 1:
                    placed.append(box)
                    break
                a.remove()
        unit = "exact kernel" if st["baseline"] != LAMBERT else "Lambert"
        ax.set_title(f"{st['title']}\nagainst: {st['exact']}", fontsize=9)
        ax.set_yscale("log")
        span = max(np.max(x + hi) - np.min(x - lo), 0.1)
        ax.set_xlim(np.min(x - lo) - 0.35 * span, np.max(x + hi) + 0.35 * span)
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlabel(f"time × {unit} ({lang.upper()} on lavapipe; bar: interquartile range of the pairs)", fontsize=8)
        ax.set_ylabel("error vs exact model (cos-weighted rel. RMS)", fontsize=8)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, fontsize=7, frameon=False)
    for ax in list(axes.flat)[len(sts):]:
        ax.set_axis_off()
    fig.suptitle(f"Run time against error: approximations against the model they approximate "
                 f"({report['samples']:,} samples per dispatch)", fontsize=11)
    fig.tight_layout()
    tmp = path.with_suffix(".tmp.png")
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--samples", type=positive, default=1 << 20, help="samples per dispatch (default 2^20)")
    ap.add_argument("--repeats", type=positive, default=31, help="timed dispatch pairs per kernel (default 31)")
    ap.add_argument("--languages", type=languages, default=",".join(GPU_TARGETS),
                    help="comma-separated, from glsl, hlsl, wgsl; the first one is plotted and its errors measured")
    ap.add_argument("--grid", type=positive, default=12, help="k of the k⁴ error grid (default 12)")
    ap.add_argument("--out", type=folder, default=str(REPO / "benchmarks" / "results"),
                    help="the folder the table, JSON and plot go into (default benchmarks/results)")
    args = ap.parse_args(argv)

    from generator import __version__
    from generator.io import atomic_write, show_progress
    from generator.library.bricks import load_library

    lib = load_library()
    load_start = os.getloadavg()[0]
    measured = measure(lib, args.languages, args.samples, args.repeats, args.grid, show_progress())
    report = {
        "generator": __version__,
        "environment": {"device": measured["device"], "cpus": os.cpu_count(),
                        "lp_num_threads": os.environ.get("LP_NUM_THREADS", "default"),
                        "python": platform.python_version(), "numpy": np.__version__,
                        "load_average": [load_start, os.getloadavg()[0]]},
        "samples": args.samples, "repeats": args.repeats, "error_samples": args.grid ** 4,
        "langs": list(args.languages), "studies": measured["studies"], "bricks": measured["bricks"],
        "notes": measured["notes"],
    }
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / "runtime_vs_error.json", (json.dumps(report, indent=2) + "\n").encode())
    atomic_write(out / "runtime_vs_error.md", markdown(report).encode())
    plot(report, out / "runtime_vs_error.png")
    print(markdown(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
