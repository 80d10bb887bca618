"""The build toward 100,000 permutations: planning, a cold build, its no-op, and packs only.

    .venv/bin/python benchmarks/scale.py [--permutations 10000] [--plan 10000,100000] [--work DIR [--reuse]]
                                         [--report-only]

One run, on this machine (benchmarks/scenegen.py makes each scene: N distinct permutations, one object each, and
`ubershader = false`: one ubershader of 10,000 permutations' 9,526 material variants is 12 MB of GLSL whose compile
ran for over 45 minutes here — the build warns about such a scene, and an engine with this many wants none):

- plan: `shadermatrix matrix SCENE --no-compile` (load the scene, resolve every permutation, count the matrix:
  full product, valid, used) for each size of --plan: the command's own CPU time and peak memory (RSS), and its
  wall time;
- a cold build of --permutations N (empty output directory and compile cache, the default -j): wall time, the CPU
  time of the building process and of all its children (workers, tools), peak memory of each, files written;
- its no-op rebuild (best of 3): wall time, files written (the tree's mtimes compared before and after), and
  whether it loaded the scene (a run whose scene loader raises must still say "up to date"); and the same no-op
  decided by the full path (another compile cache: no record of the last build), which loads the scene;
- the same scene with --pack-only into another directory (the compile cache warm from the cold build, so its
  time is composing, analysing and writing): wall time, files in the tree, its no-op as above.

--work DIR builds in DIR (kept) instead of a temporary directory; with --reuse, a DIR holding the trees of an
earlier run of the same --permutations is measured again without building (the plan and the no-ops: on a
quieter machine, say), its builds' figures taken from the scale.json that run wrote.

The CPU and memory figures are the processes' own (getrusage), so that other work on a shared machine changes
them less than it changes wall times. Writes benchmarks/results/scale.md and scale.json; the model there extends
the per-permutation figures to 100,000 permutations.

Targets: plan ≤ 10 s for 10,000 and ≤ 60 s for 100,000 within 2 GB; the 10,000-permutation no-op ≤ 1 s, 0 files
written, the scene not loaded; the same for --pack-only.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
RESULTS = REPO / "benchmarks" / "results"
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))
from cliargs import positive  # noqa: E402

ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as an ordinary installation runs

# `shadermatrix ARGV` in this child, its own and its children's resource use on stderr; refuse_loading: a scene
# or brick loader that raises (a no-op that gets past its check fails)
_MEASURED = """
import json, resource, sys
if {refuse_loading}:
    import generator.library.bricks as bricks
    import generator.scene.load as load
    def refuse(*args, **kwargs):
        raise SystemExit("the scene loader was reached")
    bricks.load_library = load.load_scene = refuse
from generator.cli import main
rc = main({argv!r})
# the worker processes are the forkserver's children: wait for it, so that their CPU (and their tools', which they
# waited for) is counted in this process's children
# (a private API of CPython's: where it is missing the workers' CPU is not counted, and the result says so)
import multiprocessing.forkserver as fs
server = getattr(fs, "_forkserver", None)
waited = callable(getattr(server, "_stop", None))
if waited and getattr(server, "_forkserver_pid", None) is not None:
    server._stop()
me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
print("measured " + json.dumps({{"workers_waited": waited,
                               "cpu_s": me.ru_utime + me.ru_stime, "children_cpu_s": kids.ru_utime + kids.ru_stime,
                               "peak_mb": me.ru_maxrss / 1024, "children_peak_mb": kids.ru_maxrss / 1024}}),
      file=sys.stderr)
