"""The build at build-system scale: cold, against the compilers' own floor, no-op, one brick; -j and Dask.

    .venv/bin/python benchmarks/build.py [--n 1000] [--seed 0] [--scaling] [--report-only]

One run, on this machine, side by side. The scene is `benchmarks/scenegen.py N --fixed --seed S`: N distinct
permutations drawn from a fixed brick list, so that the figures do not move when the library gains bricks.

- cold build: `shadermatrix build` with an empty cache and output directory (wall time; the CPU of it, its
  workers and their tools; peak memory);
- the compiler floor: the build's distinct shaders through the same pinned tools with the best invocation
  each allows and no Python of ours — glslc batched (256 files a process), naga, spirv-opt -O and
  spirv-val once per file, glslangValidator on the OpenGL / ES sources in batches of 256, all with xargs -P the
  core count (wall time and the tools' CPU);
- no-op rebuild (best of 3): time and files written;
- one brick changed (ndf=beckmann's source hash, in process, as tests/assemble/test_incremental.py does): time and
  permutations rebuilt, against the permutations that read it;
- with --scaling: cold builds without the cache at -j 1 and -j 2 (worker processes), -j 2 in-process
  (composition and analysis in the building process, pipelined with 2 tool processes), and on a Dask
  LocalCluster of 1 and 2 workers, their outputs compared (the building process's CPU on a CLI-started cluster:
  benchmarks/dask_build.py);
- scene loading: 1,000 and 10,000 objects over five permutations.

Every command runs with bytecode caching as on an ordinary installation (PYTHONDONTWRITEBYTECODE is removed
from the environment: where it is set, as on the machine these results came from, each run compiles the
package again, +0.3 s on the no-op). The default run (no --scaling) takes ~10-15 min at 1,000 on 2 cores.

Targets: cold ≤ 1.3 × floor; no-op ≤ 0.5 s with 0 files written; a one-brick change rebuilds
only what reads it. Writes benchmarks/results/build.md and build.json.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
RESULTS = REPO / "benchmarks" / "results"
sys.path.insert(0, str(REPO))

from generator import __version__  # noqa: E402
sys.path.insert(0, str(REPO / "benchmarks"))
from cliargs import positive  # noqa: E402
from generator.toolchain import TARGET_ENV, find_tool, tool_versions  # noqa: E402


ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def cli(*args, env=None) -> tuple[float, subprocess.CompletedProcess]:
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                       text=True, env=env or ENV)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, args))} failed:\n{r.stderr[-2000:]}")
    return time.perf_counter() - t, r


_MEASURED = """
import resource, sys
import generator.assemble.parallel as parallel
if {in_process}:
    parallel.MIN_PERMUTATIONS = float("inf")
