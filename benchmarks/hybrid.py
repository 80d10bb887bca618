"""The ubershader / shader-matrix hybrid on lavapipe: frame time, first frame, pipeline creation, registers.

Everything is measured in one run on one device, as ratios beside each other (the machines are
noisy): the example scene rendered `--frames` times in each mode and language-independent
GLSL, then

- frame time (median GPU ms after the first frame): ubershader / specialized and hybrid steady
  state / specialized (target ≤ 1.05);
- time to first frame: hybrid, all-specialized-up-front, ubershader only;
- pipeline creation per specialized pipeline and for the ubershader, cold and with the
  persisted caches;
- cold against persisted: each mode rendered by its own device into a fresh output directory
  (an empty VkPipelineCache file and an empty Mesa shader cache: every shader is compiled), then
  again into the same directory, which loads both caches; time to first frame, pipeline
  creation, and the driver's own shader-cache hit and miss counts (lavapipe JIT-compiles at the
  first draw that uses a pipeline, so the compile shows in the first frame, not in creation);
- the specialization-constant ubershader (one pipeline per material variant) against the
  uniform-branch one: creation time and frame time;
- the ubershader's register estimate and instruction count against the worst specialized
  fragment shader's (the course's "register load is based on the worst-case path");
- a contact sheet: per permutation of the example scene a tile, specialized above, ubershader
  below, the difference (×16) beside.

    .venv/bin/python benchmarks/hybrid.py [--frames 30] [--size 320x160]

writes benchmarks/results/hybrid.md, hybrid.json and hybrid_contact_sheet.png.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

import numpy as np  # noqa: E402

from generator import __version__  # noqa: E402
sys.path.insert(0, str(REPO / "benchmarks"))
from cliargs import positive, size as size_arg  # noqa: E402
from generator.analysis import entry_cost  # noqa: E402
from generator.assemble import BuildContext, build  # noqa: E402
from generator.library.bricks import load_library  # noqa: E402
from generator.scene.load import load_scene  # noqa: E402
from generator.runtime.device import Device  # noqa: E402
from generator.runtime.placement import load_placement  # noqa: E402
from generator.assemble.render_inputs import scene_textures  # noqa: E402
from generator.runtime.renderer import render_scene as _render_scene  # noqa: E402

RESULTS = REPO / "benchmarks" / "results"
EXAMPLE = REPO / "scenes" / "example.toml"


def render_scene(scene, lib, mode, frames, out, *args, **kw):
    """The renderer, drawing the scene's texture artifacts written into its folder first (not timed: the
    renderer's own clocks start after)."""
    return _render_scene(scene, lib, mode, frames, out, *args, build=scene_textures(scene, out), **kw)


def median_gpu(report, skip_first=True) -> float:
    frames = report.frames[1:] if skip_first and len(report.frames) > 1 else report.frames
    return statistics.median(f.gpu_ms for f in frames)


def steady_gpu(report) -> float:
    """Median GPU ms over the hybrid frames that drew no ubershader, and the drained frame."""
    frames = [f.gpu_ms for f in report.frames[1:] if f.draws_ubershader == 0] + [report.steady.gpu_ms]
    return statistics.median(frames)


COLD_MODES = (("specialized", "buffer"), ("ubershader", "buffer"), ("hybrid", "buffer"),
              ("ubershader", "specialization"))


