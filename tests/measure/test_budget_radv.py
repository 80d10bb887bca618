"""Budgets on RADV's own figures (the null device, no AMD GPU): an over-budget shader is one line at the scene line
of the material that asks for it, and `--diff` sums up what a change helped and hurt as shader-db does.

Every figure comes from ACO on RADV's null device for real (generator/runtime/gpu_stats.py); without
mesa-vulkan-drivers these skip, and under CI=true they fail.
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import require

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]  # a Vulkan device (RADV's null one) and glslc


@pytest.fixture(scope="module")
def measured():
    from generator.library.bricks import load_library
    from generator.measure.gpu import GpuRequest
    from generator.measure.plans import scene_rows
    from generator.runtime import gpu_stats
    from generator.scene.load import load_scene
    require(gpu_stats.unavailable() == "", f"RADV's null device: {gpu_stats.unavailable()}")
    lib = load_library()
    scene = load_scene(EXAMPLE, lib)
    request = GpuRequest(("navi21",))
    rows = scene_rows(scene, lib, gpu=request)
    assert request.note == "" and not request.errors
    return scene, rows


def _brdf_line(text: str, material: str) -> int:
    """The line of `brdf =` in [materials.<material>], found in the text independently of the scene loader."""
    lines = text.splitlines()
    start = lines.index(f"[materials.{material}]")
    return next(i for i in range(start, len(lines)) if lines[i].startswith("brdf")) + 1


def test_an_over_budget_shader_is_one_line_at_its_materials_line(measured):
    from generator.measure.budget import check, parse
    scene, rows = measured
    vgprs: dict = {}
    for r in rows:
        vgprs[(r.table, r.subject, r.stage)] = max(vgprs.get((r.table, r.subject, r.stage), 0), r.gpu["navi21"]["VGPRs"])
    limit = max(vgprs.values()) - 1  # the shaders with the most VGPRs are over; the example has lighter ones too
    expected = {k for k, v in vgprs.items() if v > limit}
    assert 0 < len(expected) < len(vgprs)
    over, shaders = check(rows, parse(f"navi21.vgprs={limit},spills=0"), scene)  # spills: navi21's too
    assert shaders == len(vgprs) == 12 and len(over) == len(expected)
    text = EXAMPLE.read_text()
    scene_line = text.splitlines().index("[scene]") + 1
    for (table, subject, stage), o in zip(sorted(expected, key=lambda k: (k[0] == "ubershader", k[1], k[2] == "vert")),
                                          over):
        assert f": navi21 vgprs {vgprs[(table, subject, stage)]} > {limit} — fewer values live at once" in o.line, o
        if table == "ubershader":
            assert o.line.startswith(f"{EXAMPLE}:{scene_line}:1: the ubershader of every material ({stage})"), o
            continue
        material = next(r.materials[0] for r in rows if r.subject == subject)
        assert o.line.startswith(f"{EXAMPLE}:{_brdf_line(text, material)}:1: material '{material}' "
                                 f"(permutation {subject}, {stage}; objects "), o
    # occupancy is a floor: every shader of the example runs its waves_per_simd, none more
    waves = min(r.gpu["navi21"]["Subgroups per SIMD"] for r in rows)
    assert check(rows, parse(f"navi21.waves_per_simd={waves}"), scene)[0] == []
    floor = check(rows, parse(f"navi21.waves_per_simd={waves + 1}"), scene)[0]
    assert len(floor) == 12 and all(f"navi21 waves_per_simd {waves:g} < {waves + 1}" in o.line for o in floor)


def test_the_cli_compiles_for_the_budgets_families_and_exits_1_over_it(measured, tmp_path):
    _, rows = measured
    top = max(r.gpu["navi21"]["VGPRs"] for r in rows)
    r = subprocess.run([sys.executable, "-m", "generator.cli", "costs", "scenes/example.toml", "--format", "json",
                        "--budget", f"alu=100000,navi21.vgprs={top - 1},spills=0", "--cache-dir", tmp_path],
                       cwd=REPO, capture_output=True, text=True, timeout=600)
    assert r.returncode == 1, r.stderr
    assert json.loads(r.stdout)["gpu"]["families"] == ["navi21"]  # no --gpu: the budget's family was measured
    located = [x for x in r.stderr.splitlines() if re.match(r"error: scenes/example\.toml:\d+:\d+: ", x)]
    assert located and all(f"navi21 vgprs {top} > {top - 1}" in x for x in located), r.stderr
    assert r.stderr.splitlines()[-1].startswith(
        f"budget alu ≤ 100000, navi21 vgprs ≤ {top - 1}, navi21 spills ≤ 0: {len(located)} of 12 shaders over")


def test_a_diff_ends_with_shader_dbs_helped_and_hurt_on_radvs_figures(measured):
    from generator.measure.diff import diff
    from generator.measure.report import to_json
    _, rows = measured
    old = json.loads(to_json(rows, "courtyard"))["rows"]  # an earlier report, in which ...
    uber = next(x for x in old if x["table"] == "ubershader" and x["stage"] == "frag" and x["language"] == "glsl")
    uber["gpu"]["navi21"]["VGPRs"] += 8  # ... the ubershader needed 8 more VGPRs and ran half the waves,
    uber["gpu"]["navi21"]["Subgroups per SIMD"] /= 2
    perm = next(x for x in old if x["table"] == "permutation")
    perm["gpu"]["navi21"]["Instructions"] -= 10  # and one permutation had 10 fewer instructions
    md = diff(rows, old, "OLD.json")
    assert "2 shaders changed, 0 new or gone, 36 compared." in md, md
    vg = sum(r.gpu["navi21"]["VGPRs"] for r in rows)
    waves = sum(r.gpu["navi21"]["Subgroups per SIMD"] for r in rows)
    instr = sum(r.gpu["navi21"]["Instructions"] for r in rows)
    summary = md.split("## Helped and hurt")[1]
    u_vg, u_w = uber["gpu"]["navi21"]["VGPRs"], uber["gpu"]["navi21"]["Subgroups per SIMD"]
    p_i = perm["gpu"]["navi21"]["Instructions"]
    assert (f"| navi21 vgprs | {vg + 8} → {vg} | {-8 / (vg + 8) * 100:+.2f}% | {u_vg} → {u_vg - 8} | "
            f"{-8 / u_vg * 100:+.2f}% | 1 | 0 |") in summary, summary
    assert f"| navi21 waves_per_simd | {waves - u_w:g} → {waves:g} | " in summary
    assert summary.split("| navi21 waves_per_simd |")[1].split("\n")[0].endswith("| 1 | 0 |")  # more waves: helped
    assert f"| navi21 instructions | {instr - 10} → {instr} | " in summary
    assert summary.split("| navi21 instructions |")[1].split("\n")[0].endswith(f"| {p_i} → {p_i + 10} | "
                                                                                f"{10 / p_i * 100:+.2f}% | 0 | 1 |")
    assert "Unchanged in every shader: texture, alu," in summary and "navi21 sgprs" in summary
