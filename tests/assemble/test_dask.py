"""`build --executor dask://...`: the compiles run on a real Dask cluster (a distributed.LocalCluster
the test starts), the output is byte-identical to a local build, and a worker without the tools fails the
build with one line."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
pytestmark = pytest.mark.toolchain


def _tree(root: Path) -> dict:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
            and p.name != ".shadermatrix-lock"}


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=600)


@pytest.fixture
def cluster():
    from distributed import LocalCluster
    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    yield c
    c.close()


def test_a_dask_build_is_byte_identical_to_a_local_one(cluster, tmp_path):
    local = _cli("build", EXAMPLE, "--out", tmp_path / "local", "--no-cache", "-j", "1")
    assert local.returncode == 0, local.stderr
    remote = _cli("build", EXAMPLE, "--out", tmp_path / "dask", "--no-cache",
                  "--executor", "dask://" + cluster.scheduler_address.removeprefix("tcp://"))
    assert remote.returncode == 0, remote.stderr
    assert _tree(tmp_path / "local") == _tree(tmp_path / "dask")
    info = cluster.scheduler_info if isinstance(cluster.scheduler_info, dict) else cluster.scheduler_info()
    assert len(info["workers"]) == 2


def test_a_worker_without_the_tools_fails_the_build_in_one_line(tmp_path):
    from distributed import LocalCluster
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                      env={"PATH": "/nonexistent"}) as c:  # no glslc, no spirv-tools on it
        r = _cli("build", EXAMPLE, "--out", tmp_path / "out", "--no-cache", "--executor", "dask://" +
                 c.scheduler_address.removeprefix("tcp://"))
    assert r.returncode == 1
    errors = [line for line in r.stderr.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "dask worker" in errors[0] and "missing" in errors[0] and "make setup" in errors[0], \
        r.stderr


def test_a_scheduler_that_is_not_there_is_one_line(tmp_path):
    r = _cli("build", EXAMPLE, "--out", tmp_path / "out", "--executor", "dask://127.0.0.1:9")
    assert r.returncode == 1 and r.stderr.startswith("error: no Dask scheduler at tcp://127.0.0.1:9")
    assert _cli("build", EXAMPLE, "--out", tmp_path / "o", "--executor", "tcp://x:1").returncode == 2
