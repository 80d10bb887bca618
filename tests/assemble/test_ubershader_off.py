"""`[scene] ubershader = false`: build ships no fallback ubershader, and turning it back on builds it; a scene whose
ubershader would hold more than UBER_VARIANTS_WARN material variants gets one located warning."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.toolchain


def _build(scene: Path, out: Path) -> subprocess.CompletedProcess:
    r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(out), "--platform",
                        "vulkan"], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    return r


def _uber_files(out: Path) -> list[str]:
    """The ubershader's sources in the tree (its SPIR-V may be shared: a vertex stage equal to a permutation's)."""
    return sorted(p.name for p in out.rglob("ubershader.*"))


def test_ubershader_false_ships_none_and_true_builds_it_again(tmp_path):
    text = (REPO / "scenes" / "example.toml").read_text()
    assert "[scene]\n" in text
    off = text.replace("[scene]\n", "[scene]\nubershader = false\n", 1)
    scene, out = tmp_path / "s.toml", tmp_path / "out"
    scene.write_text(text)
    _build(scene, out)
    on = json.loads((out / "manifest.json").read_text())["ubershader"]
    assert on["status"] == "ok" and _uber_files(out)
    scene.write_text(off)
    _build(scene, out)
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["ubershader"] == {}
    assert _uber_files(out) == []  # the last build's ubershader files went too
    assert all(e["status"] == "ok" for e in manifest["permutations"])
    scene.write_text(text)
    r = _build(scene, out)
    assert json.loads((out / "manifest.json").read_text())["ubershader"]["hash"] == on["hash"], r.stdout


def test_a_scene_whose_ubershader_would_be_huge_is_warned_at_its_scene_line(tmp_path, monkeypatch):
    from generator.assemble import entries
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    scene_path = tmp_path / "s.toml"
    text = (REPO / "scenes" / "example.toml").read_text()
    scene_path.write_text(text)
    scene = load_scene(scene_path, load_library(()))
    variants = len({(p.brdf, p.packing, p.output) for p in scene.permutations.values()})
    assert entries.ubershader_warning(scene) is None
    monkeypatch.setattr(entries, "UBER_VARIANTS_WARN", variants - 1)
    line = text[:text.index("[scene]")].count("\n") + 1
    w = entries.ubershader_warning(scene)
    assert w.startswith(f"{scene_path}:{line}:1: the ubershader would hold {variants} material variants")
    assert "ubershader = false" in w
    scene.ubershader = False
    assert entries.ubershader_warning(scene) is None


def test_ubershader_must_be_true_or_false(tmp_path):
    text = (REPO / "scenes" / "example.toml").read_text()
    scene = tmp_path / "s.toml"
    scene.write_text(text.replace("[scene]\n", '[scene]\nubershader = "no"\n', 1))
    r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(tmp_path / "o")],
                       cwd=REPO, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and f"{scene}:" in r.stderr and "ubershader" in r.stderr, r.stderr
