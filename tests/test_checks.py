"""CI integration: `shadermatrix check SCENE [--golden DIR]` and the pytest plugin (`pytest --shadermatrix-scene`)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
EXAMPLE = REPO / "scenes" / "example.toml"
PERMUTATIONS = 5  # scenes/example.toml draws 5 permutations


def _check(*args, cwd=REPO):
    return subprocess.run([sys.executable, "-m", "generator.cli", "check", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=900)


@pytest.mark.toolchain
def test_check_passes_writes_and_diffs_golden_sources(tmp_path):
    golden = tmp_path / "golden"
    r = _check(EXAMPLE, "--golden", golden, "--update-golden", "--languages", "glsl,wgsl")
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("ok ") == 2 * PERMUTATIONS and f"{2 * PERMUTATIONS} of {2 * PERMUTATIONS} checks pass" in r.stderr
    files = sorted(p.relative_to(golden).as_posix() for p in golden.rglob("*") if p.is_file())
    assert len(files) == 2 * 2 * PERMUTATIONS and all(re.fullmatch(r"(glsl|wgsl)/[0-9a-f]{12}\.(vert|frag)\.\1", f)
                                                       for f in files)
    assert _check(EXAMPLE, "--golden", golden, "--languages", "glsl,wgsl").returncode == 0
    victim = golden / files[0]
    victim.write_text(victim.read_text().replace("main", "main_renamed", 1))
    r = _check(EXAMPLE, "--golden", golden, "--languages", "glsl,wgsl")
    assert r.returncode == 1 and "DRIFT " in r.stderr and "1 drifted" in r.stderr
    assert f"--- golden/{files[0]}" in r.stderr and "+++ emitted/" in r.stderr
    # a golden source no permutation emits any more (a permutation that left the scene) is a drift too
    _check(EXAMPLE, "--golden", golden, "--update-golden", "--languages", "glsl,wgsl")
    (golden / "glsl" / "000000000000.frag.glsl").write_text("// gone\n")
    r = _check(EXAMPLE, "--golden", golden, "--languages", "glsl,wgsl")
    assert r.returncode == 1 and "DRIFT glsl/000000000000.frag.glsl" in r.stderr and "1 golden files left" in r.stderr
    assert _check(EXAMPLE, "--golden", golden, "--update-golden", "--languages", "glsl,wgsl").returncode == 0
    assert not (golden / "glsl" / "000000000000.frag.glsl").exists()


def test_check_usage_errors(tmp_path):
    assert _check(EXAMPLE, "--languages", "metal").returncode == 2
    assert _check(EXAMPLE, "--languages", "glsl,glsl").returncode == 2
    assert _check(EXAMPLE, "--update-golden").returncode == 2
    # the plugin: a bad option or scene is the run's usage error, one line, never an INTERNALERROR
    for opts in (["--shadermatrix-scene", str(EXAMPLE), "--shadermatrix-languages", "metal"],
                 ["--shadermatrix-scene", str(tmp_path / "missing.toml")]):
        r = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *opts], cwd=tmp_path,
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 4 and "INTERNALERROR" not in r.stdout + r.stderr, r.stdout + r.stderr
        assert "--shadermatrix-scene" in r.stderr


@pytest.mark.toolchain
def test_pytest_plugin_runs_one_test_per_permutation_and_language(tmp_path):
    """An engine's suite: a subprocess pytest in a folder without tests, the plugin loaded by its entry point."""
    golden = tmp_path / "golden"
    assert _check(EXAMPLE, "--golden", golden, "--update-golden", "--languages", "hlsl").returncode == 0
    run = [sys.executable, "-m", "pytest", "-v", "-p", "no:cacheprovider", "--shadermatrix-scene", str(EXAMPLE),
           "--shadermatrix-languages", "hlsl,glsl", "--shadermatrix-golden", str(golden)]
    victim = next(golden.rglob("*.frag.hlsl"))
    victim.write_text(victim.read_text() + "// edited\n")
    r = subprocess.run(run, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    # hlsl: 4 match the golden and 1 drifts; glsl has no golden files, so all 5 drift
    assert re.search(r"\b4 passed\b", r.stdout) and re.search(r"\b6 failed\b", r.stdout), r.stdout[-2000:]
    assert f"example.toml::{victim.name.split('.')[0]}-hlsl FAILED" in r.stdout
    assert "emitted sources drift from the golden ones" in r.stdout
    r = subprocess.run(run[:-2] + ["--shadermatrix-languages", "wgsl"], cwd=tmp_path, capture_output=True, text=True,
                       timeout=900)
    assert r.returncode == 0 and re.search(rf"\b{PERMUTATIONS} passed\b", r.stdout), r.stdout[-2000:]
