"""`build --executor dask://...` on a real cluster started from the `dask` CLI (`dask scheduler` and `dask worker`
processes on localhost, free ports): whole chunks — compose, compile, analyse, the manifest entries — run on the
workers (generator/assemble/cluster.py), the output is byte-identical to a local build, a worker killed while it
runs a chunk gets its chunk run again elsewhere (or fails the build in one line: never a hang), and a worker
whose generator or tools differ from the build's is refused in one line."""
from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
HANG_S = 120  # past this a build counts as hung (it takes seconds)
pytestmark = pytest.mark.toolchain


def _tree(root: Path) -> dict:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
            and p.name != ".shadermatrix-lock"}


def _cli(*args, **kw):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=HANG_S, **kw)


class Cluster:
    """`dask scheduler` and `workers` × `dask worker --nthreads 1 --no-nanny` (a killed worker stays dead)."""

    def __init__(self, workers: int, env: dict | None = None, cwd: Path = REPO):
        dask = Path(sys.executable).with_name("dask")
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        self.address = f"127.0.0.1:{port}"
        quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
        self.procs = [subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                        "--no-dashboard"], cwd=REPO, **quiet)]
        self.workers = [subprocess.Popen([str(dask), "worker", f"tcp://{self.address}", "--nthreads", "1",
                                          "--no-nanny", "--no-dashboard"], cwd=cwd, env=env, **quiet)
                        for _ in range(workers)]
        self.procs += self.workers
        from distributed import Client
        with Client(f"tcp://{self.address}", timeout="30s") as c:
            c.wait_for_workers(workers, timeout=60)

    def close(self) -> None:
        for p in self.procs:
            p.kill()
            p.wait()


@pytest.fixture(scope="module")
def cluster():
    c = Cluster(2)
    yield c
    c.close()


@pytest.fixture(scope="module")
def local(tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("local") / "out"
    r = _cli("build", EXAMPLE, "--out", out, "--no-cache", "-j", "1")
    assert r.returncode == 0, r.stderr
    return _tree(out)


def test_a_dask_build_is_byte_identical_to_a_local_one(cluster, local, tmp_path):
    r = _cli("build", EXAMPLE, "--out", tmp_path / "dask", "--no-cache", "--executor", f"dask://{cluster.address}")
    assert r.returncode == 0, r.stderr
    assert _tree(tmp_path / "dask") == local
    text = (tmp_path / "dask" / "manifest.json").read_text()  # the entries' texts were made on the workers
    assert text == json.dumps(json.loads(text), indent=2) + "\n"


def _compiling(pid: int) -> bool:
    """Whether process `pid` runs a tool on a shader (a chunk's compile; not a `--version` of its check)."""
    try:
        children = [c for t in os.listdir(f"/proc/{pid}/task")
                    for c in Path(f"/proc/{pid}/task/{t}/children").read_text().split()]
        return any(b"--version" not in Path(f"/proc/{c}/cmdline").read_bytes() for c in children)
    except OSError:
        return False


def test_a_worker_killed_while_it_runs_a_chunk_never_hangs_the_build(cluster, local, tmp_path):
    build = subprocess.Popen([sys.executable, "-m", "generator.cli", "build", EXAMPLE, "--out", tmp_path / "dask",
                              "--no-cache", "--executor", f"dask://{cluster.address}"], cwd=REPO,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    killed = None
    deadline = time.monotonic() + HANG_S
    while killed is None and build.poll() is None and time.monotonic() < deadline:
        for w in cluster.workers:
            if _compiling(w.pid):  # its chunk is running: a tool it started is
                os.kill(w.pid, signal.SIGKILL)
                killed = w
                break
        time.sleep(0.01)
    try:
        _, err = build.communicate(timeout=HANG_S)
    except subprocess.TimeoutExpired:
        build.kill()
        pytest.fail("the build hung after a worker was killed")
    assert killed is not None and killed.wait(5) == -signal.SIGKILL, "no chunk was caught running"
    if build.returncode == 0:  # the chunk ran again on the other worker
        assert _tree(tmp_path / "dask") == local
    else:
        errors = [line for line in err.splitlines() if line.startswith("error:")]
        assert build.returncode == 1 and len(errors) == 1 and "Dask cluster" in errors[0], err


def test_a_cluster_left_without_workers_fails_the_build_in_one_line(cluster, tmp_path, monkeypatch):
    """Every worker killed as soon as it runs a chunk (this module's cluster: the last test to use it)."""
    import threading

    from generator.assemble import BuildContext, build
    from generator.assemble import cluster as C
    from generator.lang.errors import UserError
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from generator.toolchain.dask import DaskExecutor
    monkeypatch.setattr(C, "NO_WORKERS_S", 2.0)
    lib = load_library()
    executor = DaskExecutor(f"dask://{cluster.address}")
    done = threading.Event()

    def kill_each_as_it_compiles():
        alive = [w for w in cluster.workers if w.poll() is None]
        while alive and not done.is_set():
            for w in [w for w in alive if _compiling(w.pid)]:
                os.kill(w.pid, signal.SIGKILL)
                alive.remove(w)
            time.sleep(0.01)

    killer = threading.Thread(target=kill_each_as_it_compiles)
    killer.start()
    started = time.monotonic()
    try:
        with pytest.raises(UserError) as e:
            build(load_scene(EXAMPLE, lib), tmp_path / "out", BuildContext(lib, store=None, executor=executor))
    finally:
        done.set()
        killer.join()
        executor.close()
    assert time.monotonic() - started < HANG_S
    message = str(e.value)
    assert "\n" not in message and "Dask cluster" in message, message
    assert not (tmp_path / "out" / "manifest.json").exists()


def test_a_worker_with_another_generator_or_tools_is_refused_in_one_line(tmp_path):
    # a checkout of the generator with one more line, and a glslc that says it is another version
    shutil.copytree(REPO / "generator", tmp_path / "other" / "generator",
                    ignore=shutil.ignore_patterns("__pycache__"))
    with open(tmp_path / "other" / "generator" / "__init__.py", "a") as f:
        f.write("# another generator\n")
    tools = tmp_path / "tools"
    tools.mkdir()
    glslc = shutil.which("glslc")
    (tools / "glslc").write_text(f'#!/bin/sh\n[ "$1" = --version ] && {{ echo "shaderc v2099.1"; exit 0; }}\n'
                                 f'exec {glslc} "$@"\n')
    (tools / "glslc").chmod(0o755)
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "other"), "SHADERMATRIX_TOOLS": str(tools)}
    c = Cluster(1, env=env, cwd=tmp_path)
    try:
        r = _cli("build", EXAMPLE, "--out", tmp_path / "out", "--no-cache", "--executor", f"dask://{c.address}")
    finally:
        c.close()
    assert r.returncode == 1, r.stderr
    errors = [line for line in r.stderr.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and errors[0].startswith("error: dask worker tcp://127.0.0.1:"), r.stderr
    assert "shadermatrix 0.1.0 (sources" in errors[0] and "glslc v2099.1" in errors[0] and "(this build: " in errors[0]
    assert not (tmp_path / "out" / "manifest.json").exists()


def test_a_scheduler_that_is_not_there_is_one_line(tmp_path):
    r = _cli("build", EXAMPLE, "--out", tmp_path / "out", "--executor", "dask://127.0.0.1:9")
    assert r.returncode == 1 and r.stderr.startswith("error: no Dask scheduler at tcp://127.0.0.1:9")
    assert _cli("build", EXAMPLE, "--out", tmp_path / "o", "--executor", "tcp://x:1").returncode == 2
