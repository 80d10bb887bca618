"""AMD compiler statistics from Mesa RADV's null device: real ACO figures, no AMD GPU.

Every test here compiles on RADV for real (`generator/runtime/gpu_stats.py`: one process per family,
RADV_FORCE_FAMILY and RADV's ICD); without mesa-vulkan-drivers they skip, and under CI=true they fail.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import require

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]  # a Vulkan device (RADV's null one) and glslc

SMALL = """#version 450
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer In { float x[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Out { float y[]; };
void main() { uint i = gl_GlobalInvocationID.x; y[i] = 2.0 * x[i]; }
"""
# 48 values loaded up front and all live until the sums at the end: the compiler must hold them in registers.
BIG = """#version 450
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer In { float x[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Out { float y[]; };
void main() {
  uint i = gl_GlobalInvocationID.x * 48u;
  float v[48];
  for (int k = 0; k < 48; ++k) v[k] = x[i + uint(k)];
  float s = 0.0;
  for (int a = 0; a < 48; ++a) for (int b = a + 1; b < 48; ++b) s += v[a] * v[b] * float(a ^ b);
  y[gl_GlobalInvocationID.x] = s;
}
"""


@pytest.fixture(scope="module")
def radv():
    from generator.runtime import gpu_stats
    require(gpu_stats.unavailable() == "", f"RADV's null device: {gpu_stats.unavailable()}")
    return gpu_stats


def _spirv(text):
    from generator.toolchain import CompileJob, compile_many
    r = compile_many([CompileJob("k", "glsl", "comp", text)])["k"]
    assert r.ok, r.errors()
    return r.spirv


def test_a_fixed_kernel_has_plausible_statistics_and_a_bigger_one_needs_more_registers(radv, tmp_path,
                                                                                      monkeypatch):
    odd = SMALL.replace("set = 0, binding = 1", "set = 1, binding = 0")  # not a layout a compute job binds
    jobs = [radv.Job("small", (("comp", _spirv(SMALL)),)), radv.Job("big", (("comp", _spirv(BIG)),)),
            radv.Job("odd", (("comp", _spirv(odd)),))]
    monkeypatch.chdir(tmp_path)
    res = radv.statistics(jobs, ("polaris10", "navi21"), ir_dir="isa")  # relative to here, not to the worker
    assert res.errors == {}
    assert set(res.failed["odd"]) == {"polaris10", "navi21"} and "set 0" in res.failed["odd"]["navi21"]
    tmp_path = tmp_path / "isa"
    for family in ("polaris10", "navi21"):
        assert res.devices[family].startswith(f"Null hardware (RADV {family.upper()})")
        small, big = res.of(family, "small", "comp"), res.of(family, "big", "comp")
        assert small["VGPRs"] > 0 and small["Instructions"] > 0 and small["Code size"] > 0
        assert small["Spilled VGPRs"] == 0 and small["Spilled SGPRs"] == 0 and small["Scratch size"] == 0
        assert big["VGPRs"] > small["VGPRs"] and big["Instructions"] > small["Instructions"], (small, big)
        assert big["Subgroups per SIMD"] <= small["Subgroups per SIMD"]  # more registers, no more waves
        ir = (tmp_path / family / "small.comp.txt").read_text()
        assert "ACO IR" in ir and "Assembly" in ir  # the executable's internal representations, saved


def test_the_ubershader_needs_at_least_the_registers_of_every_specialized_shader(radv):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from generator.measure.gpu import GpuRequest, estimate_check
    from generator.measure.plans import scene_rows

    lib = load_library()
    request = GpuRequest(("polaris10", "navi21", "vangogh", "navi31"))
    rows = scene_rows(load_scene(EXAMPLE, lib), lib, gpu=request)
    assert request.note == "" and not request.errors
    assert all(r.gpu and set(r.gpu) == set(request.families) for r in rows)
    for family in request.families:
        for stage in ("frag", "vert"):
            for lang in ("glsl", "hlsl", "wgsl"):
                uber = [r for r in rows if r.table == "ubershader" and r.stage == stage and r.language == lang]
                spec = [r for r in rows if r.table == "permutation" and r.stage == stage and r.language == lang]
                assert len(uber) == 1 and len(spec) == 5
                worst = max(r.gpu[family]["VGPRs"] for r in spec)
                assert uber[0].gpu[family]["VGPRs"] >= worst, (family, stage, lang)
                assert uber[0].gpu[family]["Subgroups per SIMD"] <= min(r.gpu[family]["Subgroups per SIMD"]
                                                                         for r in spec)
    check = estimate_check(rows, request.families)
    assert set(check) == set(request.families)
    assert all(c["n"] == 36 and -1 <= c["spearman"] <= 1 for c in check.values())


def _costs(*args):
    return subprocess.run([sys.executable, "-m", "generator.cli", "costs", *map(str, args)], cwd=REPO,
                          capture_output=True, text=True, timeout=600)


def test_costs_shows_radv_figures_for_the_example_beside_the_spirv_counts(radv):
    r = _costs(EXAMPLE, "--gpu")
    assert r.returncode == 0, r.stderr
    md = r.stdout
    assert "## AMD compiler statistics (RADV null device)" in md
    table = md.split("## AMD compiler statistics")[1]
    for family in ("polaris10", "navi21", "vangogh", "navi31"):  # the default families
        assert f"| `ec099fb79c17` | ground | frag | {family} |" in table
        assert f"| `ubershader` |  | frag | {family} |" in table
    assert "### The ubershader's register load" in md and "### The SPIR-V register estimate against RADV" in md
    again = _costs(EXAMPLE, "--gpu")
    assert again.stdout == md  # ACO's figures are deterministic
    ip = _costs(EXAMPLE, "--gpu", "polaris10,navi21,vangogh,gfx1100", "--format", "json")  # the spelling
    assert ip.returncode == 0, ip.stderr
    import json
    assert json.loads(ip.stdout)["gpu"]["families"] == ["polaris10", "navi21", "vangogh", "navi31"]
    csv = _costs(EXAMPLE, "--gpu", "navi21,vangogh", "--format", "csv")
    head = csv.stdout.splitlines()[0].split(",")
    assert "gpu_navi21_vgprs" in head and "gpu_vangogh_waves_per_simd" in head and "gpu_polaris10_vgprs" not in head


def test_bad_gpu_options_are_one_line_errors():
    r = _costs(EXAMPLE, "--gpu", "navi2")
    assert r.returncode == 2 and "did you mean 'navi21'?" in r.stderr and len(r.stderr.splitlines()) == 1
    r = _costs(EXAMPLE, "--gpu-ir", "x")
    assert r.returncode == 2 and "--gpu-ir needs --gpu" in r.stderr


def test_without_radv_the_columns_are_absent_with_one_line(monkeypatch, capsys):
    from generator.cli import main
    from generator.runtime import gpu_stats

    monkeypatch.setattr(gpu_stats, "ICD_GLOB", ("/nonexistent/radeon_icd*.json",))
    assert main(["costs", str(EXAMPLE), "--gpu"]) == 3  # asked for, not there: the environment's exit code
    out, err = capsys.readouterr()
    notes = [line for line in err.splitlines() if line.startswith("error:")]
    assert len(notes) == 1 and "install mesa-vulkan-drivers" in notes[0], err
    assert "## AMD compiler statistics" not in out and "| permutation | materials | objects | stage | tex |" in out