sys.exit(rc)
"""


def measured(*args, refuse_loading: bool = False, check: bool = True) -> dict:
    """Run `shadermatrix ARGS`: {"wall_s", "cpu_s", "children_cpu_s", "peak_mb", "children_peak_mb", "rc",
    "stdout"}."""
    code = _MEASURED.format(refuse_loading=refuse_loading, argv=[str(a) for a in args])
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, env=ENV)
    wall = time.perf_counter() - t
    m = re.search(r"^measured (.*)$", r.stderr, re.M)
    if check and (r.returncode != 0 or m is None):
        raise SystemExit(f"{' '.join(map(str, args))} failed:\n{r.stderr[-3000:]}")
    return {"wall_s": wall, **(json.loads(m[1]) if m else {}), "rc": r.returncode, "stdout": r.stdout}


def generate(n: int, path: Path) -> Path:
    subprocess.run([sys.executable, str(REPO / "benchmarks" / "scenegen.py"), str(n), str(path), "--no-ubershader"],
                   check=True)
    old = time.time() - 3600  # an input newer than the build's start is not recorded (assemble/noop.py)
    os.utime(path, (old, old))
    return path


def plan(scene: Path) -> dict:
    r = measured("matrix", scene, "--no-compile")
    counts = {m[1]: int(m[2].replace(",", "")) for m in re.finditer(r"^\| (full product|valid|used) \| ([\d,]+) \|",
                                                                     r["stdout"], re.M)}
    return {k: r[k] for k in ("wall_s", "cpu_s", "peak_mb")} | {"counts": counts}


def tree(out: Path) -> dict[str, int]:
    return {str(p): p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()}


def written(stdout: str) -> int:
    return int(re.search(r"(\d+) files written", stdout)[1])


def noop(scene: Path, out: Path, cache: Path, *flags) -> dict:
    """Best of 3 no-ops, the tree unchanged; then one whose scene loader raises; then the full path's."""
    before, runs = tree(out), []
    for _ in range(3):
        r = measured("build", scene, "--out", out, "--cache-dir", cache, *flags, "-q")
        assert "up to date" in r["stdout"], r["stdout"][-500:]
        runs.append(r)
    best = min(runs, key=lambda r: r["wall_s"])
    unchanged = tree(out) == before
    blind = measured("build", scene, "--out", out, "--cache-dir", cache, *flags, "-q", refuse_loading=True, check=False)
    empty = cache.parent / f"{cache.name}-empty"
    shutil.rmtree(empty, ignore_errors=True)  # no record of the last build there (a --reuse run made one)
    full = measured("build", scene, "--out", out, "--cache-dir", empty, *flags, "-q")
    return {"wall_s": best["wall_s"], "cpu_s": best["cpu_s"], "files_written": written(best["stdout"]),
            "tree_unchanged": unchanged, "scene_not_loaded": blind["rc"] == 0 and "up to date" in blind["stdout"],
            "full_path_wall_s": full["wall_s"], "full_path_cpu_s": full["cpu_s"], "full_path_peak_mb": full["peak_mb"]}


def cold(scene: Path, out: Path, cache: Path, *flags) -> dict:
    r = measured("build", scene, "--out", out, "--cache-dir", cache, *flags, "-q")
    files = sum(1 for p in out.rglob("*") if p.is_file())
    size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    return {k: r[k] for k in ("wall_s", "cpu_s", "children_cpu_s", "peak_mb", "children_peak_mb")} | {
        "files_written": written(r["stdout"]), "files": files, "bytes": size}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--permutations", type=positive, default=10_000, help="the built scene's permutations")
    ap.add_argument("--plan", default="10000,100000", type=_sizes,
                    help="comma-separated scene sizes to plan (matrix --no-compile), default 10000,100000")
    ap.add_argument("--work", metavar="DIR", type=Path, help="build in DIR and keep it (default: a temporary directory)")
    ap.add_argument("--reuse", action="store_true",
                    help="with --work: measure the trees an earlier run left there again, without building")
    ap.add_argument("--report-only", action="store_true", help="rewrite scale.md from the recorded scale.json")
    args = ap.parse_args()
    if args.reuse and args.work is None:
        ap.error("--reuse needs --work DIR")
    if args.report_only:
        report(json.loads((RESULTS / "scale.json").read_text()))
        return 0
    from generator import __version__
    from generator.toolchain import tool_versions
    res: dict = {"generator": f"shadermatrix {__version__}", "tools": tool_versions(), "cores": os.cpu_count() or 1,
                 "permutations": args.permutations, "plan": {}}
    with contextlib.ExitStack() as stack:
        if args.work is None:
            tmp = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="shadermatrix-scale-")))
        else:
            tmp = args.work.resolve()
            tmp.mkdir(parents=True, exist_ok=True)
        for n in args.plan:
            scene = generate(n, tmp / f"plan_{n}.toml")
            res["plan"][str(n)] = plan(scene) | {"scene_bytes": scene.stat().st_size}
            scene.unlink()
        cache = tmp / "cache"
        if args.reuse:
            earlier = json.loads((RESULTS / "scale.json").read_text())
            scene = tmp / f"generated_{args.permutations}.toml"
            if earlier.get("permutations") != args.permutations or not scene.is_file() or not (tmp / "packs").is_dir():
                raise SystemExit(f"--reuse: {tmp} holds no run of {args.permutations} permutations recorded in "
                                 "scale.json — run without --reuse first")
            res["cold"], res["pack_only"] = earlier["cold"], earlier["pack_only"]
            res["reused"] = True
        else:
            scene = generate(args.permutations, tmp / f"generated_{args.permutations}.toml")
            shutil.rmtree(tmp / "loose", ignore_errors=True)
            shutil.rmtree(tmp / "packs", ignore_errors=True)
            shutil.rmtree(cache, ignore_errors=True)
            res["cold"] = cold(scene, tmp / "loose", cache)
            res["pack_only"] = cold(scene, tmp / "packs", cache, "--pack-only")
        if (tmp / "loose").is_dir():
            res["noop"] = noop(scene, tmp / "loose", cache)
        else:
            res["noop"] = json.loads((RESULTS / "scale.json").read_text())["noop"]
        res["pack_only_noop"] = noop(scene, tmp / "packs", cache, "--pack-only")
    (RESULTS / "scale.json").write_text(json.dumps(res, indent=2) + "\n")
    report(res)
    return 0


