"""CI integration: `shadermatrix check SCENE [--golden DIR]` and the pytest plugin (`pytest --shadermatrix-scene`)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
PERMUTATIONS = 5  # scenes/example.toml draws 5 permutations


def _check(*args, cwd=REPO):
    return subprocess.run([sys.executable, "-m", "generator.cli", "check", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=900)


PLATFORMS = ("vulkan", "d3d12", "gl", "webgpu")
GOLDEN = re.compile(r"(vulkan/[0-9a-f]{12}\.(vert|frag)\.(glsl|hlsl|wgsl)|d3d12/[0-9a-f]{12}\.(vert|frag)\.hlsl"
                    r"|gl/[0-9a-f]{12}\.(vert|frag)\.(glsl|essl)|webgpu/[0-9a-f]{12}\.(vert|frag)\.wgsl)")


@pytest.mark.toolchain
def test_check_passes_writes_and_diffs_golden_sources_per_platform(tmp_path):
    golden = tmp_path / "golden"
    r = _check(EXAMPLE, "--golden", golden, "--update-golden")  # default: every platform
    n = len(PLATFORMS) * PERMUTATIONS
    assert r.returncode == 0, r.stderr
    ids = re.findall(r"^ok ([0-9a-f]{12})-(\w+)", r.stdout, re.M)
    assert len(ids) == n and {p for _, p in ids} == set(PLATFORMS), r.stdout
    assert f"{n} of {n} checks pass ({PERMUTATIONS} permutations × 4 platforms: vulkan, d3d12, gl, webgpu)" in r.stderr
    files = sorted(p.relative_to(golden).as_posix() for p in golden.rglob("*") if p.is_file())
    assert all(GOLDEN.fullmatch(f) for f in files), files
    per = {p: sum(f.startswith(p + "/") for f in files) for p in PLATFORMS}
    # vulkan: 3 languages × 2 stages; d3d12, webgpu: 2 stages; gl: 2 stages core, and ES where it validates
    assert per["vulkan"] == 6 * PERMUTATIONS and per["d3d12"] == per["webgpu"] == 2 * PERMUTATIONS
    assert per["gl"] == 2 * PERMUTATIONS + 2 * (PERMUTATIONS - r.stdout.count("GLSL ES 3.10 unsupported"))
    frag = {p: next((golden / p).glob(f"*.frag.{ext}")).read_text()  # each platform's own dialect
            for p, ext in (("vulkan", "glsl"), ("d3d12", "hlsl"), ("gl", "glsl"), ("webgpu", "wgsl"))}
    assert "set = " in frag["vulkan"] and "#version 450 core" in frag["gl"] and "set = " not in frag["gl"]
    assert "register(" in frag["d3d12"] and "@group(" in frag["webgpu"]
    # an edited golden source is a drift (the diff printed), and a golden source no permutation emits any more
    # (a permutation that left the scene) too; another platform's tree, not checked, is not looked at
    victim = golden / next(f for f in files if f.startswith("webgpu/"))
    victim.write_text(victim.read_text().replace("main", "main_renamed", 1))
    (golden / "gl" / "000000000000.frag.glsl").write_text("// gone\n")
    (golden / "d3d12" / "000000000000.frag.hlsl").write_text("// not checked here\n")
    r = _check(EXAMPLE, "--golden", golden, "--platform", "gl,webgpu")
    assert r.returncode == 1 and "1 drifted" in r.stderr and r.stdout.count("ok ") == 2 * PERMUTATIONS - 1, r.stderr
    assert f"DRIFT {victim.name.split('.')[0]}-webgpu" in r.stderr
    assert f"--- golden/webgpu/{victim.name}" in r.stderr and "+++ emitted/webgpu/" in r.stderr
    assert "DRIFT gl/000000000000.frag.glsl" in r.stderr and "1 golden files left" in r.stderr
    assert "d3d12/000000000000" not in r.stderr
    assert _check(EXAMPLE, "--golden", golden, "--update-golden", "--platform", "gl,webgpu").returncode == 0
    assert not (golden / "gl" / "000000000000.frag.glsl").exists() and "main_renamed" not in victim.read_text()
    assert (golden / "d3d12" / "000000000000.frag.hlsl").exists()


def test_check_usage_errors_and_selection(tmp_path):
    from generator.assemble.checks import checks
    from generator.cli.commands.check import selection
    from generator.lang.errors import UsageError
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    assert _check(EXAMPLE, "--platform", "metal").returncode == 2
    assert _check(EXAMPLE, "--update-golden").returncode == 2
    for plats, langs, what in (("gl,gl", None, "--platform: "), (None, "metal", "--languages: "),
                               ("d3d12", "wgsl", "checks nothing")):  # d3d12 is made from HLSL alone
        with pytest.raises(UsageError, match=what):
            selection(plats, langs)
    # the languages narrow the platforms (docs/guide/build.md's plugin command names them): vulkan compiles those it is given
    assert selection(None, "hlsl") == (["vulkan", "d3d12"], ["hlsl"])
    scene = load_scene(EXAMPLE, load_library([]))
    got = checks(scene, *selection("vulkan,gl", "glsl,hlsl"))
    assert [(c.platform, c.languages) for c in got[:2]] == [("vulkan", ("glsl", "hlsl")), ("gl", ())]
    assert len(got) == 2 * PERMUTATIONS and got[0].id == f"{got[0].hash}-vulkan"
    # the plugin: a bad option or scene is the run's usage error, one line, never an INTERNALERROR
    for opts in (["--shadermatrix-scene", str(EXAMPLE), "--shadermatrix-platforms", "metal"],
                 ["--shadermatrix-scene", str(tmp_path / "missing.toml")]):
        r = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *opts], cwd=tmp_path,
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 4 and "INTERNALERROR" not in r.stdout + r.stderr, r.stdout + r.stderr
        assert "--shadermatrix-scene" in r.stderr


@pytest.mark.toolchain
def test_pytest_plugin_runs_one_test_per_permutation_and_platform(tmp_path):
    """An engine's suite: a subprocess pytest in a folder without tests, the plugin loaded by its entry point."""
    golden = tmp_path / "golden"
    assert _check(EXAMPLE, "--golden", golden, "--update-golden", "--platform", "d3d12").returncode == 0
    run = [sys.executable, "-m", "pytest", "-v", "-p", "no:cacheprovider", "--shadermatrix-scene", str(EXAMPLE),
           "--shadermatrix-golden", str(golden)]
    victim = next(golden.rglob("*.frag.hlsl"))
    victim.write_text(victim.read_text() + "// edited\n")
    r = subprocess.run([*run, "--shadermatrix-platforms", "d3d12,gl"], cwd=tmp_path, capture_output=True, text=True,
                       timeout=900)
    # d3d12: 4 match the golden and 1 drifts; gl has no golden files, so all 5 drift
    assert re.search(r"\b4 passed\b", r.stdout) and re.search(r"\b6 failed\b", r.stdout), r.stdout[-2000:]
    assert f"example.toml::{victim.name.split('.')[0]}-d3d12 FAILED" in r.stdout
    assert "emitted sources drift from the golden ones" in r.stdout and "+++ emitted/gl/" in r.stdout
    r = subprocess.run(run[:-2], cwd=tmp_path, capture_output=True, text=True, timeout=900)  # every platform
    assert r.returncode == 0 and re.search(rf"\b{len(PLATFORMS) * PERMUTATIONS} passed\b", r.stdout), r.stdout[-2000:]
    for plat in PLATFORMS:
        assert len(re.findall(rf"example\.toml::[0-9a-f]{{12}}-{plat} PASSED", r.stdout)) == PERMUTATIONS
