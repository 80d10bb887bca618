"""How far the SPIR-V register estimate can be trusted: against RADV's VGPRs over the whole matrix.

The shaders: every permutation of the example scene and its ubershader (vertex and fragment), and the
eval kernel of every BRDF the library can build (each brick, each slot filler combination of a brick
with slots), in GLSL, HLSL and WGSL. Each is compiled by ACO on Mesa RADV's null device for the
default families (generator/runtime/gpu_stats.py), and its VGPRs are set beside the estimate
(generator/analysis/liveness.py): per family the Spearman rank correlation, the least-squares line,
and the worst misprediction; a scatter plot per family.

    .venv/bin/python benchmarks/radv_estimate.py

writes benchmarks/results/radv_estimate.md, radv_estimate.json and radv_estimate.png, and the
example scene's `shadermatrix costs --gpu` report as costs_example_gpu.md (the source of docs/benchmarks.md's
ubershader table). Counts, not times: the figures are the same on every run.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from types import SimpleNamespace

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

import numpy as np  # noqa: E402

from generator import __version__  # noqa: E402
from generator.analysis import entry_cost  # noqa: E402
from generator.compose import compose_eval  # noqa: E402
from generator.library.bricks import load_library  # noqa: E402
from generator.scene.load import load_scene  # noqa: E402
from generator.measure.gpu import GpuRequest, estimate_check, spearman, uber_load  # noqa: E402
from generator.measure.plans import scene_rows  # noqa: E402
from generator.measure.report import group, markdown  # noqa: E402
from generator.runtime.gpu_stats import DEFAULT_FAMILIES, Job, statistics  # noqa: E402
from generator.toolchain import CompileJob, compile_many  # noqa: E402

RESULTS = REPO / "benchmarks" / "results"
LANGUAGES = ("glsl", "hlsl", "wgsl")  # the project's one order


def brdf_specs(lib) -> list[str]:
    """Every BRDF term the library builds: accuracy's default set (each brick; a host with each slot filler at
    least once — the full filler product is ~700 kernels × 4 families, a quarter of an hour here)."""
    from generator.eval.accuracy import default_specs
    return default_specs(lib)


def kernel_rows(lib, families) -> list:
    """Rows (like the cost table's) for the eval kernel of every BRDF spec, with RADV's statistics."""
    units, jobs = {}, []
    for spec in brdf_specs(lib):
        c = compose_eval(spec, lib, LANGUAGES)
        for src in c.sources:
            key = f"{c.hash}.{src.language}"
            units[key] = (spec, src.language)
            jobs.append(CompileJob(key, src.language, "comp", src.text, line_map=tuple(src.line_map)))
    built = compile_many(jobs)
    bad = [k for k, r in built.items() if not r.ok]
    assert not bad, bad
    res = statistics([Job(k, (("comp", r.spirv),)) for k, r in sorted(built.items())], families)
    assert not res.errors, res.errors
    return [SimpleNamespace(table="permutation", subject=spec, stage="comp", language=lang,
                            cost=entry_cost(built[k].spirv),
                            gpu={f: res.of(f, k, "comp") for f in families})
            for k, (spec, lang) in sorted(units.items())]


def plot(rows, families, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(families), figsize=(4 * len(families), 3.6), sharex=True)
    for ax, f in zip(np.atleast_1d(axes), families):
        for stage, colour in (("comp", "tab:blue"), ("frag", "tab:orange"), ("vert", "tab:green")):
            pts = [(r.cost.registers, r.gpu[f]["VGPRs"]) for r in rows if r.stage == stage]
            if pts:
                x, y = np.array(pts).T
                ax.scatter(x, y + np.random.default_rng(0).uniform(-0.4, 0.4, len(y)), s=10, alpha=0.6,
                           color=colour, label={"comp": "eval kernel", "frag": "fragment", "vert": "vertex"}[stage])
        ax.set_title(f)
        ax.set_xlabel("SPIR-V register estimate")
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("RADV VGPRs (allocated)")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    fig.tight_layout()
    tmp = path.with_name(f".{path.name}.tmp")
    fig.savefig(tmp, format="png", dpi=90, metadata={"Software": None})
    tmp.replace(path)


def main() -> int:
    import argparse
    argparse.ArgumentParser(description=__doc__.splitlines()[0], epilog="No options: it measures the example "
                            "scene and every BRDF's eval kernel.").parse_args()
    lib = load_library()
    families = DEFAULT_FAMILIES
    request = GpuRequest(families)
    example = load_scene(REPO / "scenes" / "example.toml", lib)
    all_scene = scene_rows(example, lib, gpu=request)
    assert not request.note and not request.errors, (request.note, request.errors)
    (RESULTS / "costs_example_gpu.md").write_text(markdown(all_scene, f"Costs of scene {example.name}", None,
                                                           request, course=True, languages=True))
    scene = [r for r in all_scene if r.gpu and not r.error]
    kernels = kernel_rows(lib, families)
    rows = scene + kernels
    check = estimate_check(rows, families)
    per_set = {name: estimate_check(rs, families) for name, rs in (("scene shaders", scene),
                                                                  ("eval kernels", kernels))}
    spills = sum(r.gpu[f]["Spilled VGPRs"] + r.gpu[f]["Spilled SGPRs"] for r in rows for f in families)
    out = {"generator": f"shadermatrix {__version__}", "devices": request.devices, "shaders": len(rows),
           "scene_shaders": len(scene), "eval_kernels": len(kernels), "all": check, "by_set": per_set,
           "spills": spills,
           "vgpr_range": {f: [min(r.gpu[f]["VGPRs"] for r in rows), max(r.gpu[f]["VGPRs"] for r in rows)]
                          for f in families},
           "estimate_range": [min(r.cost.registers for r in rows), max(r.cost.registers for r in rows)],
           "instructions_spearman": {f: spearman([r.cost.instructions for r in rows],
                                                 [r.gpu[f]["Instructions"] for r in rows]) for f in families},
           # per kind of shader: the estimate's range and RADV's VGPR range over the families
           "by_stage": {st: {"estimate": [min(r.cost.registers for r in rs), max(r.cost.registers for r in rs)],
                             "vgprs": [min(r.gpu[f]["VGPRs"] for r in rs for f in families),
                                       max(r.gpu[f]["VGPRs"] for r in rs for f in families)]}
                        for st in ("comp", "frag", "vert") if (rs := [r for r in rows if r.stage == st])},
           "ubershader": uber_load(group(all_scene), families),
           "ubershader_latency_ratio": {
               f: max(r.gpu[f]["Latency"] for r in scene if r.table == "ubershader" and r.stage == "frag")
               / max(r.gpu[f]["Latency"] for r in scene if r.table == "permutation" and r.stage == "frag")
               for f in families}}
    (RESULTS / "radv_estimate.json").write_text(json.dumps(out, indent=2, sort_keys=True) + "\n")
    plot(rows, families, RESULTS / "radv_estimate.png")
    md = [f"# The SPIR-V register estimate against RADV's VGPRs ({len(rows)} shaders)", "",
          f"Generated by `benchmarks/radv_estimate.py` ({out['generator']}): every permutation of the example "
          f"scene and its ubershader, vertex and fragment ({len(scene)} shaders), and the eval kernel of every "
          f"BRDF the library builds ({len(kernels)}), each in GLSL, HLSL and WGSL, compiled by ACO on "
          "Mesa RADV's null device: " + "; ".join(f"{f}: {d}" for f, d in request.devices.items()) + ".", "",
          "| family | shaders | Spearman ρ (all) | ρ scene shaders | ρ eval kernels | VGPRs ≈ | RADV VGPRs | "
          "worst misprediction | instructions ρ |",
          "|---|---|---|---|---|---|---|---|---|"]
    for f, c in check.items():
        w = c["worst"]
        md.append(f"| {f} | {c['n']} | {c['spearman']:.2f} | {per_set['scene shaders'][f]['spearman']:.2f} | "
                  f"{per_set['eval kernels'][f]['spearman']:.2f} | {c['slope']:.2f} × estimate + "
                  f"{c['intercept']:.1f} | {out['vgpr_range'][f][0]}–{out['vgpr_range'][f][1]} | "
                  f"`{w['subject']}` {w['stage']} {w['language']}: estimate {w['estimate']}, {w['vgprs']} VGPRs, "
                  f"line {w['predicted']:.0f} | {out['instructions_spearman'][f]:.2f} |")
    kinds = {"comp": "eval kernels", "frag": "fragment shaders", "vert": "vertex shaders"}
    md += ["", f"Estimates range over {out['estimate_range'][0]}–{out['estimate_range'][1]} live scalars; "
           f"spilled registers in all {len(rows) * len(families)} compiles: {spills}. By kind: "
           + "; ".join(f"{kinds[st]}: estimate {v['estimate'][0]}–{v['estimate'][1]}, "
                       f"{v['vgprs'][0]}–{v['vgprs'][1]} VGPRs" for st, v in out["by_stage"].items()) + ". "
           "The scene's ubershader fragment shader against its worst specialized one, in ACO's latency "
           "estimate: " + ", ".join(f"{f} {x:.1f}×" for f, x in out["ubershader_latency_ratio"].items())
           + " (the whole report: [costs_example_gpu.md](costs_example_gpu.md)).", "",
           "![estimate against RADV VGPRs](radv_estimate.png)", ""]
    (RESULTS / "radv_estimate.md").write_text("\n".join(md))
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
