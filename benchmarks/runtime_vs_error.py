"""Run time against error: every approximation a brick makes, timed on lavapipe against the exact model it approximates.

    .venv/bin/python benchmarks/runtime_vs_error.py [--samples 1048576] [--repeats 31]
        [--languages glsl,hlsl,wgsl] [--grid 12] [--out benchmarks/results]

Two parts.

**Approximations against their exact model** (the plot). A study holds the
kernels that approximate one exact model, with everything else held fixed, so
the error on the y-axis is the approximation's and never a choice between
models (an implicit or Kelemen geometry term is another model, not an
approximation of Smith's; it appears in the second part only):

- Fresnel: Schlick (Schlick 1994 eq. 15), the spherical Gaussian
  (Gotanda 2014 eq. 3) and the `fresnel_ramp` table (Hoffman & Baker 2006,
  "Fresnel Ramps": the exact dielectric R_F baked over (1 − cos α_h, √f0),
  three bilinear taps) against the exact dielectric Fresnel written with f0
  (Gotanda eq. 2), inside microfacet(ndf=ggx, vis=smith_ggx_height_correlated);
- Smith for GGX: Smith-Schlick with k = α/2 (Karis) and with k = α·sqrt(2/π)
  (Schlick's Beckmann match) against the exact separable Smith G of GGX
  (Walter et al. 2007 eq. 34), inside microfacet(ndf=ggx, fresnel=schlick);
- Smith for Beckmann: Smith-Schlick (k = α·sqrt(2/π)) and the `smith_beckmann`
  brick against the exact Beckmann Λ with erfc (Walter et al. 2007 eq. 27),
  inside microfacet(ndf=beckmann, fresnel=schlick);
- diffuse: Lambert, the Oren-Nayar family (with its factored form) and
  Gotanda's fit (eq. 8) against the microfacet diffuse model Gotanda integrates
  (his eq. 4 and footnote 3: GGX D, Schlick-type F_diff, height-correlated Smith G
  on Lambertian facets), computed by quadrature (generator/reference/diffuse.py),
  at σ = α = 0.5 (Gotanda's fit reads α), f0 = 0.04, ρ_d = 1;
- factored against direct (Hoffman & Baker 2006, "BRDF Costs": each model
  direct and factored into lookup tables the generator bakes from the float64
  reference): one study per pair, since each pair has its own exact model —
  blinn_phong_factored against blinn_phong_normalized, banks_factored against
  banks, ashikhmin_shirley_factored against ashikhmin_shirley,
  ashikhmin_shirley_diffuse_factored against ashikhmin_shirley_diffuse,
  oren_nayar_factored against oren_nayar, each at the direct brick's default
  parameters (the factored brick's are the same); the direct brick's kernel is
  the exact kernel, so time is × direct;
- measured: `homomorphic_factorization` (McCool et al. 2001: three cube-map
  taps p(ω_i) q(ω_h) p(ω_o), fitted by the generator in log space) against the
  BRDF it factors, direct `ashikhmin_shirley` at the fit's parameters
  (generator/reference/specular.py HOMOMORPHIC_TARGET), beside
  ashikhmin_shirley_factored at the same parameters.

The hand-painted bricks (ndf_map, ndf_map_anisotropic, ndf_fresnel_map) have no
analytic model to approximate (the painting is their reference): they are in the
second part only.

Time: device time of one dispatch over `--samples` samples (timestamp queries),
each dispatch of a kernel paired with one of the study's exact kernel (order
alternating; for the diffuse study, with Lambert: its exact model has no
kernel), and the ratio is the median of the pairs' ratios, so drift of the
machine cancels; the error bar is the pairs' interquartile range. A kernel that
samples baked tables gets them as eval does (eval.evaluate.resolve_textures),
uploaded and bound once by `load`, before the warm-up: the timed dispatches
sample them and upload nothing. Error: the
cosine-weighted relative RMS sqrt(Σ cosθ_l (f − f*)²) / sqrt(Σ cosθ_l f*²) of the
first language's kernel on lavapipe against the exact model in float64, over a
jittered stratified k⁴ grid of (L, V) (at the kernel's float32 inputs); `model`
is the same for the float64 emission of the kernel (the approximation alone,
without float32 arithmetic; a table's texels are the same in both). Pareto front:
a kernel is dominated when another is more accurate and not slower beyond the
noise (their interquartile ranges overlap or it is faster); the front is drawn
only when two or more kernels are on it, that is, when speed really buys error.

**Every brick** (the table): each spec of `shadermatrix accuracy`'s default set,
timed paired with Lambert, with its float32 error against its own float64
reference (the arithmetic alone; for a brick that samples baked tables, its
reference is the model the tables are baked from, so the error is the table's).

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
    direct: bool = False  # the exact kernel is the direct form of factored kernels: time is "× direct"

    @property
    def baseline(self) -> str:
        return self.exact or LAMBERT

    @property
    def unit(self) -> str:
        """What the time ratio is relative to."""
        return "Lambert" if not self.exact else "direct" if self.direct else "exact"


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


def _tables(spec: str, lib) -> str:
    """The baked tables a spec samples, as "W×H format" (cube maps "W×H cube format"; the same table
    declared twice counted "2 × ..."), for its label; "" for a spec that samples none."""
    from collections import Counter

    from generator.eval.evaluate import program
    seen = Counter()
    for _n, ty, d in program(spec, lib).textures:
        w, h = (list(d.get("size", [])) + [1, 1])[:2]
        seen[f"{w}×{h}{' cube' if ty.name == 'texturecube' else ''} {d.get('format', '?')}"] += 1
    return ", ".join(t if c == 1 else f"{c} × {t}" for t, c in seen.items())


def _factored(name: str, title: str, factored: str, direct: str, params: dict) -> Study:
    """A factored brick against its direct form (its reference), both at `params`."""
    return Study(name, f"{title}: factored against direct", {factored: factored},
                 exact=direct, exact_label=f"{direct} (direct, ALU only)", params=params, direct=True)


def _homomorphic_params() -> dict:
    """The parameters of the BRDF homomorphic_factorization's cube maps are fitted to, as plain lists."""
    from generator.reference.specular import HOMOMORPHIC_TARGET
    return {k: (np.asarray(v).tolist() if np.ndim(v) else float(v)) for k, v in HOMOMORPHIC_TARGET.items()}


