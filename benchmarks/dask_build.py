"""Whole chunks on a Dask cluster: the building process's own CPU per permutation, and the cluster at 100,000.

    .venv/bin/python benchmarks/dask_build.py [--n 1000] [--small 250] [--workers 2] [--baseline DIR] [--report-only]

A cluster is started from the `dask` CLI on this machine (`dask scheduler` and --workers `dask worker
--nthreads 1 --no-nanny` processes, ports chosen free); generated scenes of --small and --n distinct
permutations (benchmarks/scenegen.py) are built cold on it (`build --no-cache --executor dask://…`), and the
larger one locally with `-j` as many workers, byte for byte the same output (diff -r) or the run fails.

Measured per build: the building process's own CPU (time.process_time at its end: every thread of it, the
Dask client's included; nothing of the workers or the tools), and the workers' CPU from /proc — their own
(Python: composing, analysing, making the entries) and their children's (the tools they ran and waited
for). Per permutation: the building process's marginal CPU (its CPU at --n less its CPU at --small, over the
difference: what each permutation adds, Python's start-up and the bricks' loading aside) and its total over
--n; the workers' Python and the tools' CPU over --n. --baseline DIR: a checkout of an earlier commit
(`git worktree add DIR COMMIT`), measured alike on a cluster started from it, for the before column.

The model at 100,000 permutations takes these per-permutation costs: the cluster's cores do the tools and the
workers' Python, the building process its own share, the two overlapped chunk by chunk:
build ≈ max(P × (tools + workers' Python) / cores, fixed + P × building-process marginal).

Targets (the building process): ≤ 2 ms of CPU per permutation with loose files, ≤ 1 ms writing packs only.
Writes benchmarks/results/dask.md and dask.json.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
RESULTS = REPO / "benchmarks" / "results"
sys.path.insert(0, str(REPO / "benchmarks"))
from cliargs import positive  # noqa: E402

ENV = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "SHADERMATRIX_CHECK_MANIFEST")}
MODEL = (100_000, ((8, 8), (32, 8)))  # permutations; Dask workers × cores each
LOCAL_MODEL = (16, 64)  # cores of one machine, -j

_MEASURED = """
import functools, importlib, json, os, sys, time
SPENT = {{}}

def timed(label, modname, owner, name):  # the main thread's CPU in it, where the checkout has it
    try:
        mod = importlib.import_module(modname)
        holder = getattr(mod, owner) if owner else mod
        f = getattr(holder, name)
    except (ImportError, AttributeError):
        return
    @functools.wraps(f)
    def g(*a, **k):
        t = time.thread_time()
        try:
            return f(*a, **k)
        finally:
            SPENT[label] = SPENT.get(label, 0.0) + time.thread_time() - t
    setattr(holder, name, g)

for args in {phases!r}:
    timed(*args)
