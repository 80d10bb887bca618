"""Hostile files: only regular files of a bounded size are read, and no brick path can
carry a line break or control character into generated code."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
LAMBERT = '"""L."""\nBRICK = {"kind": "diffuse", "cite": "x"}\n\n\ndef diffuse(NdotL: float) -> vec3:\n    return vec3(NdotL)\n'


def _cli(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout)


def _one_error(r, *parts):
    assert r.returncode != 0 and "Traceback" not in r.stderr, r.stderr
    lines = [x for x in r.stderr.splitlines() if x.startswith("error:")]
    assert len(lines) == 1 and all(p in lines[0] for p in parts), r.stderr


def test_a_fifo_as_brick_or_scene_is_an_error_not_a_hang(tmp_path):
    d = tmp_path / "bricks"
    d.mkdir()
    os.mkfifo(d / "x.py")
    _one_error(_cli("bricks", "--bricks", d), "x.py:1:1", "is a FIFO, not a regular file")
    os.mkfifo(tmp_path / "scene.toml")
    _one_error(_cli("build", tmp_path / "scene.toml", "--out", tmp_path / "out"), "scene.toml:1:1", "FIFO")


def test_a_symlink_to_a_device_and_an_oversized_file_are_refused(tmp_path):
    d = tmp_path / "bricks"
    d.mkdir()
    (d / "zero.py").symlink_to("/dev/zero")
    _one_error(_cli("bricks", "--bricks", d), "zero.py:1:1", "a device, not a regular file")
    (d / "zero.py").unlink()
    from generator.lang.errors import MAX_INPUT_BYTES
    with open(d / "huge.py", "wb") as f:
        f.truncate(MAX_INPUT_BYTES + 1)  # sparse: no disk used
    _one_error(_cli("bricks", "--bricks", d), "huge.py:1:1", "allowed")


@pytest.mark.parametrize("char", ["\r", "\u2028", "\u0085", "\v", "\f", "\x1b", '"'],
                         ids=["CR", "LS", "NEL", "VT", "FF", "ESC", "quote"])
def test_no_control_character_in_a_brick_path_reaches_generated_code(tmp_path, char):
    d = tmp_path / f"evil{char}fn INJECTED() {{}}"
    d.mkdir()
    (d / "lam.py").write_text(LAMBERT)
    r = _cli("bricks", "--bricks", d)
    _one_error(r, "the brick's path contains", "rename the file or its directory")
    raw = subprocess.run([sys.executable, "-m", "generator.cli", "bricks", "--bricks", str(d)], cwd=REPO,
                         capture_output=True, timeout=60).stderr  # bytes: no newline translation hides a CR
    assert char.encode() not in raw.split(b"error:", 1)[1]  # not even in the message