def studies(lib) -> tuple[list[Study], list[str]]:
    """The studies whose bricks the library holds, and a note per study left out (a brick missing)."""
    notes: list[str] = []
    s = [
        Study("fresnel", "Fresnel, in microfacet(ndf=ggx, vis=smith_ggx_height_correlated)",
              {"schlick": _microfacet("ggx", "schlick", "smith_ggx_height_correlated"),
               "spherical_gaussian": _microfacet("ggx", "spherical_gaussian", "smith_ggx_height_correlated"),
               "fresnel_ramp": _microfacet("ggx", "fresnel_ramp", "smith_ggx_height_correlated")},
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
               "gotanda_fitted": "gotanda_fitted", "oren_nayar_factored": "oren_nayar_factored"},
              exact_label="Gotanda's microfacet diffuse model (eq. 4, quadrature)",
              params={"sigma": DIFFUSE_SIGMA, "alpha": DIFFUSE_SIGMA, "f0": [0.04] * 3, "rho_d": [1.0] * 3},
              exact_fn=_diffuse_exact),
        # Factored against direct (Hoffman & Baker 2006, "BRDF Costs"): one exact model per study, at the
        # direct brick's default parameters, written out so the table states them.
        _factored("factored_blinn_phong", "Blinn-Phong (normalized)", "blinn_phong_factored",
                  "blinn_phong_normalized", {"n": 64.0, "f0": [0.04] * 3}),
        _factored("factored_banks", "Banks", "banks_factored", "banks", {"n": 32.0, "k_s": [0.5] * 3}),
        _factored("factored_ashikhmin_shirley", "Ashikhmin-Shirley specular", "ashikhmin_shirley_factored",
                  "ashikhmin_shirley", {"n_u": 100.0, "n_v": 10.0, "f0": [0.04] * 3}),
        _factored("factored_ashikhmin_shirley_diffuse", "Ashikhmin-Shirley diffuse",
                  "ashikhmin_shirley_diffuse_factored", "ashikhmin_shirley_diffuse",
                  {"rho_d": [0.5] * 3, "f0": [0.04] * 3}),
        _factored("factored_oren_nayar", "Oren-Nayar", "oren_nayar_factored", "oren_nayar",
                  {"rho_d": [0.5] * 3, "sigma": 0.3}),
    ]
    measured = _homomorphic_params()
    if measured:
        # Measured: the cube-map factorization against the BRDF it was fitted to, beside the analytic
        # factored form of the same model at the same parameters (one exact model for both).
        s.append(Study("measured", "Measured: homomorphic factorization of Ashikhmin-Shirley",
                       {"homomorphic_factorization": "homomorphic_factorization",
                        "ashikhmin_shirley_factored": "ashikhmin_shirley_factored"},
                       exact="ashikhmin_shirley",
                       exact_label="ashikhmin_shirley (direct) at the factorization's parameters",
                       params=measured, direct=True))
    else:
        notes.append("measured: left out, no HOMOMORPHIC_TARGET in generator/reference/specular.py")
    from generator.spec.permutation import SpecError, parse_brdf
    have = []
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
            continue
        # a kernel that samples baked tables says which (texture against ALU is what the study is about)
        st.kernels = {(f"{label} ({t})" if (t := _tables(spec, lib)) else label): spec
                      for label, spec in st.kernels.items()}
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
        from generator.runtime.eval_kernel import EvalSession
        self.lib, self.repeats = lib, repeats
        self.session = EvalSession()  # closed by measure() when it is done
        self.device = self.session.device
        self.vecs = timing_samples(samples, seed=2)

    def kernel(self, spec: str, lang: str, params: dict):
        """The loaded kernel: samples, parameters and the baked tables it samples (as eval binds them:
        uploaded and bound here, once, so the timed dispatches only sample them)."""
        from generator.eval.evaluate import _param_block, gpu_kernel, program, resolve_params, resolve_textures
        from generator.runtime.eval_kernel import Texture
        ep = program(spec, self.lib)
        k = gpu_kernel(spec, lang, self.lib, self.session)
        textures = [Texture(np.asarray(x), bool(d.get("srgb")))
                    for x, (_n, _t, d) in zip(resolve_textures(ep, None), ep.textures)]
        k.load(self.vecs, _param_block(ep, resolve_params(ep, own_params(spec, params, self.lib))),
               textures=textures or None)
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


