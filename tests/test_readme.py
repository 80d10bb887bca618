"""README's commands: every concrete command in its ```sh blocks runs, exactly as written.

Synopsis lines (with placeholders such as SCENE, DIR, SPEC) are usage, checked by their
subcommand's --help; `make test` is what runs this file, so it is checked to exist only.
"""
from __future__ import annotations

import os
import re
import shlex
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
README = (REPO / "README.md").read_text()


def _commands() -> list[str]:
    out = []
    for block in re.findall(r"```sh\n(.*?)```", README, re.S):
        for line in re.sub(r"\\\n\s*", " ", block).splitlines():
            cmd = line.split("  #")[0].strip()
            if cmd:
                out.append(cmd)
    return out


COMMANDS = _commands()
PLACEHOLDER = re.compile(r"\b(SCENE|DIR|SPEC|FILE|NAME|VALUE|S\.npy|F\.npy)\b|\[|\{")


def test_readme_shows_commands():
    assert "make demo" in COMMANDS and "make test" in COMMANDS
    assert any(c.startswith(". .venv/bin/activate && shadermatrix") for c in COMMANDS)  # how to run the CLI
    assert any(c.startswith("shadermatrix costs scenes/example.toml") for c in COMMANDS)


@pytest.mark.toolchain
@pytest.mark.lavapipe  # `shadermatrix doctor` and `make demo` look for the device and the tools
@pytest.mark.parametrize("cmd", [c for c in COMMANDS if not PLACEHOLDER.search(c)])
def test_concrete_readme_command_runs(cmd, tmp_path):
    argv = shlex.split(cmd)
    if argv[0] == "." or "&&" in argv:  # a shell line (`. .venv/bin/activate && shadermatrix …`): bash runs it
        argv = ["bash", "-c", cmd]
    elif argv[0] == "make":
        targets = re.findall(r"^([a-z]+):", (REPO / "Makefile").read_text(), re.M)
        assert argv[1] in targets, f"README shows `{cmd}` but the Makefile has no such target"
        if argv[1] in ("test", "goldens"):  # test runs this file; goldens would rewrite the goldens
            return
    elif argv[0] in ("shadermatrix", "pytest"):  # as after `. .venv/bin/activate`
        argv[0] = str(REPO / ".venv" / "bin" / argv[0])
    env = dict(os.environ)
    env.pop("SHADERMATRIX_FORBID_TOOLS", None)
    env.pop("SHADERMATRIX_FORBID_DEVICE", None)
    r = subprocess.run(argv, cwd=REPO, capture_output=True, text=True, timeout=600, env=env)
    assert r.returncode == 0, f"`{cmd}` exited {r.returncode}:\n{r.stderr[-2000:]}"


def test_readme_links_stay_inside_the_repository():
    for target in re.findall(r"\]\(([^)#]+)", README):
        if not re.match(r"https?://", target):
            assert (REPO / target).resolve().is_relative_to(REPO) and (REPO / target).exists(), target


@pytest.mark.parametrize("cmd", [c for c in COMMANDS if PLACEHOLDER.search(c) and c.startswith("shadermatrix ")])
def test_synopsis_lines_name_real_subcommands_and_options(cmd):
    from generator.cli import parser

    sub = cmd.split()[1]
    p = parser()
    choices = next(a for a in p._actions if a.dest == "command").choices
    assert sub in choices, f"README shows `shadermatrix {sub}`, which is no command"
    known = {o for a in choices[sub]._actions for o in a.option_strings}
    for opt in re.findall(r"(?<![\w-])--[a-z][a-z-]*", cmd):
        assert opt in known, f"README shows {opt} for `shadermatrix {sub}`, which does not take it"
