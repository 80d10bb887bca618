"""The light loop an engine can afford: a static light list against a dynamic set's two loops, on lavapipe and RADV.

One scene (a Lambert floor and a Blinn-Phong ball, 2 materials) under N lights on a circle, half point and half
spot (N = 1: one point), drawn three ways, in one run on one device, as ratios beside each other:

- static: the N lights as a static set, unrolled in the shader (N ≤ 32, the static cap);
- types: a dynamic set, `loop = "types"`, one loop per light type over its own buffer (`*point/none,*spot/none`);
- switch: a dynamic set, `loop = "switch"`, one loop over one buffer, a switch on each light's type
  (`**point/none,**spot/none`);
- tiles: the types loop with `culling = "tiles"` (`*point_range/none@tiles,…`): each loop reads its 16-pixel
  tile's index list, which the renderer's CPU culling fills. Tiles need lights with a reach, so these cases and
  their "types" twins (form "types (ranged)") use point_range lights and spots of radius RANGE.

The shadowed cases put shadow_map on every light, static and (types loop) dynamic: the same maps, as separate
textures or as one 2D array per pair (a switch loop with shadows is refused).

Per case: permutations and the cold build time (GLSL, Vulkan, no cache); the lavapipe frame time (median GPU ms of
the render report's frames, the first dropped, over interleaved rounds: the machine's drift spreads over all
three forms); per AMD family (RADV's null device) the ball's fragment shader's VGPRs, instructions, latency and
waves per SIMD (occupancy); shadow-map memory (0 for shadow none; the static shadowed cases give the
renderer's maps: width × height × 4 bytes of D32 per map, a point light six faces). No pass or fail: wall-clock figures are
this machine's.

    .venv/bin/python benchmarks/lights.py [--frames 12] [--rounds 4] [--size 320x160] [--quick]

writes benchmarks/results/lights.md and lights.json (--quick: 1, 4 and 64 lights, 2 frames, 1 round; for a smoke
run, and marked so in the results).
"""
from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

from cliargs import positive, size as size_arg  # noqa: E402
from generator import __version__  # noqa: E402
from generator.assemble import BuildContext, build  # noqa: E402
from generator.io import atomic_write  # noqa: E402
from generator.library.bricks import load_library  # noqa: E402
from generator.runtime.device import Device  # noqa: E402
from generator.runtime.gpu_stats import DEFAULT_FAMILIES, Job, statistics as radv_statistics  # noqa: E402
from generator.runtime.renderer import render_scene  # noqa: E402
from generator.scene.load import load_scene  # noqa: E402

RESULTS = REPO / "benchmarks" / "results"
STATIC_COUNTS = (1, 4, 16, 32)  # a static set holds at most 32 (scene/light_sets.py MAX_LIGHTS_PER_SET)
DYNAMIC_ONLY = (64, 256)
SHADOWED = (1, 4, 16)  # static and dynamic (types) sets with shadow_map on every light: the shadow maps' memory
FORMS = ("static", "types", "switch")
LABEL = {"ranged": "types (ranged)"}
TILED = (64, 256)  # ranged lights, the types loop untiled and tiled
RANGE = 1.5  # the ranged lights' radius (metres; the lights' circle has radius 2.5)
RADV_SHOWN = {"VGPRs": "vgprs", "Instructions": "instructions", "Latency": "latency",
              "Subgroups per SIMD": "waves_per_simd"}
PLACEMENT = ('[objects.floor]\nmesh = "plane"\nscale = [4.0, 1.0, 4.0]\n[objects.ball]\nmesh = "sphere"\n'
             'translate = [0.0, 0.7, 0.0]\nscale = 0.7\n[camera]\neye = [0.0, 6.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n')