def errors(spec: str, exact, params: dict, lib, k: int, lang: str, session) -> dict:
    """The kernel (lavapipe, float32, on the EvalSession `session`) and its float64 emission against `exact`: a
    spec whose reference is the exact model, or a function (L, V, N) -> f."""
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
        f = evaluate(spec, L, V, N, T, params=mine, target=target, dtype=dtype, lib=lib, session=session)
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
        own = f"{st.exact} (direct)" if st.direct else "exact model's kernel"
        members = list(st.kernels.items()) + ([(own, st.exact)] if st.exact else [])
        for label, spec in members:
            row = {"label": label, "spec": spec, "exact_kernel": spec == st.exact, "time": {}}
            for lang in langs:
                bar.set_description(f"{st.name} {lang} {label}")
                row["time"][lang] = timer.ratio(spec, st.baseline, lang, st.params)
                bar.update()
            row["errors"] = errors(spec, exact, st.params, lib, k, langs[0], timer.session)
            rows.append(row)
        pts = [{"error": r["errors"]["gpu"]["rel_rms"], **r["time"][langs[0]]} for r in rows]
        for r, on in zip(rows, front(pts)):
            r["front"] = on
        out_studies.append({"name": st.name, "title": st.title, "exact": st.exact_label, "baseline": st.baseline,
                            "unit": st.unit, "params": st.params, "rows": rows})
    bricks = []
    for spec in every:
        row = {"spec": spec, "time": {}}
        for lang in langs:
            bar.set_description(f"{lang} {spec}")
            row["time"][lang] = timer.ratio(spec, LAMBERT, lang, {})
            bar.update()
        row["errors"] = errors(spec, spec, {}, lib, k, langs[0], timer.session)
        bricks.append(row)
    bar.close()
    name = timer.device.name
    timer.session.close()
    return {"device": name, "studies": out_studies, "bricks": bricks, "notes": notes}