from generator.cli import main
rc = main({argv!r})
SPENT["main thread"] = time.thread_time()
print(f"building-process-cpu {{time.process_time()}}", file=sys.stderr)
t = os.times()
print(f"building-process-user-system {{t.user}} {{t.system}}", file=sys.stderr)
print(f"building-process-phases {{json.dumps(SPENT)}}", file=sys.stderr)
sys.exit(rc)
"""
# where the building process's CPU goes (the main thread's; the rest of the process is the Dask client's thread)
PHASES = [("load the bricks and the scene", "generator.library.bricks", None, "load_library"),
          ("load the bricks and the scene", "generator.scene.load", None, "load_scene"),
          ("plan: the keys, what is up to date", "generator.assemble", "_Build", "__init__"),
          ("write the chunks' files", "generator.assemble", None, "replay"),
          ("the manifest, tables, textures, depth passes, record", "generator.assemble", "_Build", "_finish")]


def checkout(text: str) -> str:
    """A folder holding a generator (a checkout of this repository)."""
    if not (Path(text) / "generator" / "cli").is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is not a checkout of shadermatrix (no generator/cli in it)")
    return text


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """`dask scheduler` and `workers` × `dask worker` on localhost, run from `repo` (its generator)."""

    def __init__(self, workers: int, repo: Path):
        dask = Path(sys.executable).with_name("dask")
        self.env = {**ENV, "PYTHONPATH": str(repo)}
        port = free_port()
        self.address = f"127.0.0.1:{port}"
        self.procs = [subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                        "--no-dashboard"], cwd=repo, env=self.env, stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL)]
        self.workers = [subprocess.Popen([str(dask), "worker", f"tcp://{self.address}", "--nthreads", "1",
                                          "--no-nanny", "--no-dashboard"], cwd=repo, env=self.env,
                                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                        for _ in range(workers)]
        self.procs += self.workers
        from distributed import Client
        with Client(f"tcp://{self.address}", timeout="60s") as c:
            c.wait_for_workers(workers, timeout=120)

    def cpu(self) -> tuple[float, float]:
        """(the workers' own CPU seconds, their waited-for children's: the tools), from /proc."""
        tick = os.sysconf("SC_CLK_TCK")
        own = tools = 0.0
        for p in self.workers:
            fields = Path(f"/proc/{p.pid}/stat").read_text().rsplit(")", 1)[1].split()
            utime, stime, cutime, cstime = (int(fields[k]) for k in (11, 12, 13, 14))
            own += (utime + stime) / tick
            tools += (cutime + cstime) / tick
        return own, tools

    def close(self) -> None:
        for p in self.procs:
            p.terminate()
        for p in self.procs:
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()


def measured(repo: Path, *args) -> tuple[float, float, str]:
    """(wall seconds, the building process's own CPU seconds, stdout) of `shadermatrix ARGS` run from `repo`."""
    code = _MEASURED.format(argv=[str(a) for a in args], phases=PHASES)
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code], cwd=repo, capture_output=True, text=True,
                       env={**ENV, "PYTHONPATH": str(repo)})
    wall = time.perf_counter() - t
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, args))} failed:\n{r.stderr[-2000:]}")
    cpu = float(re.search(r"building-process-cpu (\S+)", r.stderr)[1])
    user, system = (float(x) for x in re.search(r"building-process-user-system (\S+) (\S+)", r.stderr).groups())
    phases = json.loads(re.search(r"building-process-phases (.+)", r.stderr)[1])
    main_thread = phases.pop("main thread")
    phases["the rest of the main thread (the chunks' loop, settling, start-up)"] = main_thread - sum(phases.values())
    phases["its other threads (the Dask client: receiving the chunks)"] = cpu - main_thread
    phases["of all the above, the kernel's (system CPU: creating the files, most of it)"] = system
    return wall, cpu, r.stdout, phases


def on_cluster(cluster: Cluster, repo: Path, scene: Path, out: Path, n: int, extra=()) -> dict:
    own0, tools0 = cluster.cpu()
    wall, cpu, stdout, phases = measured(repo, "build", scene, "--out", out, "--no-cache", "-q", *extra, "--executor",
                                         "dask://" + cluster.address)
    own1, tools1 = cluster.cpu()
    files = int(re.search(r"(\d+) files written", stdout)[1])
    return {"permutations": n, "wall_s": wall, "building_cpu_s": cpu, "workers_python_cpu_s": own1 - own0,
            "tools_cpu_s": tools1 - tools0, "files": files, "phases_s": phases}


def same(a: Path, b: Path) -> bool:
    return subprocess.run(["diff", "-r", "-q", "-x", ".shadermatrix-lock", str(a), str(b)],
                          capture_output=True).returncode == 0


