"""AMD compiler statistics in the cost tables: RADV's figures beside the SPIR-V counts.

`shadermatrix costs ... --gpu FAMILIES` compiles every measured shader on RADV's null device of each
family (runtime/gpu_stats.py) and attaches, per row, ``Row.gpu = {family: {statistic: value}}``:
the statistics of the row's stage, by the driver's names (``VGPRs``, ``SGPRs``, ``Spilled VGPRs``,
``Instructions``, ``Subgroups per SIMD`` …). A per-permutation or ubershader row carries its shader's
figures; a per-brick or model row carries "with the brick" minus "with the stand-in", like its SPIR-V
counts (so a VGPR delta moves in RADV's allocation granules: 4 or 8 registers).

The estimate check: over every row of a scene (permutations and the ubershader, both stages, every
language), the SPIR-V register estimate (analysis/liveness.py) against RADV's VGPRs, per family — the
Spearman rank correlation (does the estimate order shaders as the compiler does?) and the worst
misprediction (the row whose VGPRs a least-squares line through the estimate misses by most).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..runtime.gpu_stats import SHOWN, GpuStatsUnavailable, Job, statistics
from .plans import REPORT_LANGUAGES
from .report import LANGS_AND, LANGS_SLASH

__all__ = ["GpuRequest", "attach", "estimate_check", "SHOWN"]


@dataclass
class GpuRequest:
    """Which families to compile for, where to save ACO's IR (or None), and — after the run — why no
    figures came (``note``: '' when they did) and which families failed (``errors``)."""

    families: tuple[str, ...]
    ir_dir: str | None = None
    note: str = ""
    errors: dict | None = None
    devices: dict | None = None  # family -> device and driver


def attach(request: GpuRequest, rows, units: dict[str, dict[str, bytes]], subtract=None) -> None:
    """Compile `units` ({job key: {stage: SPIR-V}}) for every family and set each row's ``gpu``.

    rows: (row, with_key, without_key or None) triples; a row gets the statistics of its stage for
    with_key, minus those of without_key when it has one. Leaves ``gpu`` unset and sets
    ``request.note`` when RADV cannot be used; a shader RADV cannot take is in ``request.errors``.
    """
    jobs = [Job(key, tuple(sorted(stages.items(), key=lambda s: ("vert", "frag", "comp").index(s[0]))))
            for key, stages in sorted(units.items())]
    try:
        result = statistics(jobs, request.families, request.ir_dir)
    except GpuStatsUnavailable as e:
        request.note = f"no AMD compiler statistics: {e}"
        return
    request.errors, request.devices = dict(result.errors), dict(result.devices)
    for key, by_family in sorted(result.failed.items()):  # a shader RADV could not take: its rows say so
        for family, why in sorted(by_family.items()):
            request.errors[f"{family}/{key}"] = f"RADV {family}: {key}: {why}"
    for row, with_key, without_key in rows:
        gpu = {}
        for family in request.families:
            a = result.of(family, with_key, row.stage)
            if a is None:
                continue
            if without_key is not None:
                b = result.of(family, without_key, row.stage)
                if b is None:
                    continue
                a = {k: v - b[k] for k, v in a.items() if k in b and k != "Driver pipeline hash" and k != "Hash"}
            gpu[family] = a
        row.gpu = gpu or None


def _ranks(x: np.ndarray) -> np.ndarray:
    """Ranks with ties averaged (what Spearman's coefficient uses)."""
    order = np.argsort(x, kind="stable")
    ranks = np.empty(len(x))
    ranks[order] = np.arange(len(x), dtype=float)
    for v in np.unique(x):
        tied = x == v
        ranks[tied] = ranks[tied].mean()
    return ranks


def spearman(x, y) -> float | None:
    """Spearman's rank correlation; None when either side is constant (no ranking to compare)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    rx, ry = _ranks(x), _ranks(y)
    if rx.std() == 0 or ry.std() == 0:
        return None
    return float(np.corrcoef(rx, ry)[0, 1])


def estimate_check(rows, families) -> dict[str, dict]:
    """Per family: n, Spearman ρ of the SPIR-V estimate against RADV's VGPRs, the fitted line, the worst row."""
    out = {}
    for family in families:
        pts = [(r, r.cost.registers, r.gpu[family]["VGPRs"]) for r in rows
               if r.table in ("permutation", "ubershader") and r.cost is not None and r.gpu
               and family in r.gpu and "VGPRs" in r.gpu[family]]
        if len(pts) < 3:
            continue
        est = np.array([p[1] for p in pts], float)
        vgpr = np.array([p[2] for p in pts], float)
        slope, intercept = np.polyfit(est, vgpr, 1) if est.std() > 0 else (0.0, float(vgpr.mean()))
        miss = vgpr - (slope * est + intercept)
        k = int(np.argmax(np.abs(miss)))
        worst = pts[k][0]
        out[family] = {"n": len(pts), "spearman": spearman(est, vgpr), "slope": float(slope),
                       "intercept": float(intercept),
                       "worst": {"subject": worst.subject, "stage": worst.stage, "language": worst.language,
                                 "estimate": int(est[k]), "vgprs": int(vgpr[k]),
                                 "predicted": float(slope * est[k] + intercept), "miss": float(miss[k])}}
    return out


# ------------------------------------------------------------------ reports

# Markdown columns: (header, driver statistic name or a derived one).
MD = [("VGPRs", "VGPRs"), ("SGPRs", "SGPRs"), ("spills V/S", "spills"), ("instr.", "Instructions"),
      ("code B", "Code size"), ("waves/SIMD", "Subgroups per SIMD"), ("latency", "Latency"),
      ("inv. throughput", "Inverse Throughput")]
LANGS = REPORT_LANGUAGES


def _stat(row, family, name):
    g = (row.gpu or {}).get(family)
    if g is None:
        return None
    if name == "spills":
        return f"{g.get('Spilled VGPRs', 0):g}/{g.get('Spilled SGPRs', 0):g}"
    v = g.get(name)
    return None if v is None else (f"{v:g}" if isinstance(v, float) else str(v))


def _cell(by_lang, family, name) -> str:
    shown = ["–" if (v := _stat(by_lang[lang], family, name)) is None else v for lang in LANGS if lang in by_lang]
    return shown[0] if len(set(shown)) == 1 else " / ".join(shown)


def families_of(rows) -> list[str]:
    out = []
    for r in rows:
        for f in (r.gpu or {}):
            if f not in out:
                out.append(f)
    return out


def markdown(rows, groups, request: GpuRequest | None) -> list[str]:
    """The RADV sections of a cost report (none when no row has figures)."""
    families = families_of(rows)
    if not families:
        return [f"*{request.note}*", ""] if request is not None and request.note else []
    devices = (request.devices or {}) if request else {}
    out = ["## AMD compiler statistics (RADV null device)", "",
           "ACO's own figures, read with VK_KHR_pipeline_executable_properties from pipelines created on Mesa "
           "RADV's null device for each GPU family (`generator/runtime/gpu_stats.py`): VGPRs and SGPRs allocated "
           "per wave, spilled VGPRs/SGPRs, instructions, code bytes, waves (subgroups) per SIMD — the occupancy —, "
           "ACO's latency and inverse-throughput estimates in cycles. Graphics pipelines have the permutation's "
           "vertex layout and the renderer's R8G8B8A8_UNORM + D32_SFLOAT targets. A cell holds one number when "
           f"{LANGS_AND} agree, otherwise {LANGS_SLASH}. Per-brick rows: with the brick minus with "
           "the stand-in.", "",
           "Devices: " + "; ".join(f"{f}: {devices.get(f, '?')}" for f in families) + ".", ""]
    head = [h for h, _ in MD]
    shader = [(k, v) for k, v in groups.items() if k[0] in ("permutation", "ubershader")]
    if shader:
        lines = []
        for (table, subject, stage, _), by_lang in shader:
            if not any(r.gpu for r in by_lang.values()):
                continue
            first = next(iter(by_lang.values()))
            for f in families:
                lines.append([f"`{subject}`", ", ".join(first.objects), stage, f,
                              *[_cell(by_lang, f, name) for _, name in MD],
                              _spirv_cell(by_lang, "registers"), _spirv_cell(by_lang, "instructions")])
        out += _table(["shader", "objects", "stage", "family", *head, "SPIR-V regs (est.)", "SPIR-V instr."], lines)
        out += [""]
        out += _uber_section(groups, families)
        out += _estimate_section(rows, families)
    bricks = [(k, v) for k, v in groups.items() if k[0] in ("brick", "model") and any(r.gpu for r in v.values())]
    if bricks:
        lines = [[next(iter(v.values())).kind, f"`{k[1]}`", k[2], f, *[_cell(v, f, name) for _, name in MD]]
                 for k, v in bricks for f in families]
        out += ["### Per brick (with minus stand-in)", ""]
        out += _table(["kind", "brick", "stage", "family", *head], lines) + [""]
    if request is not None and request.errors:
        out += [f"- {e}" for _, e in sorted(request.errors.items())] + [""]
    return out


def _spirv_cell(by_lang, field) -> str:
    shown = [str(getattr(by_lang[lang].cost, field)) if by_lang[lang].cost else "–" for lang in LANGS
             if lang in by_lang]
    return shown[0] if len(set(shown)) == 1 else " / ".join(shown)


def _table(header, lines) -> list[str]:
    return (["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
            + ["| " + " | ".join(c) + " |" for c in lines])


def uber_load(groups, families) -> list[dict]:
    """Per family and stage: the ubershader's VGPRs and waves against the specialized shaders' worst."""
    out = []
    for stage in ("frag", "vert"):
        uber = [r for (t, _, s, _), v in groups.items() if t == "ubershader" and s == stage for r in v.values()]
        spec = [r for (t, _, s, _), v in groups.items() if t == "permutation" and s == stage for r in v.values()]
        for f in families:
            u = [r for r in uber if r.gpu and f in r.gpu]
            p = [r for r in spec if r.gpu and f in r.gpu]
            if not u or not p:
                continue
            worst = max(p, key=lambda r: r.gpu[f]["VGPRs"])
            out.append({"family": f, "stage": stage,
                        "ubershader_vgprs": max(r.gpu[f]["VGPRs"] for r in u),
                        "worst_specialized_vgprs": worst.gpu[f]["VGPRs"], "worst_specialized": worst.subject,
                        "ubershader_waves": min(r.gpu[f]["Subgroups per SIMD"] for r in u),
                        "worst_specialized_waves": min(r.gpu[f]["Subgroups per SIMD"] for r in p),
                        "ubershader_instructions": max(r.gpu[f]["Instructions"] for r in u),
                        "worst_specialized_instructions": max(r.gpu[f]["Instructions"] for r in p),
                        "ubershader_estimate": max(r.cost.registers for r in u if r.cost),
                        "worst_specialized_estimate": max(r.cost.registers for r in p if r.cost)})
    return out


def _uber_section(groups, families) -> list[str]:
    load = uber_load(groups, families)
    if not load:
        return []
    lines = [[d["family"], d["stage"], f"{d['ubershader_vgprs']:g} / {d['worst_specialized_vgprs']:g} "
              f"(`{d['worst_specialized']}`)", f"{d['ubershader_waves']:g} / {d['worst_specialized_waves']:g}",
              f"{d['ubershader_instructions']:g} / {d['worst_specialized_instructions']:g}",
              f"{d['ubershader_estimate']} / {d['worst_specialized_estimate']}"] for d in load]
    return (["### The ubershader's register load", "",
             "Hoffman & Baker 2006: \"register load is based on the worst-case path\". Measured: the ubershader "
             "(every language, the most any language needs) against the worst specialized shader of the scene.", ""]
            + _table(["family", "stage", "VGPRs: ubershader / worst specialized", "waves/SIMD: ubershader / fewest",
                      "instr.: ubershader / most", "SPIR-V estimate: ubershader / worst"], lines) + [""])


def _estimate_section(rows, families) -> list[str]:
    check = estimate_check(rows, families)
    if not check:
        return []
    lines = [[f, str(c["n"]), "–" if c["spearman"] is None else f"{c['spearman']:.2f}", f"{c['slope']:.2f} × estimate + {c['intercept']:.1f}",
              f"`{c['worst']['subject']}` {c['worst']['stage']} {c['worst']['language']}: estimate "
              f"{c['worst']['estimate']}, RADV {c['worst']['vgprs']} VGPRs, line says {c['worst']['predicted']:.0f}"]
             for f, c in check.items()]
    return (["### The SPIR-V register estimate against RADV", "",
             "Over every shader above: Spearman's rank correlation of the estimate (`regs`) with RADV's VGPRs "
             "(1: the estimate orders shaders exactly as ACO does), the least-squares line through them, and the "
             "shader that line misses by most.", ""]
            + _table(["family", "shaders", "Spearman ρ", "VGPRs ≈", "worst misprediction"], lines) + [""])


def csv_fields(rows) -> list[str]:
    return [f"gpu_{f}_{key}" for f in families_of(rows) for key in SHOWN.values()]


def csv_values(row) -> dict:
    out = {}
    for f, stats in (row.gpu or {}).items():
        for name, key in SHOWN.items():
            if name in stats:
                out[f"gpu_{f}_{key}"] = stats[name]
    return out