# ------------------------------------------------------------------ reporting

def _unit(st: dict) -> str:
    """What a study's time ratios are relative to (results recorded before "unit" existed: exact or Lambert)."""
    return st.get("unit") or ("exact" if st["baseline"] != LAMBERT else "Lambert")


def markdown(report: dict) -> str:
    langs = report["langs"]
    env = report["environment"]
    lines = [
        "# Run time against error (lavapipe)", "",
        f"Generated by `benchmarks/runtime_vs_error.py` on {env['device']} ({env['cpus']} CPUs, "
        f"LP_NUM_THREADS={env['lp_num_threads']}); {report['samples']:,} samples per dispatch, "
        f"{report['repeats']} paired dispatches per kernel and language (timestamp queries). Time: the median ratio "
        "of paired dispatches with the study's exact kernel (× exact; factored and measured forms: × their "
        "direct form's kernel, the exact model; diffuse: × Lambert), in brackets the "
        "pairs' interquartile range — two kernels whose ranges overlap are equally fast as far as this machine "
        f"can tell. Error: cosine-weighted relative RMS against the exact model in float64 over "
        f"{report['error_samples']:,} stratified hemisphere pairs, of the {langs[0].upper()} kernel on lavapipe "
        "(float32) and of the float64 emission (`model`: the approximation alone); max rel with a floor of "
        f"{REL_FLOOR:g} sr⁻¹. Front ●: no other kernel is more accurate without being slower beyond the noise. "
        f"Load average (1 min) at start / end: {env['load_average'][0]:.2f} / {env['load_average'][1]:.2f}.", ""]
    for st in report["studies"]:
        unit = f"× {_unit(st)}"
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
              "its choice of model — except for bricks that sample baked tables, whose reference is the model the "
              "tables are baked from (a factored form's direct model, the fitted BRDF of the homomorphic "
              "factorization, the continuous painting of a painted map): their error includes the tables'.", "",
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


