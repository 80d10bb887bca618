"""The depfile names every template the output was composed with, whichever units a build composed again: a
rebuild after a change of scene values alone composes every permutation again (their input keys hold the values)
and keeps the ubershader (its key does not), and the ubershader's templates stay in the depfile."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.toolchain


def _build(scene: Path, out: Path, dep: Path) -> tuple[str, set[str]]:
    r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(out),
                        "--depfile", str(dep)], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    rest = dep.read_text().partition(":")[2]
    return r.stdout, {d.strip().rstrip("\\").strip() for d in rest.splitlines()} - {""}


def test_a_rebuild_that_keeps_the_ubershader_still_lists_its_templates(tmp_path):
    scene = tmp_path / "example.toml"
    text = (REPO / "scenes" / "example.toml").read_text()
    scene.write_text(text)
    _, first = _build(scene, tmp_path / "out", tmp_path / "first.d")
    uber = {d for d in first if d.endswith(".j2") and "ubershader" in Path(d).name}
    assert {f"generator/backends/{lang}/templates/ubershader.{lang}.j2" for lang in ("glsl", "hlsl", "wgsl")} <= uber

    lamp = "color = [4.0, 3.2, 2.0]"  # the lamp lights every object: every permutation's input key changes
    assert text.count(lamp) == 1
    scene.write_text(text.replace(lamp, "color = [4.0, 3.2, 2.5]"))  # a parameter value, no permutation key
    stdout, second = _build(scene, tmp_path / "out", tmp_path / "second.d")
    assert "(0 up to date, 0 failed, 0 stale)" in stdout  # every permutation composed again, the ubershader kept
    assert uber <= second, sorted(uber - second)
    assert second == first
