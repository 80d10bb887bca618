"""The pytest plugin as an engine's CI runs it: real pytest subprocesses in a folder laid out like an engine's
repository (its own tests beside a scene), the plugin loaded by its `pytest11` entry point."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
PERMUTATIONS = 5  # of the example scene


def _pytest(cwd, *args):
    return subprocess.run([sys.executable, "-m", "pytest", "-rf", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=600)


def test_the_plugin_takes_a_scene_by_the_loaders_suffixes():
    from generator.cli import pytest_plugin
    from generator.scene.load import SCENE_SUFFIXES
    assert pytest_plugin.SCENE_SUFFIXES == SCENE_SUFFIXES


@pytest.mark.toolchain
def test_ids_rerun_the_count_is_right_unrelated_tests_stay_out_and_junit_keeps_the_notes(tmp_path):
    from generator.assemble.checks import check_notes
    engine = tmp_path / "engine"
    (engine / "tests").mkdir(parents=True)
    (engine / "scenes").mkdir()
    shutil.copy(EXAMPLE, engine / "scenes" / "example.toml")
    (engine / "tests" / "test_engine.py").write_text("def test_the_engines_own():\n    assert False\n")
    golden = tmp_path / "golden"
    made = subprocess.run([sys.executable, "-m", "generator.cli", "check", EXAMPLE, "--golden", golden,
                           "--update-golden", "--platform", "vulkan,d3d12"], capture_output=True, text=True,
                          timeout=600)
    assert made.returncode == 0, made.stderr
    victim = next((golden / "vulkan").glob("*.frag.*"))
    victim.write_text(victim.read_text() + "// edited\n")
    bad = victim.name.split(".")[0]
    opts = ("--shadermatrix-platforms", "vulkan,d3d12", "--shadermatrix-golden", golden)

    r = _pytest(engine, "--shadermatrix-scene", "scenes/example.toml", *opts, "--junitxml", tmp_path / "j.xml")
    out = r.stdout
    assert r.returncode == 1, out
    # the header counts what runs, and the engine's own (failing) test is not among it
    assert re.search(rf"^collected {2 * PERMUTATIONS} items$", out, re.M), out
    assert "test_engine" not in out and re.search(rf"\b1 failed, {2 * PERMUTATIONS - 1} passed\b", out), out
    failed = re.findall(r"^FAILED (\S+)", out, re.M)
    assert failed == [f"scenes/example.toml::{bad}-vulkan"], out

    again = _pytest(engine, failed[0], *opts)  # the id as printed, alone: one test, the same failure
    assert re.search(r"^collected 1 item$", again.stdout, re.M), again.stdout + again.stderr
    assert re.findall(r"^FAILED (\S+)", again.stdout, re.M) == failed, again.stdout
    assert "emitted sources drift from the golden ones" in again.stdout

    last = _pytest(engine, "--lf", "--shadermatrix-scene", "scenes/example.toml", *opts)  # pytest's cache: the failed one
    assert re.search(r"\b1 failed\b", last.stdout) and " passed" not in last.stdout.splitlines()[-1], last.stdout

    # JUnit: a test per check, the notes of each (no dxc: d3d12 validates with glslang alone) as its properties
    cases = ET.parse(tmp_path / "j.xml").getroot().iter("testcase")
    props = {c.get("name"): [p.get("value") for p in c.iter("property") if p.get("name") == "shadermatrix-note"]
             for c in cases}
    assert len(props) == 2 * PERMUTATIONS and f"{bad}-vulkan" in props
    notes = check_notes(["d3d12"])
    for name, got in props.items():
        assert got == (notes if name.endswith("-d3d12") else []), (name, got)
