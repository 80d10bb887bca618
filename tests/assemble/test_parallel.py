"""`build -j N` with N > 1: permutations are composed, compiled and analysed in N worker processes
(generator/assemble/parallel.py); the output is byte-identical to an in-process build, the counts are the same,
the depfile names the templates the workers read, and a worker's compose error or missing tool is reported as
in-process."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.assemble.test_dask import _tree  # an output tree's files and bytes

REPO = Path(__file__).resolve().parents[2]
EXAMPLE_SMALL = REPO / "scenes" / "example.toml"
pytestmark = pytest.mark.toolchain
HANG_S = 20  # seconds from a signal to the build's exit past which it counts as hung
# The generated scenes' builds are for one platform: a worker composes, compiles and analyses every platform's
# sources the same way, and make test's budget is spent once rather than four times.
ONE = ("--platform", "vulkan")


def _cli(*args, env=None):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=600, env=env)


def _generated(tmp_path_factory, n: int) -> Path:
    path = tmp_path_factory.mktemp("gen") / "gen.toml"
    r = subprocess.run([sys.executable, "benchmarks/scenegen.py", str(n), str(path)], cwd=REPO, capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    return path


@pytest.fixture(scope="module")
def scene(tmp_path_factory) -> Path:
    from generator.assemble.loop import MIN_PERMUTATIONS
    return _generated(tmp_path_factory, MIN_PERMUTATIONS + 4)


@pytest.fixture(scope="module")
def few(tmp_path_factory) -> Path:
    """12 permutations, built in worker processes under FEW_ENV: what a worker makes is the same for 12 as
    for 68 (the signal tests keep `scene`, whose build lasts long enough to be interrupted mid-write)."""
    return _generated(tmp_path_factory, 12)


FEW_ENV = {**os.environ, "SHADERMATRIX_WORKERS_FROM": "8"}


@pytest.fixture(scope="module")
def small_scene(tmp_path_factory) -> Path:
    """Too few permutations for worker processes: `-j 2` is two tool processes of the building process."""
    from generator.assemble.loop import MIN_PERMUTATIONS
    return _generated(tmp_path_factory, MIN_PERMUTATIONS - 1)


def test_worker_processes_build_what_one_process_builds(few, tmp_path):
    one = _cli("build", few, "--out", tmp_path / "one", "--no-cache", "-j", "1", *ONE,
               "--depfile", tmp_path / "one.d")
    assert one.returncode == 0, one.stderr
    # a fresh cache: the workers compose, compile and analyse everything themselves
    two = _cli("build", few, "--out", tmp_path / "two", "--cache-dir", tmp_path / "cache", "-j", "2", *ONE,
               "--depfile", tmp_path / "two.d", env=FEW_ENV)
    assert two.returncode == 0, two.stderr
    assert _tree(tmp_path / "one") == _tree(tmp_path / "two")
    summary = [line.split("→")[0] for r in (one, two) for line in r.stdout.splitlines() if "shaders," in line]
    assert summary[0] == summary[1]  # shaders, distinct, merged, compiled, files: counted the same way
    deps = [(tmp_path / d).read_text().replace(str(tmp_path / "one"), "OUT").replace(str(tmp_path / "two"), "OUT")
            for d in ("one.d", "two.d")]
    assert deps[0] == deps[1] and "fragment.glsl.j2" in deps[1]  # the templates the workers read


def test_a_permutation_that_fails_in_a_worker_is_reported_located(few, tmp_path):
    engine = tmp_path / "engine"
    engine.mkdir()
    good = (REPO / "bricks" / "output" / "linear.py").read_text()
    (engine / "tinted.py").write_text(good.replace("return vec4(color, 1.0)", "k = 1\n    q = k / 0\n"
                                                   "    return vec4(color * float(q), 1.0)"))
    text = few.read_text()
    assert "[scene]" in text
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("[scene]", '[scene]\noutput = "tinted"', 1))
    r = _cli("build", bad, "--out", tmp_path / "out", "--bricks", engine, "--no-cache", "-j", "2", *ONE, env=FEW_ENV)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    heads = [line for line in r.stderr.splitlines() if line.startswith("error: ")]
    assert heads and all(line.startswith(f"error: {bad}:") and "does not build" in line for line in heads)
    assert "engine/tinted.py:" in r.stderr and "Division by zero" in r.stderr


def test_a_worker_without_the_tools_is_one_line(scene, tmp_path):
    env = {**os.environ, "PATH": "/nonexistent"}  # no glslc, no spirv-tools
    r = _cli("build", scene, "--out", tmp_path / "out", "--no-cache", "-j", "2", env=env)
    assert r.returncode == 3 and "Traceback" not in r.stderr  # the environment's exit code, as in-process
    errors = [line for line in r.stderr.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "not found" in errors[0] and "make setup" in errors[0], r.stderr


def _session_pythons(sid: int, tools: bool = False) -> list[int]:
    """The Python processes (the build, its forkserver and workers) still alive in session `sid`; with
    `tools`, the compilers and validators the workers started too."""
    alive = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_bytes()
        except OSError:
            continue
        comm, rest = text.split(b"(", 1)[1].rsplit(b")", 1)
        fields = rest.split()
        wanted = b"python" in comm or (tools and comm.startswith((b"glslc", b"glslang", b"naga", b"spirv-", b"dxc")))
        if wanted and int(fields[3]) == sid and fields[0] != b"Z":
            alive.append(int(stat.parent.name))
    return alive


def test_kill_9_of_a_parallel_build_loses_nothing_and_leaves_no_worker(scene, tmp_path):
    import signal
    import time

    from tests.assemble.test_build_system import _consistent
    out = tmp_path / "out"
    assert _cli("build", EXAMPLE_SMALL, "--out", out, "-j", "1").returncode == 0
    before = _consistent(out)
    p = subprocess.Popen([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(out),
                          "--no-cache", "-j", "2", *ONE], cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         start_new_session=True)
    names = {str(p.relative_to(out)) for p in out.glob("*/*")}
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and p.poll() is None:  # until the first chunk is being written
        if {str(p.relative_to(out)) for p in out.glob("*/*")} - names:
            break
        time.sleep(0.05)
    assert p.poll() is None, "the build ended before it could be killed"
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert _consistent(out, exact=False) == before  # the old manifest, every file it names intact
    deadline = time.monotonic() + 10
    while _session_pythons(p.pid, tools=True) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _session_pythons(p.pid, tools=True) == []  # the workers went with the build, and their tools
    assert p.stderr.read() == b""  # and said nothing (no broken pipe from a worker sending to the dead build)
    r = _cli("build", scene, "--out", out, "--no-cache", "-j", "2", *ONE)
    assert r.returncode == 0, r.stderr
    assert all(e["status"] == "ok" for e in _consistent(out)["permutations"])


def _start_build(scene: Path, out: Path) -> subprocess.Popen:
    """A -j 2 build in a session of its own, once its workers are composing (its first shader being compiled)."""
    import time
    p = subprocess.Popen([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(out), "--no-cache",
                          "-j", "2"], cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and p.poll() is None and len(_session_pythons(p.pid)) < 4:
        time.sleep(0.05)  # the build, the forkserver and two workers
    time.sleep(1.0)
    assert p.poll() is None, "the build ended before it could be interrupted"
    return p


def _ends(p: subprocess.Popen, code: int, line: str) -> None:
    """The build exits within HANG_S with `code` and `line` as its whole stderr, and leaves no process behind
    (the forkserver and the resource tracker follow it out; the workers' tools were killed with them)."""
    import time
    try:
        _, err = p.communicate(timeout=HANG_S)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, 9)
        p.communicate()
        pytest.fail(f"the build was still running {HANG_S} s after the signal (hung)")
    assert p.returncode == code and err == line, (p.returncode, err)
    deadline = time.monotonic() + 10
    while _session_pythons(p.pid, tools=True) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _session_pythons(p.pid, tools=True) == []


