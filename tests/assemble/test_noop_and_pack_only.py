"""A no-op known before the scene is loaded (assemble/noop.py), and `build --pack-only` (assemble/spool.py).

The no-op: after a real build, the same build again with a scene loader that fails (generator.scene.load and
the brick library replaced by one that raises, nothing of the tools) says "up to date" and changes no file, so it
never loaded anything; each kind of change to what the build reads (the scene's bytes or only its mtime, a brick
touched or added, an output file gone, another option) reaches the loader instead. Pack-only: no loose artifact
in the tree, packs byte-identical to a loose build's, after a rebuild that keeps units from the packs too.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
OLD = time.time() - 3600  # inputs older than the build: the record trusts what was there when a build began

# `shadermatrix ARGS` where loading a scene or the bricks raises: a build that gets past its no-op check fails
_NO_LOADING = """
import sys
import generator.library.bricks as bricks
import generator.scene.load as load
def refuse(*args, **kwargs):
    raise SystemExit("the scene loader was reached")
bricks.load_library = load.load_scene = refuse
from generator.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _cli(*args, loading: bool = True) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "generator.cli"] if loading else [sys.executable, "-c", _NO_LOADING]
    return subprocess.run([*cmd, *map(str, args)], cwd=REPO, capture_output=True, text=True, timeout=600)


def _tree(out: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(out)): (p.stat().st_size, p.stat().st_mtime_ns) for p in out.rglob("*") if p.is_file()}


def _old(*paths: Path) -> None:
    for p in paths:
        os.utime(p, (OLD, OLD))


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The example (its images are generated) with an unused brick of an engine's own directory, built loose with
    packs and packs-only."""
    tmp = tmp_path_factory.mktemp("noop")
    scene, bricks = tmp / "example.toml", tmp / "bricks"
    shutil.copy(REPO / "scenes" / "example.toml", scene)
    bricks.mkdir()
    shutil.copy(REPO / "bricks" / "output" / "linear.py", bricks / "tinted.py")
    _old(scene, bricks / "tinted.py", bricks)
    for name, flag in (("loose", "--pack"), ("only", "--pack-only")):
        r = _cli("build", scene, "--out", tmp / name, "--bricks", bricks, flag, "-q")
        assert r.returncode == 0, r.stderr[-3000:]
    return tmp


def _noop(tmp: Path, out: str, *flags) -> subprocess.CompletedProcess:
    return _cli("build", tmp / "example.toml", "--out", tmp / out, "--bricks", tmp / "bricks", *flags, "-q",
                loading=False)


@pytest.mark.toolchain
def test_a_noop_loads_nothing_writes_nothing_and_any_change_takes_the_full_path(built):
    tmp, out = built, built / "loose"
    before = _tree(out)
    r = _noop(tmp, "loose", "--pack")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "5 permutations up to date: 0 composed, 0 compiled; 0 files written" in r.stdout
    assert _tree(out) == before
    r = _noop(tmp, "loose", "--pack", "--json")
    summary = json.loads(r.stdout)
    assert summary["up_to_date"] == 5 and summary["files_written"] == 0 and len(summary["packs"]) == 4

    scene, brick = tmp / "example.toml", tmp / "bricks" / "tinted.py"
    text = scene.read_text()
    artifact = next(p for p in (out / "vulkan" / "glsl").iterdir() if p.suffix == ".spv")
    saved = tmp / "saved.spv"
    shutil.copy2(artifact, saved)

    def reached(*flags) -> None:
        r = _noop(tmp, "loose", *flags)
        assert r.returncode != 0 and "the scene loader was reached" in r.stderr, (flags, r.stdout, r.stderr)

    scene.write_text(text + "# a comment\n")  # the scene's bytes
    _old(scene)
    reached("--pack")
    scene.write_text(text)
    reached("--pack")  # its mtime alone
    _old(scene)
    os.utime(brick)  # a brick of a brick directory touched
    reached("--pack")
    _old(brick)
    (tmp / "bricks" / "new.py").write_text(brick.read_text())  # a brick added
    os.utime(tmp / "bricks", (OLD, OLD))
    reached("--pack")
    (tmp / "bricks" / "new.py").unlink()
    artifact.unlink()  # an output gone
    reached("--pack")
    shutil.copy2(saved, artifact)
    reached()  # another request: without --pack
    reached("--pack", "--explain")  # it says why: the full path
    # the artifact back as it was: its directory's mtime changed, which the record vouched for (assemble/noop.py)
    reached("--pack")
    r = _cli("build", scene, "--out", out, "--bricks", tmp / "bricks", "--pack", "-q")
    assert r.returncode == 0 and _tree(out) == before, r.stderr[-3000:]  # the full path: nothing to rewrite
    assert _noop(tmp, "loose", "--pack").returncode == 0  # every change undone and recorded: a no-op again


@pytest.mark.toolchain
def test_pack_only_writes_no_loose_artifact_and_the_packs_of_a_loose_build(built):
    tmp = built
    loose, only = tmp / "loose", tmp / "only"

    def same_packs() -> None:
        assert sorted(p.name for p in (only / "packs").iterdir()) == sorted(p.name for p in (loose / "packs").iterdir())
        for p in (loose / "packs").iterdir():
            assert (only / "packs" / p.name).read_bytes() == p.read_bytes(), p.name
        m = json.loads((only / "manifest.json").read_text())
        assert m.pop("artifacts") == "packs" and m == json.loads((loose / "manifest.json").read_text())
        assert sorted(p.name for p in only.iterdir() if not p.name.startswith(".")) == ["manifest.json", "packs",
                                                                                      "textures"]

    same_packs()
    r = _noop(tmp, "only", "--pack-only")  # its no-op: known without loading too
    assert r.returncode == 0 and "up to date" in r.stdout, r.stderr
    scene = tmp / "example.toml"
    text = scene.read_text()
    try:  # one material's BRDF changed: one permutation rebuilt, the others kept from the old packs
        scene.write_text(text.replace('brdf = "lambert+phong_normalized"', 'brdf = "lambert+blinn_phong_normalized"'))
        for name, flag in (("loose", "--pack"), ("only", "--pack-only")):
            r = _cli("build", scene, "--out", tmp / name, "--bricks", tmp / "bricks", flag, "--json")
            assert r.returncode == 0, r.stderr[-3000:]
            assert json.loads(r.stdout)["up_to_date"] == 4
        same_packs()
    finally:
        scene.write_text(text)
        _old(scene)


@pytest.mark.parametrize("dir_fd", [True, False], ids=["dir_fd", "whole_paths"])
def test_the_size_check_finds_a_changed_or_missing_file(tmp_path, monkeypatch, dir_fd):
    """noop._sizes_match, by directory descriptors and (where a platform has none) by whole paths."""
    from generator.assemble import noop
    if not dir_fd:
        monkeypatch.setattr(noop.os, "supports_dir_fd", set())
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.spv").write_bytes(b"1234")
    (tmp_path / "m.json").write_bytes(b"{}")
    files = {"a/x.spv": 4, "m.json": 2}
    root = os.fspath(tmp_path)
    assert noop._sizes_match(root, files)
    assert not noop._sizes_match(root, {**files, "a/x.spv": 5})
    with pytest.raises(OSError):  # check() reads a missing file as "not a no-op"
        noop._sizes_match(root, {**files, "a/y.spv": 1})