from generator.cli import main
rc = main({argv!r})
ru = resource.getrusage(resource.RUSAGE_SELF)
print(f"building-process-cpu {{ru.ru_utime + ru.ru_stime}}", file=sys.stderr)
sys.exit(rc)
"""


def measured(*args, in_process: bool = False) -> tuple[float, float]:
    """(wall seconds, the building process's own CPU seconds) of `shadermatrix ARGS`; in_process: as -j N
    builds without worker processes (composition and analysis in the building process)."""
    code = _MEASURED.format(in_process=in_process, argv=[str(a) for a in args])
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, env=ENV)
    wall = time.perf_counter() - t
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, args))} failed:\n{r.stderr[-2000:]}")
    return wall, float(re.search(r"building-process-cpu (\S+)", r.stderr)[1])


def scene_load(tmp: Path) -> dict:
    """Seconds to load the example scene's objects repeated to 1,000 and 10,000 (five permutations)."""
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    base = (REPO / "scenes" / "example.toml").read_text()
    head, rest = base.split("[[objects]]", 1)
    objects = ["[[objects]]" + o for o in ("[[objects]]" + rest).split("[[objects]]")[1:]]
    lib, out = load_library(), {}
    for n in (1_000, 10_000):
        path = tmp / f"objects_{n}.toml"
        path.write_text(head + "".join(o.replace('name = "', f'name = "n{i}_', 1)
                                       for i, o in enumerate(objects[k % len(objects)] for k in range(n))))
        best = float("inf")
        for _ in range(3):
            t = time.perf_counter()
            load_scene(path, lib)
            best = min(best, time.perf_counter() - t)
        out[str(n)] = best
    return out


def _content_key(language: str, stage: str, text: str) -> str:
    """A source's identity as the compile cache sees it: its language, its stage, its text without comment lines."""
    return hashlib.sha256(f"{language}{stage}".encode() + "\n".join(
        x for x in text.split("\n") if not x.lstrip().startswith("//")).encode()).hexdigest()


def distinct_shaders(out: Path, dest: Path) -> dict[str, int]:
    """Copy the build's distinct shaders (comments aside, as the compile cache keys them) into dest/<lang>/<stage>."""
    m = json.loads((out / "manifest.json").read_text())
    seen, counts = set(), {}
    for e in [*m["permutations"], m["ubershader"], *m.get("depth_shaders", {}).values()]:
        for lang, stages in e.get("languages", {}).items():
            for stage, item in stages.items():
                text = (out / item["source"]).read_text()
                key = _content_key(lang, stage, text)
                if key in seen:
                    continue
                seen.add(key)
                d = dest / lang / stage
                d.mkdir(parents=True, exist_ok=True)
                (d / f"{key[:16]}.{lang}").write_text(text)
                counts[f"{lang}.{stage}"] = counts.get(f"{lang}.{stage}", 0) + 1
    return counts


def gl_sources(out: Path, dest: Path) -> int:
    """Copy the build's distinct OpenGL and ES sources (comments aside) into dest/gl/<dialect>/<key>.<stage> (the
    extension gives glslangValidator the stage); how many."""
    m = json.loads((out / "manifest.json").read_text())
    seen = set()
    for e in m["permutations"]:
        for stage, dialects in e["platforms"].get("gl", {}).get("stages", {}).items():
            for dialect, item in dialects.items():
                text = (out / item["path"]).read_text()
                key = _content_key(dialect, stage, text)
                if key in seen:
                    continue
                seen.add(key)
                d = dest / "gl" / dialect
                d.mkdir(parents=True, exist_ok=True)
                (d / f"{key[:16]}.{stage}").write_text(text)
    return len(seen)


def floor(src: Path, cores: int) -> float:
    """Wall seconds for the pinned tools alone on every distinct shader (a shell pipeline, no Python)."""
    glslc, naga = find_tool("glslc"), find_tool("naga")
    opt, val = find_tool("spirv-opt"), find_tool("spirv-val")
    q = shlex.quote
    script = ["set -e"]
    for lang in ("glsl", "hlsl"):
        for stage_dir in sorted((src / lang).iterdir()):
            script.append(f"cd {q(str(stage_dir))} && ls *.{lang} | xargs -P {cores} -n 256 {q(glslc)} "
                          f"--target-env={TARGET_ENV} -c -x {lang} -fshader-stage={stage_dir.name} -fentry-point=main")
    if (src / "gl").is_dir():  # the OpenGL / ES validation: one glslangValidator process validates a batch
        gl = q(find_tool("glslangValidator"))
        for dialect in sorted((src / "gl").iterdir()):
            script.append(f"cd {q(str(dialect))} && ls | xargs -P {cores} -n 256 {gl}")
    for stage_dir in sorted((src / "wgsl").iterdir()):
        script.append(f"cd {q(str(stage_dir))} && ls *.wgsl | xargs -P {cores} -I{{}} {q(naga)} --spirv-version 1.3 "
                      "--keep-coordinate-space {} {}.spv")
    script.append(f"cd {q(str(src))} && find . -name '*.spv' | xargs -P {cores} -I{{}} {q(opt)} "
                  f"--target-env={TARGET_ENV} -O {{}} -o {{}}.opt")
    script.append(f"cd {q(str(src))} && find . -name '*.opt' | xargs -P {cores} -I{{}} {q(val)} "
                  f"--target-env {TARGET_ENV} {{}}")
    t = time.perf_counter()
    subprocess.run(["bash", "-c", " && ".join(script)], check=True, capture_output=True)
    return time.perf_counter() - t


def one_brick(scene_path: Path, out: Path, cache: Path) -> dict:
    """Rebuild after ndf=beckmann's source changes (its hash, in process): time, rebuilt, readers."""
    import copy

    from generator.assemble import BuildContext, build
    from generator.io import Store
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    scene = load_scene(scene_path, lib)
    key = ("ndf", "beckmann")
    edited = copy.copy(lib.bricks[key])
    edited.module = copy.copy(edited.module)
    edited.module.source_hash = hashlib.sha256(b"edited").hexdigest()
    lib.bricks[key] = edited
    readers = sum(1 for p in scene.permutations.values() if "ndf=beckmann" in p.brdf)
    t = time.perf_counter()
    res = build(scene, out, BuildContext(lib, store=Store(cache)))
    return {"seconds": time.perf_counter() - t, "rebuilt": len(scene.permutations) - res.kept, "readers": readers,
            "compiled": res.compile.compiled, "from_cache": res.compile.cached}


def dask_build(scene: Path, out: Path, workers: int) -> float:
    from distributed import LocalCluster
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        seconds, _ = cli("build", scene, "--out", out, "--no-cache", "--executor",
                         "dask://" + c.scheduler_address.removeprefix("tcp://"))
    return seconds


def _machine_cpu() -> float:
    """Seconds of CPU the whole machine has spent (/proc/stat: every state but idle and iowait). A build's worker
    processes are a forkserver's children, which the building process never waits for, so its RUSAGE_CHILDREN
    leaves them out; on a quiet machine the difference across a run is that run's CPU, the floor's alike."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    return (sum(fields[:8]) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=positive, default=1000, help="distinct permutations of the generated scene")
    ap.add_argument("--seed", type=int, default=0, help="the generated scene's shuffle (scenegen.py --seed)")
    ap.add_argument("--scaling", action="store_true",
                    help="also build without the cache at -j 1, -j 2, -j 2 in-process and on a Dask LocalCluster of "
                         "1 and 2 workers (another ~25 min at 1,000 on 2 cores)")
    ap.add_argument("--report-only", action="store_true", help="rewrite build.md from the recorded build.json")
    args = ap.parse_args()
    if args.report_only:
        report(json.loads((RESULTS / "build.json").read_text()))
        return 0
    cores = os.cpu_count() or 1
    res: dict = {"generator": f"shadermatrix {__version__}", "tools": tool_versions(), "cores": cores,
                 "permutations": args.n, "scene": f"scenegen.py {args.n} --fixed --seed {args.seed}"}
    with tempfile.TemporaryDirectory(prefix="shadermatrix-bench-") as tmp:
        tmp = Path(tmp)
        scene = tmp / f"generated_{args.n}.toml"
        subprocess.run([sys.executable, str(REPO / "benchmarks" / "scenegen.py"), str(args.n), str(scene), "--fixed",
                        "--seed", str(args.seed)], check=True)
        out, cache = tmp / "out", tmp / "cache"
        before, cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, _machine_cpu()
        res["cold_s"], r = cli("build", scene, "--out", out, "--cache-dir", cache)
        res["cold_cpu_s"] = _machine_cpu() - cpu0  # the building process, its workers and their tools (and the rest)
        res["cold_peak_mb"] = max(before, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024
        m = re.search(r"(\d+) shaders, (\d+) distinct \((\d+) merged\), (\d+) from the cache, (\d+) compiled; "
                      r"(\d+) files written", r.stdout)
        res["shaders"], res["distinct"], res["merged"], _, res["compiled"], res["files"] = map(int, m.groups())
        counts = distinct_shaders(out, tmp / "floor")
        res["floor_shaders"] = sum(counts.values())
        res["floor_gl_sources"] = gl_sources(out, tmp / "floor")
        cpu0 = _machine_cpu()
        res["floor_s"] = floor(tmp / "floor", cores)
        res["floor_cpu_s"] = _machine_cpu() - cpu0
        res["cold_over_floor"] = res["cold_s"] / res["floor_s"]
        # the floor as if its tools kept every core busy (its CPU over the cores): what no scheduling can beat
        res["cold_over_cpu_floor"] = res["cold_s"] / (res["floor_cpu_s"] / cores)
        noop = []
        for _ in range(3):
            seconds, r = cli("build", scene, "--out", out, "--cache-dir", cache)
            noop.append(seconds)
            assert "0 files written" in r.stdout, r.stdout[-500:]
        res["noop_s"], res["noop_files_written"] = min(noop), 0
        res["one_brick"] = one_brick(scene, out, cache)
        if args.scaling:
            res["scaling"] = scaling(scene, tmp)
        res["scene_load_s"] = scene_load(tmp)
        shutil.rmtree(tmp / "floor", ignore_errors=True)
    res["targets"] = {"cold_le_1.3x_floor": res["cold_over_floor"] <= 1.3,
                      "noop_le_0.5s_0_files": res["noop_s"] <= 0.5 and res["noop_files_written"] == 0,
                      "one_brick_rebuilds_only_readers": res["one_brick"]["rebuilt"] == res["one_brick"]["readers"]}
    (RESULTS / "build.json").write_text(json.dumps(res, indent=2) + "\n")
    report(res)
    return 0


def scaling(scene: Path, tmp: Path) -> dict:
    """Cold builds without the cache: -j 1, -j 2, -j 2 in-process, Dask LocalCluster of 1 and 2 workers."""
    sc: dict = {}
    sc["j1_s"], sc["j1_cpu_s"] = measured("build", scene, "--out", tmp / "j1", "--no-cache", "-j", "1")
    sc["j2_s"], sc["j2_cpu_s"] = measured("build", scene, "--out", tmp / "j2", "--no-cache", "-j", "2")
    sc["j2_in_process_s"], sc["j2_in_process_cpu_s"] = measured(
        "build", scene, "--out", tmp / "j2p", "--no-cache", "-j", "2", in_process=True)
    sc["dask1_s"] = dask_build(scene, tmp / "d1", 1)
    sc["dask2_s"] = dask_build(scene, tmp / "d2", 2)
    sc["identical_outputs"] = all(
        subprocess.run(["diff", "-rq", "-x", ".shadermatrix-lock", str(tmp / "j1"), str(tmp / d)],
                       capture_output=True).returncode == 0 for d in ("j2", "j2p", "d1", "d2"))
    for d in ("j1", "j2", "j2p", "d1", "d2"):
        shutil.rmtree(tmp / d, ignore_errors=True)
    return sc


def model(res: dict) -> dict:
    """Per-permutation costs from the run (CPU: the cold build's processes against the floor's tools), what they
    make of the cold / floor ratio, and what they predict at 100,000 on one machine with -j."""
    n = res["permutations"]
    tools = res["floor_cpu_s"] / n  # the pinned tools' CPU per permutation, invoked as well as they allow
    ours = max(0.0, res["cold_cpu_s"] - res["floor_cpu_s"]) / n  # everything else the cold build spent
    out = {"tools_cpu_ms_per_permutation": tools * 1e3, "ours_cpu_ms_per_permutation": ours * 1e3,
           "distinct_per_permutation": res["distinct"] / n,
           # on cores that the CPU keeps busy, cold / floor ≈ (tools + ours) / tools
           "cpu_bound_ratio": (tools + ours) / tools if tools else float("inf"),
           "ours_for_1.3_ms": 0.3 * tools * 1e3, "local": []}
    for perms, c in ((100_000, 16), (100_000, 64)):
        out["local"].append({"permutations": perms, "cores": c, "build_s": perms * (tools + ours) / c})
    return out


def report(res: dict) -> None:
    cores, n = res["cores"], res["permutations"]
    ob = res["one_brick"]
    yes = {True: "met", False: "not met"}
    load = res["scene_load_s"]
    t = res["targets"]
    md = [f"# The build at scale: {n:,} generated permutations on {cores} cores", "",
          f"Generated by `benchmarks/build.py` ({res['generator']}; glslc {res['tools']['glslc']}, naga "
          f"{res['tools']['naga']}, SPIRV-Tools {res['tools']['spirv-tools']}), one run, side by side; the scene is "
          f"`{res['scene']}` (a fixed brick list: it does not grow with the library).", "",
          "| measure | value | target |", "|---|---|---|",
          f"| cold build, default -j ({cores} worker processes; {res['shaders']:,} shaders, {res['distinct']:,} "
          f"distinct, {res['merged']:,} merged; {res['files']:,} files) | {res['cold_s']:.1f} s, CPU {res['cold_cpu_s']:.0f} s, "
          f"peak {res['cold_peak_mb']:.0f} MB | |",
          f"| compiler floor: the {res['floor_shaders']:,} distinct shaders and {res['floor_gl_sources']:,} OpenGL / ES "
          f"sources through the pinned tools alone | {res['floor_s']:.1f} s, CPU {res['floor_cpu_s']:.0f} s | |",
          f"| cold / floor | {res['cold_over_floor']:.2f} | ≤ 1.3: {yes[t['cold_le_1.3x_floor']]} |",
          f"| cold / (the floor's CPU / {cores} cores): against tools that kept every core busy | "
          f"{res['cold_over_cpu_floor']:.2f} | |",
          f"| no-op rebuild (best of 3) | {res['noop_s']:.2f} s, {res['noop_files_written']} files written | "
          f"≤ 0.5 s, 0 files: {yes[t['noop_le_0.5s_0_files']]} |",
          f"| one brick changed (ndf=beckmann) | {ob['seconds']:.1f} s, {ob['rebuilt']} permutations rebuilt of "
          f"{ob['readers']} that read it ({ob['compiled']} shaders compiled, {ob['from_cache']} from the cache) | "
          f"only its readers: {yes[t['one_brick_rebuilds_only_readers']]} |",
          f"| scene load, 1,000 / 10,000 objects (five permutations) | {load['1000']:.3f} s / {load['10000']:.3f} s | "
          f"10,000 well under a second: {yes[load['10000'] < 1.0]} |"]
    sc = res.get("scaling")
    if sc:
        md += [f"| cold, no cache: -j 1 / -j 2 (worker processes) / -j 2 in-process | {sc['j1_s']:.1f} s / "
               f"{sc['j2_s']:.1f} s / {sc['j2_in_process_s']:.1f} s | |",
               f"| the building process's own CPU in those three | {sc['j1_cpu_s']:.1f} s / {sc['j2_cpu_s']:.1f} s / "
               f"{sc['j2_in_process_cpu_s']:.1f} s | |",
               f"| cold, no cache, Dask LocalCluster of 1 / 2 workers | {sc['dask1_s']:.1f} s / {sc['dask2_s']:.1f} s | |",
               f"| outputs of -j 1, -j 2, -j 2 in-process, Dask 1, Dask 2 byte-identical | {sc['identical_outputs']} | |"]
    mo = model(res)
    md += ["", "## Where the time goes", "",
           f"CPU per permutation, from this run: the pinned tools {mo['tools_cpu_ms_per_permutation']:.0f} ms (the "
           f"floor's CPU over {n:,}; {mo['distinct_per_permutation']:.2f} distinct shaders a permutation), everything "
           f"else the cold build spent {mo['ours_cpu_ms_per_permutation']:.0f} ms (our Python in the workers and the "
           "building process, and the tools' work beyond the floor's: one process per shader where the floor batches, "
           "filling the cache; the machine's CPU, /proc/stat, so anything else it ran too). With every core busy, "
           f"cold / floor ≈ (tools + the rest) / tools = {mo['cpu_bound_ratio']:.2f}; 1.3 needs the rest at ≤ "
           f"{mo['ours_for_1.3_ms']:.0f} ms. The floor itself keeps {res['floor_cpu_s'] / res['floor_s']:.2f} of "
           f"the {cores} cores busy on average (its steps run one after another, and the ubershader's few large "
           "shaders end each step alone), which the build's workers, overlapping every step, do not wait for: hence "
           "the second ratio, against the floor's CPU spread over every core.", "",
           "At 100,000 permutations on one machine with `-j C` (the workers scale with the cores; the building "
           "process's own share and Dask: [dask.md](dask.md)):", "",
           "| permutations | cores (-j) | build |", "|---|---|---|"]
    for p in mo["local"]:
        md.append(f"| {p['permutations']:,} | {p['cores']} | {p['build_s'] / 60:.1f} min |")
    md.append("")
    (RESULTS / "build.md").write_text("\n".join(md))
    print("\n".join(md))


if __name__ == "__main__":
    sys.exit(main())