def scene_text(n: int, form: str, shadow: str = "none") -> str:
    """The benchmark scene: n lights, even ones point, odd ones spot, as a static list or a dynamic set; forms
    "tiles" and "ranged" (the types loop untiled): point_range lights and spots of radius RANGE."""
    ranged = form in ("tiles", "ranged")
    out = ['[materials.grey]\nbrdf = "lambert"\nparams = { rho_d = [0.8, 0.8, 0.8] }\n',
           '[materials.shiny]\nbrdf = "lambert+blinn_phong_normalized"\nparams = { rho_d = [0.5, 0.3, 0.2], n = 32.0 }\n']
    for i in range(n):
        a = 2 * math.pi * i / n
        c = [round(0.2 + 0.6 * abs(math.sin(a + k)), 3) * 8.0 / n for k in (0.0, 2.1, 4.2)]
        kind = ("point_range" if ranged else "point") if i % 2 == 0 else "spot"
        aim = ", direction = [0.0, -1.0, 0.0], outer_angle = 1.2" if kind == "spot" else ""
        aim += f", radius = {RANGE}" if ranged else ""
        out.append(f'[lights.l{i}]\ntype = "{kind}"\nshadow = "{shadow}"\nparams = {{ position = '
                   f'[{2.5 * math.cos(a):.4f}, 1.6, {2.5 * math.sin(a):.4f}], color = [{c[0]:.4f}, {c[1]:.4f}, '
                   f'{c[2]:.4f}]{aim} }}\n')
    names = ", ".join(f'"l{i}"' for i in range(n))
    if form == "static":
        out.append(f"[light_sets]\nall = [{names}]\n")
    else:
        loop = "types" if ranged else form
        cull = 'culling = "tiles"\n' if form == "tiles" else ""
        cap = n if shadow != "none" else max(n, 256)  # a shadowed pair's array: max x layers, at most 2048
        out.append(f'[light_sets.all]\ndynamic = true\nlights = [{names}]\nmax = {cap}\nloop = "{loop}"\n{cull}')
    out += ['[[objects]]\nname = "floor"\nmaterial = "grey"\nlights = "all"\n',
            '[[objects]]\nname = "ball"\nmaterial = "shiny"\nlights = "all"\n']
    return "\n".join(out)


def cases(quick: bool) -> list[tuple[int, str, str]]:
    """(lights, form, shadow) in the order they are built and drawn."""
    static = (1, 4) if quick else STATIC_COUNTS
    dyn = (64,) if quick else DYNAMIC_ONLY
    out = [(n, f, "none") for n in static for f in FORMS]
    out += [(n, f, "none") for n in dyn for f in FORMS[1:]]
    out += [(n, f, "shadow_map") for n in (SHADOWED[:1] if quick else SHADOWED) for f in ("static", "types")]
    out += [(n, f, "none") for n in (TILED[:1] if quick else TILED) for f in ("ranged", "tiles")]
    return out


def name_of(n: int, form: str, shadow: str) -> str:
    return f"{form}-{n}" + ("" if shadow == "none" else f"-{shadow}")


def prepare(lib, tmp: Path, case) -> dict:
    """Write, load and cold-build one case; its scene, permutation count, build time and the ball's SPIR-V."""
    n, form, shadow = case
    d = tmp / name_of(*case)
    d.mkdir(parents=True)
    (d / "s.toml").write_text(scene_text(n, form, shadow))
    (d / "s.placement.toml").write_text(PLACEMENT)
    scene = load_scene(d / "s.toml", lib)
    t0 = time.perf_counter()
    res = build(scene, d / "build", BuildContext(lib, languages=("glsl",), platforms=("vulkan",)))
    seconds = time.perf_counter() - t0
    assert res.ok, res.failures
    m = res.manifest
    ball = next(o for o in m["objects"] if o["name"] == "ball")["permutation"]
    perm = next(p for p in m["permutations"] if p["hash"] == ball)
    glsl = perm["languages"]["glsl"]
    stages = tuple((s, (d / "build" / glsl[s]["spirv"]).read_bytes()) for s in ("vert", "frag"))
    key = next(p for p in scene.permutations.values() if p.hash == ball).canonical()
    return {"scene": scene, "dir": d, "permutations": len(m["permutations"]), "cold_build_s": seconds,
            "ball_key": key.split(";")[1], "stages": stages}