def cold_and_persisted(scene, lib, size, tmp: Path, repeats: int) -> dict:
    """Per mode, medians over `repeats` of a cold render (its own device, a fresh directory) and a second
    render into the same directory (the persisted VkPipelineCache file and Mesa shader cache)."""
    def key(mode, ids):
        return mode if ids == "buffer" else "ubershader_spec"
    runs = {key(m, i): {"cold": [], "persisted": []} for m, i in COLD_MODES}
    render_scene(scene, lib, "hybrid", 1, tmp / "cold-warm-up", size)  # the process's one-time LLVM set-up
    for r in range(repeats):  # the modes interleaved, so that the machine's drift spreads over all of them
        for mode, ids in COLD_MODES:
            d = tmp / f"cold-{key(mode, ids)}-{r}"
            runs[key(mode, ids)]["cold"].append(render_scene(scene, lib, mode, 1, d, size, uber_ids=ids))
            runs[key(mode, ids)]["persisted"].append(render_scene(scene, lib, mode, 1, d, size, uber_ids=ids))
    missing = [k for k, v in runs.items() for reps in v.values() for x in reps if x.shader_cache_misses is None]
    assert not missing, f"Mesa printed no shader-cache statistics for {missing} (MESA_SHADER_CACHE_SHOW_STATS)"
    out = {}
    for k, v in runs.items():
        out[k] = {}
        for when, reps in v.items():
            out[k][when] = {
                "time_to_first_frame_ms": statistics.median(x.time_to_first_frame_ms for x in reps),
                "pipeline_create_ms": statistics.median(statistics.median(x.pipeline_create_ms) for x in reps),
                "shader_cache_hits": statistics.median(x.shader_cache_hits for x in reps),
                "shader_cache_misses": statistics.median(x.shader_cache_misses for x in reps),
                "pipeline_cache_hits": max(x.pipeline_cache_hits for x in reps)}
    return out


def costs(tmp: Path, scene, lib) -> dict:
    res = build(scene, tmp / "build", BuildContext(lib, languages=("glsl",)))
    assert res.ok, res.failures
    m = res.manifest
    spec = [(p["hash"], p["languages"]["glsl"]["frag"]["cost"]) for p in m["permutations"]]
    worst_regs = max(spec, key=lambda x: x[1]["registers"])
    worst_instr = max(spec, key=lambda x: x[1]["instructions"])
    uber = entry_cost((tmp / "build" / m["ubershader"]["languages"]["glsl"]["frag"]["spirv"]).read_bytes()).as_dict(
        histograms=False)
    return {"ubershader": {"registers": uber["registers"], "instructions": uber["instructions"]},
            "worst_specialized_registers": {"hash": worst_regs[0], "registers": worst_regs[1]["registers"]},
            "worst_specialized_instructions": {"hash": worst_instr[0], "instructions": worst_instr[1]["instructions"]}}