def run(repo: Path, args, tmp: Path, scenes: dict) -> dict:
    """The measurements of one checkout: Dask builds at --small and --n, a local -j build at --n."""
    helps = subprocess.run([sys.executable, "-m", "generator.cli", "build", "--help"], cwd=repo, capture_output=True,
                           text=True, env={**ENV, "PYTHONPATH": str(repo)}).stdout
    cluster = Cluster(args.workers, repo)
    packs = {}
    try:
        small = on_cluster(cluster, repo, scenes["small"], tmp / "dask-small", args.small)
        big = on_cluster(cluster, repo, scenes["n"], tmp / "dask", args.n)
        if "--pack-only" in helps:  # the packs without the loose files
            packs = {"small": on_cluster(cluster, repo, scenes["small"], tmp / "packs-small", args.small,
                                         ["--pack-only"]),
                     "n": on_cluster(cluster, repo, scenes["n"], tmp / "packs", args.n, ["--pack-only"])}
    finally:
        cluster.close()
    wall, cpu, _, _ = measured(repo, "build", scenes["n"], "--out", tmp / "local", "--no-cache", "-q", "-j",
                               str(args.workers))
    res = {"small": small, "n": big, "local": {"permutations": args.n, "wall_s": wall, "building_cpu_s": cpu},
           "identical_to_local": same(tmp / "dask", tmp / "local")}
    if packs:
        res["packs_only"] = packs
    if not res["identical_to_local"]:
        raise SystemExit(f"the Dask build of {repo} differs from its local build (diff -r {tmp / 'dask'} "
                         f"{tmp / 'local'})")
    return res


def per_permutation(res: dict) -> dict:
    """Milliseconds of CPU per permutation: marginal (the larger build less the smaller, over the difference in
    permutations: what each one adds, fixed costs aside — start-up, the bricks, the ubershader) and total."""
    n, s = res["n"], res["small"]
    extra = n["permutations"] - s["permutations"]

    def marginal(key: str) -> float:
        return (n[key] - s[key]) / extra * 1e3

    out = {"building_marginal_ms": marginal("building_cpu_s"),
           "building_total_ms": n["building_cpu_s"] / n["permutations"] * 1e3,
           "workers_python_ms": marginal("workers_python_cpu_s"),
           "workers_python_total_ms": n["workers_python_cpu_s"] / n["permutations"] * 1e3,
           "tools_ms": marginal("tools_cpu_s"),
           "tools_total_ms": n["tools_cpu_s"] / n["permutations"] * 1e3,
           "local_building_total_ms": res["local"]["building_cpu_s"] / n["permutations"] * 1e3,
           "files_per_permutation": n["files"] / n["permutations"]}
    out["building_fixed_s"] = s["building_cpu_s"] - s["permutations"] * out["building_marginal_ms"] / 1e3
    out["building_phases_marginal_ms"] = {k: (v - s["phases_s"].get(k, 0.0)) / extra * 1e3
                                          for k, v in n["phases_s"].items()}
    if "packs_only" in res:
        p, q = res["packs_only"]["n"], res["packs_only"]["small"]
        out["packs_only_building_marginal_ms"] = (p["building_cpu_s"] - q["building_cpu_s"]) / extra * 1e3
        out["packs_only_building_total_ms"] = p["building_cpu_s"] / p["permutations"] * 1e3
        out["packs_only_files_per_permutation"] = p["files"] / p["permutations"]
        out["packs_only_phases_marginal_ms"] = {k: (v - q["phases_s"].get(k, 0.0)) / extra * 1e3
                                                for k, v in p["phases_s"].items()}
    return out