def _sizes(text: str) -> list[int]:
    try:
        return [positive(x) for x in text.split(",")]
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of whole numbers of at least 1") \
            from None


def targets(res: dict) -> dict[str, bool]:
    p10, p100 = res["plan"].get("10000"), res["plan"].get("100000")
    ok = {}
    if p10:
        ok["plan 10,000 ≤ 10 s"] = p10["cpu_s"] <= 10
    if p100:
        ok["plan 100,000 ≤ 60 s within 2 GB"] = p100["cpu_s"] <= 60 and p100["peak_mb"] <= 2048
    for key, name in (("noop", "no-op"), ("pack_only_noop", "--pack-only no-op")):
        n = res[key]
        ok[f"{res['permutations']:,}-permutation {name} ≤ 1 s, 0 files written, the scene not loaded"] = (
            n["wall_s"] <= 1 and n["files_written"] == 0 and n["tree_unchanged"] and n["scene_not_loaded"])
    return ok


def model(res: dict) -> dict:
    """The run's per-permutation figures, and what they predict for 100,000 permutations."""
    n, c, po = res["permutations"], res["cold"], res["pack_only"]
    total_cpu = c["cpu_s"] + c["children_cpu_s"]
    # a run from before the forkserver was waited for counted none of its workers' CPU (nor their tools'), which in
    # any real build is more than the building process's own
    bound = c["children_cpu_s"] < c["cpu_s"] or not c.get("workers_waited", True)
    if bound:
        total_cpu = max(total_cpu, c["wall_s"] * res["cores"])  # at most every core for the whole build
    per = {"cpu_bound": bound, "cold_wall_ms": c["wall_s"] / n * 1e3, "cpu_ms": total_cpu / n * 1e3, "main_cpu_ms": c["cpu_s"] / n * 1e3,
           "files": c["files"] / n, "bytes": c["bytes"] / n}
    noop_fixed = res["pack_only_noop"]["wall_s"]  # a tree of a few files: what a no-op costs besides its files
    per_file = max(0.0, res["noop"]["wall_s"] - noop_fixed) / c["files"]
    big = 100_000
    return {"per_permutation": per, "noop_per_file_us": per_file * 1e6, "at_100000": {
        "plan_cpu_s": (res["plan"].get("100000") or {}).get("cpu_s"),
        "cold_here_h": big * per["cold_wall_ms"] / 1e3 / 3600,
        "cold_16_cores_min": max(big * per["cpu_ms"] / 1e3 / 16, big * per["main_cpu_ms"] / 1e3) / 60,
        "cold_64_cores_min": max(big * per["cpu_ms"] / 1e3 / 64, big * per["main_cpu_ms"] / 1e3) / 60,
        "loose_files": big * per["files"], "loose_gb": big * per["bytes"] / 1e9,
        "noop_loose_s": noop_fixed + big * per["files"] * per_file,
        "pack_only_files": po["files"], "pack_only_gb": po["bytes"] / n * big / 1e9, "noop_pack_only_s": noop_fixed}}