def test_ctrl_c_of_a_parallel_build_is_one_line_and_ends_the_workers(scene, tmp_path):
    import signal
    p = _start_build(scene, tmp_path / "out")
    os.killpg(p.pid, signal.SIGINT)  # as a terminal does: the whole process group
    _ends(p, 130, "interrupted; earlier outputs are intact\n")


@pytest.mark.parametrize("whom", ["build", "group"])
def test_sigterm_of_a_parallel_build_is_one_line_and_ends_the_workers(scene, tmp_path, whom):
    import signal
    p = _start_build(scene, tmp_path / "out")
    if whom == "build":  # `kill PID`, a supervisor
        os.kill(p.pid, signal.SIGTERM)
    else:  # a CI job or a container being stopped
        os.killpg(p.pid, signal.SIGTERM)
    _ends(p, 130, "interrupted; earlier outputs are intact\n")  # the documented code of an interrupt


def _compiling(sid: int) -> bool:
    """A tool of session `sid` is compiling (not telling its version, as the build's start asks)."""
    for pid in set(_session_pythons(sid, tools=True)) - set(_session_pythons(sid)):
        try:
            if b"--version" not in Path(f"/proc/{pid}/cmdline").read_bytes():
                return True
        except OSError:
            pass
    return False


@pytest.mark.parametrize("whom", ["build", "group"])
def test_an_in_process_build_ends_without_finishing_its_batch(small_scene, tmp_path, whom):
    """Signalled while its compile thread runs its one batch (every shader of the scene and the ubershader's),
    the build kills the tools and leaves at once: nothing of the batch is compiled after the signal, so the
    compile cache stays empty. It used to finish the batch first (12-20 s here), filling the cache."""
    import signal
    import time

    from generator.toolchain import COMPILE_NAMESPACE
    cache = tmp_path / "cache"
    p = subprocess.Popen([sys.executable, "-m", "generator.cli", "build", str(small_scene), "--out",
                          str(tmp_path / "out"), "--cache-dir", str(cache), "-j", "2"], cwd=REPO,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and p.poll() is None and not _compiling(p.pid):
        time.sleep(0.05)
    time.sleep(1.0)
    assert p.poll() is None, "the build ended before it could be interrupted"
    assert not (cache / COMPILE_NAMESPACE).exists(), "the batch was done before the signal: make the scene larger"
    (os.kill if whom == "build" else os.killpg)(p.pid, signal.SIGTERM if whom == "build" else signal.SIGINT)
    _ends(p, 130, "interrupted; earlier outputs are intact\n")
    assert not [f for f in (cache / COMPILE_NAMESPACE).rglob("*") if f.is_file()]


def test_a_worker_that_dies_fails_the_build_instead_of_hanging_it(scene, tmp_path):
    import signal
    p = _start_build(scene, tmp_path / "out")
    workers = [pid for pid in _session_pythons(p.pid) if pid != p.pid
               and b"forkserver" in Path(f"/proc/{pid}/cmdline").read_bytes()
               and int(Path(f"/proc/{pid}/stat").read_bytes().rsplit(b")", 1)[1].split()[1]) != p.pid]
    assert workers, "no worker process found"
    os.kill(workers[0], signal.SIGKILL)  # as the kernel's OOM killer would
    _ends(p, 1, "error: a worker process of the build died (killed, or out of memory) — build again, or with "
                "fewer jobs (-j)\n")


def test_a_dynamic_light_set_built_by_workers_is_described_as_in_process(tmp_path, monkeypatch):
    """The workers send each permutation back without what its entry already holds, but a dynamic set's light
    buffers are described from its interface (reflection.dynamic_tables): workers and one process agree."""
    import json

    import generator.assemble.loop as loop
    from generator.assemble import BuildContext, build
    from generator.io import Store
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    scene = load_scene(REPO / "tests" / "scenes" / "dynamic_lights.toml", lib)
    tables = []
    for jobs in (1, 2):
        monkeypatch.setattr(loop, "MIN_PERMUTATIONS", 1)  # workers for any scene with -j 2
        out = tmp_path / f"j{jobs}"
        build(scene, out, BuildContext(lib, platforms=("vulkan",), store=Store(tmp_path / "cache"), jobs=jobs))
        tables.append(json.loads((out / "manifest.json").read_text())["dynamic_light_sets"])
    assert tables[0] and tables[0] == tables[1]


def test_the_worker_threshold_is_64_or_what_the_environment_says(monkeypatch):
    from generator.assemble import loop
    from generator.assemble.context import BuildContext
    from generator.lang.errors import UserError
    ctx = BuildContext(library=None, jobs=2)
    monkeypatch.delenv(loop.WORKERS_FROM_ENV, raising=False)
    assert not loop.in_workers(ctx, 12) and loop.in_workers(ctx, 64)
    monkeypatch.setenv(loop.WORKERS_FROM_ENV, FEW_ENV[loop.WORKERS_FROM_ENV])  # what the tests above build under
    assert loop.in_workers(ctx, 12) and not loop.in_workers(ctx, 7)
    for bad in ("0", "-3", "many", ""):
        monkeypatch.setenv(loop.WORKERS_FROM_ENV, bad)
        with pytest.raises(UserError, match="SHADERMATRIX_WORKERS_FROM=.* — set it to"):
            loop.in_workers(ctx, 12)