def frame_times(lib, prepared: dict, device, size, frames: int, rounds: int) -> dict:
    """Per case, the median over rounds of its render's median GPU ms (first frame dropped); the cases interleaved
    round by round; and the shadow maps the last round drew."""
    runs = {k: [] for k in prepared}
    maps = {}
    for r in range(rounds):
        for k, p in prepared.items():
            rep = render_scene(p["scene"], lib, "specialized", frames + 1, p["dir"] / f"render{r}", size, "glsl",
                               device=device)
            runs[k].append(statistics.median(f.gpu_ms for f in rep.frames[1:]))
            maps[k] = rep.shadow_maps
    return {k: {"gpu_ms": statistics.median(v), "rounds_ms": v,
                "shadow_map_bytes": sum(_map_bytes(m) for m in maps[k].values()),
                "shadow_maps": sum(m.get("layers", 1) for m in maps[k].values())} for k, v in runs.items()}


def _map_bytes(m: dict) -> int:
    """A light's depth maps as the render report gives them: width × height × 4 bytes (D32) × its layers."""
    size = m["size"] if isinstance(m["size"], (list, tuple)) else (m["size"], m["size"])
    return size[0] * size[1] * 4 * m.get("layers", 1)


def radv(prepared: dict, families) -> dict:
    """Per case, per family, the ball's fragment shader's RADV statistics (RADV_SHOWN)."""
    res = radv_statistics([Job(k, p["stages"]) for k, p in prepared.items()], families)
    assert not res.errors, res.errors
    return {k: {f: {ours: (res.of(f, k, "frag") or {}).get(theirs) for theirs, ours in RADV_SHOWN.items()}
                for f in families} for k in prepared}