def model(pp: dict) -> list[dict]:
    perms, shapes = MODEL
    work = (pp["tools_ms"] + pp["workers_python_ms"]) / 1e3  # cluster CPU seconds per permutation
    out = []
    for workers, cores in shapes:
        cluster = perms * work / (workers * cores)
        building = pp["building_fixed_s"] + perms * pp["building_marginal_ms"] / 1e3
        out.append({"permutations": perms, "workers": workers, "cores_per_worker": cores, "cluster_s": cluster,
                    "building_s": building, "build_s": max(cluster, building)})
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=positive, default=1000, help="distinct permutations of the larger generated scene")
    ap.add_argument("--small", type=positive, default=250, help="those of the smaller one (the marginal's base)")
    ap.add_argument("--workers", type=positive, default=2, help="`dask worker` processes (one thread each)")
    ap.add_argument("--baseline", metavar="DIR", type=checkout,
                    help="a checkout of an earlier commit (git worktree add DIR COMMIT), measured alike (before)")
    ap.add_argument("--report-only", action="store_true", help="rewrite dask.md from the recorded dask.json")
    args = ap.parse_args()
    if args.report_only:
        report(json.loads((RESULTS / "dask.json").read_text()))
        return 0
    if args.small >= args.n:
        ap.error(f"--small {args.small} must be below --n {args.n}")
    from generator import __version__
    from generator.toolchain import tool_versions
    res: dict = {"generator": f"shadermatrix {__version__}", "tools": tool_versions(), "cores": os.cpu_count(),
                 "workers": args.workers, "n": args.n, "small": args.small}
    with tempfile.TemporaryDirectory(prefix="shadermatrix-dask-bench-") as tmp:
        tmp = Path(tmp)
        scenes = {}
        for name, n in (("small", args.small), ("n", args.n)):
            scenes[name] = tmp / f"generated_{n}.toml"
            subprocess.run([sys.executable, str(REPO / "benchmarks" / "scenegen.py"), str(n), str(scenes[name])],
                           check=True, env=ENV)
        runs = {"after": REPO} | ({"before": Path(args.baseline).resolve()} if args.baseline else {})
        for label, repo in runs.items():
            (tmp / label).mkdir()
            res[label] = run(repo, args, tmp / label, scenes)
            res[label]["per_permutation"] = per_permutation(res[label])
            res[label]["model"] = model(res[label]["per_permutation"])
            if label == "before":
                res[label]["commit"] = subprocess.run(["git", "-C", str(repo), "rev-parse", "--short", "HEAD"],
                                                      capture_output=True, text=True).stdout.strip()
    pa = res["after"]["per_permutation"]
    res["targets"] = {"building_le_2ms_loose": pa["building_marginal_ms"] <= 2.0}
    if "packs_only_building_marginal_ms" in pa:
        res["targets"]["building_le_1ms_packs_only"] = pa["packs_only_building_marginal_ms"] <= 1.0
    (RESULTS / "dask.json").write_text(json.dumps(res, indent=2) + "\n")
    report(res)
    return 0


