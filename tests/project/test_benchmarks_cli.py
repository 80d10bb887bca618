"""The benchmark scripts' command lines: each answers --help, names the options docs/benchmarks.md's table
gives it, and refuses a bad value as a usage error (exit 2) before any work — their runs take minutes and
belong to benchmarks/, not to the test suite."""
from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCRIPTS = sorted(p for p in (REPO / "benchmarks").glob("*.py") if p.name != "cliargs.py")
PAGES = [REPO / "docs" / "benchmarks.md", REPO / "docs" / "contributing" / "benchmarks.md"]
DOC_COMMANDS = [c for page in PAGES if page.exists()
                for c in re.findall(r"`(\.venv/bin/python benchmarks/[^`]+)`", page.read_text())]


def _run(*args):
    return subprocess.run([sys.executable, *map(str, args)], cwd=REPO, capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_every_script_answers_help(script):
    r = _run(script, "--help")
    assert r.returncode == 0 and r.stdout.startswith("usage: "), r.stderr


def test_docs_name_every_script_and_only_options_they_take():
    named = {shlex.split(c)[1] for c in DOC_COMMANDS}
    assert {f"benchmarks/{p.name}" for p in SCRIPTS} <= named
    for cmd in DOC_COMMANDS:
        argv = shlex.split(cmd)
        help_text = _run(REPO / argv[1], "--help").stdout
        for opt in (a for a in argv[2:] if a.startswith("--")):
            assert opt in help_text, f"docs show {opt} for {argv[1]}, which does not take it"


@pytest.mark.parametrize("args", [
    ("scenegen.py", "0", "x.toml"),
    ("build.py", "--n", "0"),
    ("scale.py", "--permutations", "0"),
    ("scale.py", "--plan", "10000,lots"),
    ("hybrid.py", "--size", "big"),
    ("hybrid.py", "--frames", "-3"),
    ("runtime_vs_error.py", "--samples", "0"),
    ("contact_sheet.py", "--out", "sheet.png"),  # a file name where a folder goes: refused, not made a folder
    ("contact_sheet.py", "--targets", "glsl,metal"),
    ("radv_estimate.py", "--families", "navi21"),
], ids=lambda a: " ".join(a))
def test_a_bad_value_is_a_usage_error(args, tmp_path):
    r = _run(REPO / "benchmarks" / args[0], *args[1:])
    assert r.returncode == 2 and "error:" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not (REPO / "sheet.png").exists() and not (REPO / "x.toml").exists()