def contact_sheet(scene, images: dict, size, path: Path) -> None:
    """One tile per permutation (its first object): specialized above, ubershader below, |difference| × 16 beside."""
    from PIL import Image, ImageDraw

    W, H = size
    n = len(scene.objects)
    tile_w = W // n
    pl = load_placement(scene)
    _, vp = pl.camera(W, H)
    tiles, seen = [], set()
    for i, obj in enumerate(scene.objects):
        if obj["permutation"] in seen:
            continue
        seen.add(obj["permutation"])
        clip = vp @ pl.model(i) @ np.array([0.0, 0.0, 0.0, 1.0])
        cx = int(round((clip[0] / clip[3] + 1.0) / 2.0 * W))
        x0 = max(0, min(W - tile_w, cx - tile_w // 2))
        a = images["specialized"][:, x0:x0 + tile_w, :3]
        b = images["ubershader"][:, x0:x0 + tile_w, :3]
        d = np.clip(np.abs(a.astype(int) - b.astype(int)) * 16, 0, 255).astype(np.uint8)
        tiles.append((obj["permutation"], obj["name"], a, b, d))
    label = 14
    sheet = Image.new("RGB", (len(tiles) * 2 * tile_w, 2 * H + label), (20, 20, 24))
    draw = ImageDraw.Draw(sheet)
    for k, (h, name, a, b, d) in enumerate(tiles):
        x = k * 2 * tile_w
        sheet.paste(Image.fromarray(a), (x, label))
        sheet.paste(Image.fromarray(b), (x, label + H))
        sheet.paste(Image.fromarray(d), (x + tile_w, label + H // 2))
        draw.text((x + 2, 1), f"{h[:6]} {name}", fill=(230, 230, 230))
    tmp = path.with_name(f".{path.name}.tmp")
    sheet.save(tmp, format="PNG")
    os.replace(tmp, path)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=positive, default=30, help="frames per render (default 30)")
    ap.add_argument("--size", type=size_arg, default="320x160", help="WxH (default 320x160)")
    ap.add_argument("--pairs", type=positive, default=15, help="paired short runs for the frame-time ratios")
    ap.add_argument("--repeats", type=positive, default=5, help="cold / persisted renders per mode")
    args = ap.parse_args()
    size = tuple(int(x) for x in args.size.split("x"))
    lib = load_library()
    scene = load_scene(EXAMPLE, lib)
    from PIL import Image

    device = Device()
    out: dict = {"device": device.name, "generator": f"shadermatrix {__version__}", "frames": args.frames,
                 "size": list(size), "language": "glsl"}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        runs = {}
        # Warm the device first (lavapipe's first pipelines and draws pay one-time set-up), so the
        # first-frame times below compare the modes, not the order they ran in.
        render_scene(scene, lib, "hybrid", 2, tmp / "warm-up", size, device=device)
        for mode in ("specialized", "ubershader", "hybrid"):
            runs[mode] = render_scene(scene, lib, mode, args.frames, tmp / mode, size, device=device)
        runs["ubershader_spec"] = render_scene(scene, lib, "ubershader", args.frames, tmp / "spec", size,
                                               device=device, uber_ids="specialization")
        # Frame-time ratios from paired short runs, alternating the modes (lavapipe shares 2 cores with
        # everything else: a long run of one mode then another measures the machine's drift).
        pairs = {"ubershader": [], "hybrid": [], "ubershader_spec": []}
        for r in range(args.pairs):
            base = render_scene(scene, lib, "specialized", 8, tmp / "pair", size, device=device)
            for key, mode, ids in (("ubershader", "ubershader", "buffer"), ("hybrid", "hybrid", "buffer"),
                                   ("ubershader_spec", "ubershader", "specialization")):
                other = render_scene(scene, lib, mode, 8, tmp / "pair", size, device=device, uber_ids=ids)
                value = steady_gpu(other) if key == "hybrid" else median_gpu(other)
                pairs[key].append(value / median_gpu(base))
        out["cold_and_persisted"] = cold_and_persisted(scene, lib, size, tmp, args.repeats)
        images = {m: np.asarray(Image.open(tmp / m / "frame_0001.png")) for m in ("specialized", "ubershader")}
        contact_sheet(scene, images, size, RESULTS / "hybrid_contact_sheet.png")
        out["costs"] = costs(tmp, scene, lib)
    device.close()
    s, u, h, us = (runs[m] for m in ("specialized", "ubershader", "hybrid", "ubershader_spec"))
    out["frame_gpu_ms"] = {"specialized": median_gpu(s), "ubershader": median_gpu(u), "hybrid_steady": steady_gpu(h),
                           "ubershader_spec": median_gpu(us)}
    out["ratios"] = {"ubershader/specialized": statistics.median(pairs["ubershader"]),
                     "hybrid_steady/specialized": statistics.median(pairs["hybrid"]),
                     "ubershader_spec/ubershader": statistics.median(pairs["ubershader_spec"])
                     / statistics.median(pairs["ubershader"])}
    out["paired_ratios"] = pairs
    out["time_to_first_frame_ms"] = {"hybrid": h.time_to_first_frame_ms, "specialized_up_front": s.time_to_first_frame_ms,
                                     "ubershader_only": u.time_to_first_frame_ms}
    out["pipeline_create_ms"] = {"specialized_each": s.pipeline_create_ms, "ubershader": u.pipeline_create_ms[0],
                                 "ubershader_spec_each": us.pipeline_create_ms}
    out["hybrid_draws_ubershader_per_frame"] = [fr.draws_ubershader for fr in h.frames]
    out["target_met"] = out["ratios"]["hybrid_steady/specialized"] <= 1.05
    (RESULTS / "hybrid.json").write_text(json.dumps(out, indent=2) + "\n")
    c = out["costs"]
    md = [f"# Hybrid ubershader / shader matrix on {out['device']}",
          "",
          f"Generated by `benchmarks/hybrid.py` ({out['generator']}): the example scene, {args.frames} frames of "
          f"{size[0]}×{size[1]} per mode, GLSL, one device, one run, after a warm-up render. GPU time from "
          f"timestamp queries, median over the frames after the first; the frame-time ratios are the median of {args.pairs} paired short runs "
          "(specialized, then the other mode, alternating).",
          "",
          "| measure | value |", "|---|---|",
          f"| frame time, ubershader / specialized | {out['ratios']['ubershader/specialized']:.3f} |",
          f"| frame time, hybrid steady state / specialized (target ≤ 1.05) | "
          f"{out['ratios']['hybrid_steady/specialized']:.3f} ({'met' if out['target_met'] else 'not met'}) |",
          f"| frame time, specialization-constant ubershader / uniform-branch ubershader | "
          f"{out['ratios']['ubershader_spec/ubershader']:.3f} |",
          f"| time to first frame, warm device: hybrid / all specialized up front / ubershader only (ms) | "
          f"{h.time_to_first_frame_ms:.1f} / {s.time_to_first_frame_ms:.1f} / {u.time_to_first_frame_ms:.1f} |",
          f"| pipeline creation, specialization-constant ubershader per variant (median ms) | "
          f"{statistics.median(us.pipeline_create_ms):.2f} |",
          f"| hybrid: draws with the ubershader per frame | {', '.join(map(str, out['hybrid_draws_ubershader_per_frame']))} |",
          f"| registers (estimate): ubershader / worst specialized | {c['ubershader']['registers']} / "
          f"{c['worst_specialized_registers']['registers']} (`{c['worst_specialized_registers']['hash']}`) |",
          f"| instructions: ubershader / worst specialized | {c['ubershader']['instructions']} / "
          f"{c['worst_specialized_instructions']['instructions']} (`{c['worst_specialized_instructions']['hash']}`) |",
          "",
          f"Cold against persisted caches (median of {args.repeats}; each render opens its own device: \"cold\" "
          "into a fresh directory, so an empty VkPipelineCache file and an empty Mesa shader cache, "
          "\"persisted\" again into the same directory). Hits and misses are the driver's own count "
          "(MESA_SHADER_CACHE_SHOW_STATS). lavapipe compiles a pipeline's shaders at the first draw that "
          "uses it, so the compile is in the first frame, not in pipeline creation; its VkPipelineCache "
          "holds only its header (docs/design/runtime.md, \"The pipeline cache\"), so the driver's creation feedback never "
          "reports a hit.",
          "",
          "| mode | first frame, cold / persisted (ms) | pipeline creation, cold / persisted (median ms) "
          "| shader cache, cold: misses | persisted: hits / misses | VkPipelineCache hits |",
          "|---|---|---|---|---|---|",
          *[f"| {k} | {v['cold']['time_to_first_frame_ms']:.1f} / {v['persisted']['time_to_first_frame_ms']:.1f} "
            f"| {v['cold']['pipeline_create_ms']:.2f} / {v['persisted']['pipeline_create_ms']:.2f} "
            f"| {v['cold']['shader_cache_misses']:g} "
            f"| {v['persisted']['shader_cache_hits']:g} / {v['persisted']['shader_cache_misses']:g} "
            f"| {v['persisted']['pipeline_cache_hits']} |" for k, v in out["cold_and_persisted"].items()],
          "",
          "![contact sheet](hybrid_contact_sheet.png)", ""]
    (RESULTS / "hybrid.md").write_text("\n".join(md))
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