def report(res: dict) -> None:
    after, before = res["after"], res.get("before")
    pa = after["per_permutation"]
    cols = [("after", after)] + ([("before", before)] if before else [])
    yes = {True: "met", False: "not met"}
    md = ["# Whole chunks on a Dask cluster: the building process's CPU per permutation", "",
          f"Generated by `benchmarks/dask_build.py` ({res['generator']}; glslc {res['tools']['glslc']}, naga "
          f"{res['tools']['naga']}, SPIRV-Tools {res['tools']['spirv-tools']}) on {res['cores']} cores: a cluster "
          f"started from the `dask` CLI on this machine ({res['workers']} `dask worker --nthreads 1` processes), "
          f"generated scenes of {res['small']:,} and {res['n']:,} distinct permutations built cold on it "
          "(`--no-cache`), and locally with `-j` as many workers: the outputs identical "
          f"({'yes' if all(r['identical_to_local'] for _, r in cols) else 'NO'}).", "",
          "| per permutation (CPU) | " + " | ".join(f"{label}" + (f" ({r['commit']})" if label == "before" else "")
                                                   for label, r in cols) + " | target |",
          "|---|" + "---|" * len(cols) + "---|"]
    rows = [("building process, marginal (what each permutation adds)", "building_marginal_ms", "≤ 2 ms (loose "
             f"files): {yes[pa['building_marginal_ms'] <= 2.0]}"),
            (f"building process, total over {res['n']:,} (start-up and bricks included)", "building_total_ms", ""),
            ("the workers' Python (compose, analyse, make the entries), marginal", "workers_python_ms", ""),
            ("the tools (glslc, naga, spirv-opt, spirv-val, glslangValidator), marginal", "tools_ms", ""),
            (f"building process of a local `-j {res['workers']}` build, total", "local_building_total_ms", "")]
    for text, key, target in rows:
        md.append(f"| {text} | " + " | ".join(f"{r['per_permutation'][key]:.2f} ms" for _, r in cols) + f" | {target} |")
    if "packs_only_building_marginal_ms" in pa:
        md.append("| building process writing packs only (`--pack-only`), marginal | "
                  + " | ".join(f"{r['per_permutation']['packs_only_building_marginal_ms']:.2f} ms"
                               if "packs_only_building_marginal_ms" in r["per_permutation"] else "—" for _, r in cols)
                  + f" | ≤ 1 ms: {yes[pa['packs_only_building_marginal_ms'] <= 1.0]} |")
    md.append("| building process's fixed CPU (start-up, bricks, Dask client) | "
              + " | ".join(f"{r['per_permutation']['building_fixed_s']:.1f} s" for _, r in cols) + " | |")
    md.append(f"| files written per permutation | {pa['files_per_permutation']:.1f} |" + " |" * len(cols))
    phased = [(f"{label}, loose", r["per_permutation"]["building_phases_marginal_ms"]) for label, r in cols]
    phased += [(f"{label}, --pack-only", r["per_permutation"]["packs_only_phases_marginal_ms"]) for label, r in cols
               if "packs_only_phases_marginal_ms" in r["per_permutation"]]
    md += ["", "Where the building process's marginal CPU goes (per permutation; the main thread's CPU in each step, "
           "the rest of the process is the Dask client's thread; the last row, the kernel's part of them all, is "
           "mostly creating the loose files, whose cost depends on the file system: on this machine's /tmp, "
           "crowded with recently deleted files, ~15 to ~400 µs for one empty file):", "",
           "| step | " + " | ".join(label for label, _ in phased) + " |", "|---|" + "---|" * len(phased)]
    for step in pa["building_phases_marginal_ms"]:
        md.append(f"| {step} | " + " | ".join(f"{ph.get(step, 0):.2f} ms" for _, ph in phased) + " |")
    md += ["", "Wall time here (two cores, shared with the workers and their tools, so not the cluster's):", "",
           "| build | " + " | ".join(label for label, _ in cols) + " |", "|---|" + "---|" * len(cols)]
    for key, text in (("small", f"Dask, {res['small']:,} permutations"), ("n", f"Dask, {res['n']:,} permutations")):
        md.append(f"| {text} | " + " | ".join(f"{r[key]['wall_s']:.1f} s" for _, r in cols) + " |")
    md.append(f"| local -j {res['workers']}, {res['n']:,} permutations | "
              + " | ".join(f"{r['local']['wall_s']:.1f} s" for _, r in cols) + " |")
    md += ["", f"## {MODEL[0]:,} permutations on a cluster", "",
           "From the measured costs per permutation: the cluster's cores run the tools and the workers' Python, the "
           "building process plans and writes, the two overlapped chunk by chunk: build ≈ max(P × (tools + workers' "
           "Python) / cores, fixed + P × building-process marginal).", "",
           "| Dask workers × cores | " + " | ".join(f"cluster / building process / build ({label})" for label, _ in cols)
           + " |", "|---|" + "---|" * len(cols)]
    for k, shape in enumerate(MODEL[1]):
        md.append(f"| {shape[0]} × {shape[1]} | " + " | ".join(
            f"{r['model'][k]['cluster_s'] / 60:.1f} / {r['model'][k]['building_s'] / 60:.1f} / "
            f"{r['model'][k]['build_s'] / 60:.1f} min" for _, r in cols) + " |")
    md += ["", "Each permutation costs the building process its marginal CPU whatever the cluster's size, so it "
           "bounds the build at P × that; past the cores where the cluster's share falls below it, more workers "
           "do not help.", ""]
    (RESULTS / "dask.md").write_text("\n".join(md))
    print("\n".join(md))


if __name__ == "__main__":
    sys.exit(main())