def markdown(out: dict) -> str:
    rows = out["cases"]
    fam = out["families"]
    md = ["# The light loop: static list, one loop per type, one loop with a switch", "",
          f"{out['generator']}, {out['device']}, {out['size'][0]}x{out['size'][1]}, GLSL, {out['frames']} frames x "
          f"{out['rounds']} interleaved rounds per case{' — QUICK RUN (smoke test, not the full benchmark)' if out['quick'] else ''}.",
          "Written by `benchmarks/lights.py`; half the lights point, half spot (1 light: one point, where the two "
          "dynamic forms are the same shader but for the switch).", "",
          "## Frame time on lavapipe and build cost", "",
          "| lights | form | key's lights | permutations | cold build s | GPU ms/frame | / static | / types "
          "| shadow maps (layers) | shadow-map memory |",
          "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for k, r in rows.items():
        base = rows.get(name_of(r["lights"], "static", r["shadow"]))
        types = rows.get(name_of(r["lights"], "ranged" if r["form"] == "tiles" else "types", "none"))
        vs_static = f"{r['gpu_ms'] / base['gpu_ms']:.2f}" if base and r["form"] not in ("ranged", "tiles") else ""
        vs_types = f"{r['gpu_ms'] / types['gpu_ms']:.2f}" if types and r["form"] in ("switch", "tiles") else ""
        mem = f"{r['shadow_map_bytes'] / 2 ** 20:.1f} MiB" if r["shadow_map_bytes"] else "0"
        form = LABEL.get(r["form"], r["form"]) + ("" if r["shadow"] == "none" else f" ({r['shadow']})")
        key = r["ball_key"] if len(r["ball_key"]) <= 48 else r["ball_key"][:45] + "…"
        md.append(f"| {r['lights']} | {form} | `{key}` | {r['permutations']} | "
                  f"{r['cold_build_s']:.2f} | {r['gpu_ms']:.2f} | {vs_static} | {vs_types} | {r['shadow_maps']} | {mem} |")
    md += ["", "Permutations to cover every light count above, per material: static one per count "
           f"({out['static_counts']} counts × 2 materials = {2 * len(out['static_counts'])} shaders), dynamic one "
           "(2 shaders, whatever the count up to `max`). / static: against the static list of the same lights and "
           "shadows; / types: the switch loop against the types loop, and the tiled loops against the same ranged "
           f"lights untiled (point_range and spots of radius {RANGE} on a circle of radius 2.5; the renderer's CPU "
           "culling, 16-pixel tiles). A dynamic shadowed pair's maps are one 2D array of the same layers the static "
           "set's separate maps hold, so their memory is equal (an engine's array is sized max × layers: "
           "the manifest's capacity_bytes).", "",
           "## RADV (null device, ACO): the ball's fragment shader", "",
           "VGPRs / instructions / latency (cycles, ACO's estimate) / waves per SIMD (occupancy). The dynamic forms' "
           "code does not depend on the light count, so one row per form covers every count.", "",
           "| lights | form | " + " | ".join(fam) + " |", "|---:|---|" + "---|" * len(fam)]
    seen = set()
    for k, r in rows.items():
        sig = (r["form"], r["shadow"]) if r["form"] != "static" else k
        if sig in seen:
            continue
        seen.add(sig)
        cells = [" / ".join(str(r["radv"][f][x]) for x in ("vgprs", "instructions", "latency", "waves_per_simd"))
                 for f in fam]
        lights = r["lights"] if r["form"] == "static" else "any"
        form = LABEL.get(r["form"], r["form"]) + ("" if r["shadow"] == "none" else f" ({r['shadow']})")
        md.append(f"| {lights} | {form} | " + " | ".join(cells) + " |")
    md += ["", "## Model", "", out["model"], ""]
    return "\n".join(md)


MODEL = ("Per pixel a light costs its direction, its radiance, its visibility and one BRDF evaluation whatever the "
         "form, so frame time grows linearly in the light count; the forms differ in what surrounds that work. The "
         "static list unrolls it: no loop, no buffer reads, its values in a uniform block, every light's code "
         "specialized to its type (the cap of 32 is SPIR-V's 255 function arguments, not cost). The types loop adds "
         "per light a storage-buffer read and a loop iteration, and per type one loop. The switch loop adds to that "
         "one more vec4 per light (its ids) and two branches on the type (direction; radiance and visibility), and "
         "its element is as wide as the widest pair's (a point light reads a spot's 48 bytes of data); in exchange "
         "one BRDF evaluation serves every type, so its code grows by a light brick per type, not by a whole loop "
         "body. The switch is uniform (every pixel of a draw reads the same element at the same iteration), so it "
         "costs a branch, not divergence. ACO's latency is a static estimate of the code: a loop body is counted "
         "once, so the dynamic forms' latency does not grow with the light count while the static list's does; it "
         "ranks code, it is not a frame time.")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=positive, default=12, help="timed frames per render (default 12)")
    ap.add_argument("--rounds", type=positive, default=4, help="interleaved renders per case (default 4)")
    ap.add_argument("--size", type=size_arg, default="320x160", help="WxH (default 320x160)")
    ap.add_argument("--quick", action="store_true", help="a smoke run: 1, 4, 64 lights, 2 frames, 1 round")
    ap.add_argument("--out", type=Path, default=RESULTS, help="results folder (default benchmarks/results)")
    args = ap.parse_args()
    frames, rounds = (2, 1) if args.quick else (args.frames, args.rounds)
    size = tuple(int(x) for x in args.size.split("x"))
    lib = load_library()
    device = Device()
    out = {"generator": f"shadermatrix {__version__}", "device": device.name, "size": list(size), "frames": frames,
           "rounds": rounds, "quick": args.quick, "families": list(DEFAULT_FAMILIES),
           "static_counts": list((1, 4) if args.quick else STATIC_COUNTS)}
    with tempfile.TemporaryDirectory() as tmp:
        prepared = {name_of(*c): {**prepare(lib, Path(tmp), c), "case": c} for c in cases(args.quick)}
        # lavapipe's one-time set-up (its first pipelines and draws) paid before anything is timed
        first = next(iter(prepared.values()))
        render_scene(first["scene"], lib, "specialized", 2, Path(tmp) / "warm-up", size, "glsl", device=device)
        times = frame_times(lib, prepared, device, size, frames, rounds)
        device.close()
        stats = radv(prepared, DEFAULT_FAMILIES)
    out["cases"] = {k: {"lights": p["case"][0], "form": p["case"][1], "shadow": p["case"][2],
                        "ball_key": p["ball_key"], "permutations": p["permutations"],
                        "cold_build_s": round(p["cold_build_s"], 3), **times[k], "radv": stats[k]}
                    for k, p in prepared.items()}
    out["model"] = MODEL
    args.out.mkdir(parents=True, exist_ok=True)
    atomic_write(args.out / "lights.json", (json.dumps(out, indent=2) + "\n").encode())
    atomic_write(args.out / "lights.md", markdown(out).encode())
    print((args.out / "lights.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