def _label_points(ax, fig, rs, x, y, lo, hi, avoid=()) -> None:
    """Name the points of one panel, after its limits and the figure's layout are final.

    Points that coincide on the plot (equal to 2 % in time and error) share one label; a label takes
    the first offset around its point whose box lies inside the panel and overlaps no label placed
    before it and no marker, error bar or `avoid` artist (a note) (offsets rotate with the label's rank down the error axis, so
    close points stay legible); failing all, the least bad one. A thin leader joins each label to its
    point."""
    from matplotlib.transforms import Bbox

    groups: list[list[int]] = []
    for i in np.argsort(y):
        near = next((g for g in groups if abs(x[g[0]] - x[i]) < 0.02 * max(x[g[0]], 1e-9)
                     and abs(np.log10(y[g[0]] / y[i])) < 0.01), None)
        (near.append(i) if near is not None else groups.append([i]))
    renderer = fig.canvas.get_renderer()
    inside = ax.get_window_extent(renderer)
    to_px = ax.transData.transform
    marks = []  # markers (6 pt: ± 5 px at 110 dpi) and error bars (caps ± 3 pt) in pixels
    for i in range(len(x)):
        (px, py), = to_px([(x[i], y[i])])
        (bx0, _), (bx1, _) = to_px([(x[i] - lo[i], y[i]), (x[i] + hi[i], y[i])])
        marks += [Bbox([[px - 5, py - 5], [px + 5, py + 5]]), Bbox([[bx0, py - 5], [bx1, py + 5]])]
    marks += [a.get_window_extent(renderer) for a in avoid]
    placed = []  # the boxes of the labels so far
    offsets = [(8, 4, "left"), (-8, -10, "right"), (8, -12, "left"), (-8, 6, "right"), (8, 14, "left"),
               (-8, -20, "right"), (8, -22, "left"), (-8, 16, "right"), (0, 10, "center"), (0, -16, "center"),
               (8, 24, "left"), (-8, -30, "right"), (8, -32, "left"), (-8, 26, "right")]
    for rank, g in enumerate(groups):
        text = " = ".join(rs[i]["label"] for i in g)
        best = None  # (badness, offset, box): 0 fits, 1 covers a marker, bar or note, 2 a label, 3 leaves the panel
        for k in range(len(offsets)):
            dx, dy, ha = offsets[(rank + k) % len(offsets)]
            a = ax.annotate(text, (x[g[0]], y[g[0]]), textcoords="offset points", xytext=(dx, dy), ha=ha,
                            fontsize=7)
            box = a.get_window_extent(renderer)
            a.remove()
            out = not (inside.x0 <= box.x0 and box.x1 <= inside.x1 and inside.y0 <= box.y0 and box.y1 <= inside.y1)
            bad = (3 if out else 2 if any(box.overlaps(b) for b in placed)
                   else 1 if any(box.overlaps(m) for m in marks) else 0)
            if best is None or bad < best[0]:
                best = (bad, (dx, dy, ha), box)
            if bad == 0:
                break
        dx, dy, ha = best[1]
        # a thin leader from the label to its point: close points never leave a label's owner in doubt
        ax.annotate(text, (x[g[0]], y[g[0]]), textcoords="offset points", xytext=(dx, dy), ha=ha, fontsize=7,
                    arrowprops={"arrowstyle": "-", "lw": 0.5, "color": "0.45", "shrinkA": 0, "shrinkB": 3})
        placed.append(best[2])


def plot(report: dict, path: Path) -> None:
    """One panel per study: time ratio (error bar: the pairs' interquartile range) against error, log scale."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lang = report["langs"][0]
    sts = report["studies"]
    cols = min(2 if len(sts) <= 4 else 3, len(sts))
    rows_n = math.ceil(len(sts) / cols)
    fig, axes = plt.subplots(rows_n, cols, figsize=(7.0 * cols, 5.0 * rows_n), dpi=110, squeeze=False)
    panels = []
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
        notes = []
        if on.sum() >= 2:  # a front is drawn only where speed buys error beyond the noise
            order = np.argsort(x[on])
            ax.step(x[on][order], y[on][order], where="post", color="tab:red", lw=1.0, zorder=2)
        else:
            notes.append(ax.text(0.02, 0.02, "no front: the more accurate kernels are not slower beyond the noise",
                                 transform=ax.transAxes, fontsize=7, color="0.3"))
        unit = {"exact": "exact kernel", "direct": "direct kernel"}.get(_unit(st), _unit(st))
        ax.set_title(f"{st['title']}\nagainst: {st['exact']}", fontsize=9)
        ax.set_yscale("log")
        # room for the labels: a third of the time span each side, a factor 4 in error below and above
        span = max(np.max(x + hi) - np.min(x - lo), 0.1)
        ax.set_xlim(np.min(x - lo) - 0.35 * span, np.max(x + hi) + 0.35 * span)
        ax.set_ylim(np.min(y) / 4.0, np.max(y) * 4.0)
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlabel(f"time × {unit} ({lang.upper()} on lavapipe; bar: interquartile range of the pairs)", fontsize=8)
        ax.set_ylabel("error vs exact model (cos-weighted rel. RMS)", fontsize=8)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, fontsize=7, frameon=False)
        panels.append((ax, rs, x, y, lo, hi, notes))
    for ax in list(axes.flat)[len(sts):]:
        ax.set_axis_off()
    fig.suptitle(f"Run time against error: approximations against the model they approximate "
                 f"({report['samples']:,} samples per dispatch)", fontsize=11)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.98))  # the suptitle keeps its strip
    for ax, rs, x, y, lo, hi, notes in panels:  # labels last: their boxes are measured in the final layout
        _label_points(ax, fig, rs, x, y, lo, hi, notes)
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
