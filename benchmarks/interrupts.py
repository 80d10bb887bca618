"""How long a parallel build takes to end when it is interrupted: Ctrl-C, SIGTERM, a killed worker.

    .venv/bin/python benchmarks/interrupts.py [--python PY ...] [--n 200] [--repeat 3] [--at writing]
        [--repo DIR] [--write --label LABEL]

For each Python (default: this one and the second Python's venv, .venv-alt or .venv-deb, where present: Debian
12's 3.11.2) and each way of ending a build, a `build -j 2 --no-cache` of a generated scene of N permutations
(benchmarks/scenegen.py) is started in a session of its own; once its workers are composing (two worker
processes alive, then 1.5 s more), or with --at writing once the first chunk's files appear, it is sent the
signals below. Below 64 permutations a build stays in its own process (-j 2: two tool processes); then
"busy" is a tool of its running, and there is no worker to kill.

- SIGINT to its process group (what a terminal's Ctrl-C does);
- SIGTERM to the build's own process (`kill PID`, a supervisor);
- SIGTERM to its process group (a CI job or a container being stopped);
- SIGKILL to one worker process (what the kernel's OOM killer does).

Measured: seconds from the signal to the build's exit (a run still alive after --limit seconds is killed and
reported as a hang), its exit code and stderr (the one line expected), and how long until no process of its
session is left (forkserver, workers, resource tracker, the tools they started). --write puts the table in
benchmarks/results/interrupts.md under the heading --label (e.g. "before", "after").
"""
from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
RESULTS = REPO / "benchmarks" / "results" / "interrupts.md"
sys.path.insert(0, str(REPO / "benchmarks"))
from cliargs import positive  # noqa: E402

MIN_PERMUTATIONS = 64  # generator/assemble/loop.py: from here -j 2 is two worker processes

CASES = {  # name: (signal, whom)
    "Ctrl-C (SIGINT to the group)": (signal.SIGINT, "group"),
    "SIGTERM to the build": (signal.SIGTERM, "build"),
    "SIGTERM to the group": (signal.SIGTERM, "group"),
    "SIGKILL of a worker": (signal.SIGKILL, "worker"),
}
EXPECTED = {"worker": (1, "a worker process of the build died"), "other": (130, "interrupted; earlier outputs are "
                                                                                 "intact")}


def session(sid: int) -> dict[int, tuple[int, bytes]]:
    """The live processes of session `sid`: pid -> (parent pid, command line)."""
    found = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_bytes()
            cmdline = (stat.parent / "cmdline").read_bytes()
        except OSError:
            continue
        fields = text.rsplit(b")", 1)[1].split()
        if fields[0] != b"Z" and int(fields[3]) == sid:
            found[int(stat.parent.name)] = (int(fields[1]), cmdline)
    return found


def workers(build: int) -> list[int]:
    """The build's worker processes: its session's Pythons but the build itself, multiprocessing's resource
    tracker and the forkserver (a child of the build whose children are the workers)."""
    procs = session(build)
    out = []
    for pid, (ppid, cmd) in procs.items():
        if pid == build or b"python" not in cmd.split(b"\0")[0] or b"resource_tracker import" in cmd:
            continue
        if ppid == build and any(pp == pid and b"python" in c.split(b"\0")[0] for pp, c in procs.values()):
            continue  # a forkserver: its children are Pythons (a worker's are the tools)
        out.append(pid)
    return sorted(out)


def busy(build: int, in_process: bool) -> bool:
    """Its two workers are alive; or, for a build that stays in its own process, a tool it started is running."""
    if not in_process:
        return len(workers(build)) >= 2
    return any(ppid == build and b"python" not in cmd.split(b"\0")[0] for ppid, cmd in session(build).values())


def one(python: str, repo: Path, scene: Path, case: str, limit: float, at: str, in_process: bool) -> dict:
    sig, whom = CASES[case]
    with tempfile.TemporaryDirectory(prefix="interrupts-", ignore_cleanup_errors=True) as tmp:
        p = subprocess.Popen([python, "-m", "generator.cli", "build", str(scene), "--out", f"{tmp}/out",
                              "--no-cache", "-j", "2", "-q"], cwd=repo, stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, start_new_session=True)
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and p.poll() is None and not busy(p.pid, in_process):
            time.sleep(0.05)
        if at == "composing":
            time.sleep(1.5)
        else:  # once the first chunk's files are being written
            while time.monotonic() < deadline and p.poll() is None and not list(Path(tmp, "out").glob("*/*/*")):
                time.sleep(0.05)
        if p.poll() is not None:
            raise SystemExit(f"the build ended before it could be interrupted ({p.returncode}): make --n larger")
        started = time.monotonic()
        if whom == "group":
            os.killpg(p.pid, sig)
        elif whom == "build":
            os.kill(p.pid, sig)
        else:
            os.kill(workers(p.pid)[0], sig)
        try:
            p.wait(timeout=limit)
            ended = time.monotonic() - started
        except subprocess.TimeoutExpired:
            ended = None
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
        while session(p.pid) and time.monotonic() - started < limit + 10:
            time.sleep(0.05)
        left = session(p.pid)
        if left:
            os.killpg(p.pid, signal.SIGKILL)
        gone = None if left or ended is None else time.monotonic() - started  # a hung one's was killed
        err = p.stderr.read().decode(errors="replace")
    code, line = EXPECTED["worker" if whom == "worker" else "other"]
    lines = [x for x in err.splitlines() if x.strip()]
    right = ended is not None and p.returncode == code and len(lines) == 1 and line in lines[0]
    return {"exit_s": ended, "gone_s": gone, "rc": p.returncode if ended is not None else None, "right": right,
            "stderr": err.strip()}