def report(res: dict) -> None:
    n, cores = res["permutations"], res["cores"]
    yes = {True: "met", False: "not met"}
    t = res["tools"]
    md = [f"# Toward 100,000 permutations: plan, a {n:,}-permutation build, its no-op, packs only ({cores} cores)", "",
          f"Generated by `benchmarks/scale.py` ({res['generator']}; glslc {t['glslc']}, naga {t['naga']}, SPIRV-Tools "
          f"{t['spirv-tools']}), one run. CPU time and peak memory are each process's own (getrusage); wall times "
          "are of a machine shared with other work.", "",
          "## Planning: `matrix --no-compile`", "",
          "| permutations | scene | CPU | wall | peak RSS | full product / valid / used |", "|---:|---:|---:|---:|---:|---|"]
    for size, p in sorted(res["plan"].items(), key=lambda kv: int(kv[0])):
        k = p["counts"]
        md.append(f"| {int(size):,} | {p['scene_bytes'] / 1e6:.1f} MB | {p['cpu_s']:.1f} s | {p['wall_s']:.1f} s | "
                  f"{p['peak_mb']:.0f} MB | {k.get('full product', 0):,} / {k.get('valid', 0):,} / {k.get('used', 0):,} |")
    c, po, no, pno = res["cold"], res["pack_only"], res["noop"], res["pack_only_noop"]
    md += ["", f"## A build of {n:,} permutations", "",
           "| | loose files (default) | `--pack-only` |", "|---|---|---|",
           f"| build, empty output directory | {c['wall_s'] / 60:.1f} min (compile cache empty) | "
           f"{po['wall_s'] / 60:.1f} min (compile cache warm: composing, analysing, writing) |",
           f"| CPU: building process / its children | {c['cpu_s']:.0f} s / {c['children_cpu_s']:.0f} s | "
           f"{po['cpu_s']:.0f} s / {po['children_cpu_s']:.0f} s |",
           f"| peak RSS: building process / largest child | {c['peak_mb']:.0f} MB / {c['children_peak_mb']:.0f} MB | "
           f"{po['peak_mb']:.0f} MB / {po['children_peak_mb']:.0f} MB |",
           f"| files in the tree (written) | {c['files']:,} ({c['files_written']:,}), {c['bytes'] / 1e9:.2f} GB | "
           f"{po['files']:,} ({po['files_written']:,}), {po['bytes'] / 1e9:.2f} GB |",
           f"| no-op (best of 3): wall, CPU | {no['wall_s']:.2f} s, {no['cpu_s']:.2f} s | "
           f"{pno['wall_s']:.2f} s, {pno['cpu_s']:.2f} s |",
           f"| no-op: files written, tree unchanged, scene not loaded | {no['files_written']}, {no['tree_unchanged']}, "
           f"{no['scene_not_loaded']} | {pno['files_written']}, {pno['tree_unchanged']}, {pno['scene_not_loaded']} |",
           f"| the same no-op by the full path (no record: it loads the scene) | {no['full_path_wall_s']:.1f} s, CPU "
           f"{no['full_path_cpu_s']:.1f} s, {no['full_path_peak_mb']:.0f} MB | {pno['full_path_wall_s']:.1f} s, CPU "
           f"{pno['full_path_cpu_s']:.1f} s |", "", "## Targets", "", "| target | status |", "|---|---|"]
    md += [f"| {name} | {yes[ok]} |" for name, ok in targets(res).items()]
    mo = model(res)
    per, big = mo["per_permutation"], mo["at_100000"]
    md += ["", "## At 100,000 permutations", "",
           f"Per permutation, measured here: {per['cold_wall_ms']:.0f} ms of wall time on {cores} cores for a cold "
           f"build, {'at most ' if per.get('cpu_bound') else ''}{per['cpu_ms']:.0f} ms of CPU in all (tools, workers, "
           f"the building process{': cores × wall, the workers not counted in this run' if per.get('cpu_bound') else ''}), of which "
           f"{per['main_cpu_ms']:.1f} ms are the building process's own (planning, writing: it does not scale with "
           f"the cores); {per['files']:.1f} files and {per['bytes'] / 1e3:.0f} KB in a loose tree. A loose no-op "
           f"costs {mo['noop_per_file_us']:.1f} µs per file of the tree beyond the pack-only no-op's "
           f"{big['noop_pack_only_s']:.2f} s (it checks every file's size).", "",
           "| at 100,000 permutations | predicted |", "|---|---|",
           f"| plan (`matrix --no-compile`) | {big['plan_cpu_s']:.0f} s of CPU (measured) |" if big["plan_cpu_s"]
           else "| plan | not measured in this run |",
           f"| cold build, this machine ({cores} cores) | {big['cold_here_h']:.1f} h |",
           f"| cold build, -j 16 / -j 64 on one machine: max(CPU / cores, the building process) | "
           f"{big['cold_16_cores_min']:.0f} min / {big['cold_64_cores_min']:.0f} min |",
           f"| loose tree | {big['loose_files']:,.0f} files, {big['loose_gb']:.0f} GB; no-op ≈ "
           f"{big['noop_loose_s']:.1f} s |",
           f"| `--pack-only` tree | {big['pack_only_files']} files, {big['pack_only_gb']:.0f} GB; no-op ≈ "
           f"{big['noop_pack_only_s']:.2f} s |", ""]
    (RESULTS / "scale.md").write_text("\n".join(md))
    print("\n".join(md))


if __name__ == "__main__":
    sys.exit(main())