def fmt(values: list, none: str = "hang") -> str:
    if any(v is None for v in values):
        return f"{none} ({sum(v is None for v in values)} of {len(values)})"
    return f"{statistics.median(values):.2f} s (max {max(values):.2f})"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--python", action="append", help="a Python with shadermatrix installed (repeatable)")
    ap.add_argument("--repo", type=Path, default=REPO,
                    help="the shadermatrix tree whose build is run (default this one; e.g. an export of an older "
                         "commit, `git archive`, to measure it with the same script)")
    ap.add_argument("--n", type=positive, default=200, help="permutations of the generated scene")
    ap.add_argument("--repeat", type=positive, default=3)
    ap.add_argument("--limit", type=float, default=30.0, help="seconds after which a build still alive is a hang")
    ap.add_argument("--case", action="append", choices=list(CASES), help="only these cases (default all)")
    ap.add_argument("--at", choices=["composing", "writing"], default="composing",
                    help="when the signal is sent: 1.5 s after two workers are alive (composing and compiling the "
                         "first chunks and the ubershader), or once the first chunk's files are being written")
    ap.add_argument("--write", action="store_true", help="add the table to benchmarks/results/interrupts.md")
    ap.add_argument("--label", default="", help="the heading of the table in the results file")
    args = ap.parse_args()
    pythons = [os.path.abspath(p) for p in args.python] if args.python else [sys.executable, *[str(p) for p in [REPO / ".venv-alt" / "bin" / "python",
                                                                  REPO / ".venv-deb" / "bin" / "python"]
                                                if p.exists()][:1]]
    with tempfile.TemporaryDirectory(prefix="interrupts-scene-") as tmp:
        scene = Path(tmp) / "gen.toml"
        subprocess.run([sys.executable, "benchmarks/scenegen.py", str(args.n), str(scene)], cwd=args.repo, check=True,
                       capture_output=True)
        rows = []
        in_process = args.n < MIN_PERMUTATIONS  # -j 2 then means two tool processes, no worker processes
        for python in pythons:
            version = subprocess.run([python, "-c", "import platform; print(platform.python_version())"],
                                     capture_output=True, text=True, check=True).stdout.strip()
            for case in args.case or CASES:
                if in_process and CASES[case][1] == "worker":
                    continue  # no worker to kill
                runs = [one(python, args.repo.resolve(), scene, case, args.limit, args.at, in_process)
                        for _ in range(args.repeat)]
                odd = sorted({r["stderr"] for r in runs if not r["right"]})
                rows.append((version, case, fmt([r["exit_s"] for r in runs]), fmt([r["gone_s"] for r in runs], "never, or killed with the hung build"),
                             ", ".join(sorted({str(r["rc"]) for r in runs})),
                             "yes" if all(r["right"] for r in runs) else "no: " + " / ".join(
                                 x.replace("\n", " ⏎ ")[:200] for x in odd)))
                print(" | ".join(rows[-1]), flush=True)
    table = ["| Python | how | signal → exit (median of %d) | signal → no process left | exit code | one line, "
             "right code |" % args.repeat, "|---|---|---|---|---|---|", *("| " + " | ".join(r) + " |" for r in rows)]
    text = "\n".join(table)
    print(text)
    if args.write:
        head = "" if RESULTS.exists() else (
            "# Interrupting a parallel build\n\nGenerated by `benchmarks/interrupts.py` (see its docstring for "
            "what is sent when): a `build -j 2 --no-cache` of a generated scene, on the 2-core machine.\n")
        with RESULTS.open("a") as f:
            f.write(f"{head}\n## {args.label or 'run'} ({args.n} permutations, {args.repeat} runs each)\n\n"
                    f"Signals sent while {args.at}.\n\n{text}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
