"""Every shell command in the docs runs: the ```sh blocks of README.md and docs/**/*.md.

The convention, for whoever writes a page:

- A line of a ```sh block is one command (a line ending in `\\` continues on the next). Blank lines and
  lines that start with `#` are skipped. Show usage with placeholders (SCENE, DIR) in a ```text block:
  everything in a ```sh block is run.
- Each command runs on its own with bash, from the repository root, with .venv/bin first on PATH (so
  `shadermatrix …` and `. .venv/bin/activate && …` both work), in page order; a command that needs
  what an earlier line set up in the shell (a `cd`, a variable) joins it with `&&`. Files persist between
  commands: write outputs under out/ (ignored by git) or /tmp.
- It must exit 0. A trailing comment sets what else is expected: `# exit N` expects exit status N,
  `# slow` runs it only in the slow tier (`pytest -m slow`), for a command that takes minutes; both may
  be given (`# slow, exit 1`).
- `make test`, `make goldens` and `make distclean` are not run (they would run the whole suite again,
  rewrite the goldens, or delete the environment the test runs in): their Makefile target is checked to
  exist. A `pytest …` command runs, but the docs' commands are not run again inside it.

Each command is one test, named page:line.
"""
from __future__ import annotations

import os
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
NOT_RUN = re.compile(r"^make (test|goldens|distclean)\b")
NESTED = "SHADERMATRIX_DOCS_TEST"  # set for the commands: a `pytest` among them does not run them again
TIMEOUT, SLOW_TIMEOUT = 600, 3600


@dataclass(frozen=True)
class Command:
    page: str
    line: int
    text: str
    exit: int = 0
    slow: bool = False

    @property
    def id(self) -> str:
        return f"{self.page}:{self.line}"


def _markers(text: str) -> tuple[int, bool]:
    """(expected exit status, slow) from the command's trailing comment (`# slow`, `# exit 1`)."""
    m = re.search(r"(?:^|\s)#([^'\"`]*)$", text)
    comment = m.group(1) if m else ""
    code = re.search(r"\bexit\s+(\d+)\b", comment)
    return (int(code.group(1)) if code else 0), bool(re.search(r"\bslow\b", comment))


def commands_of(page: str, text: str) -> list[Command]:
    """The commands of a page's ```sh blocks, each with the line it starts on."""
    out: list[Command] = []
    inside, pending, start = False, "", 0
    for n, line in enumerate(text.splitlines(), 1):
        if not inside:
            inside = re.match(r"^\s*```sh\s*$", line) is not None
            continue
        if re.match(r"^\s*```\s*$", line):
            if pending.strip():
                raise ValueError(f"{page}:{start}: a ```sh block ends inside a continued line")
            inside = False
            continue
        if not pending:
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            start = n
        part = line.strip() if pending else line.rstrip()
        if part.endswith("\\"):
            pending += part[:-1].rstrip() + " "
            continue
        full = (pending + part).strip()
        pending = ""
        code, slow = _markers(full)
        out.append(Command(page, start, full, code, slow))
    if inside:
        raise ValueError(f"{page}: a ```sh block is not closed")
    return out


def pages() -> list[Path]:
    found = [REPO / "README.md"] if (REPO / "README.md").is_file() else []
    return found + sorted((REPO / "docs").rglob("*.md"))


def all_commands() -> list[Command]:
    return [c for p in pages() for c in commands_of(str(p.relative_to(REPO)), p.read_text(encoding="utf-8"))]


COMMANDS = all_commands()


def _param(c: Command):
    return pytest.param(c, id=c.id, marks=[pytest.mark.slow] if c.slow else [])


def _env(tmp_path: Path) -> dict:
    env = dict(os.environ)
    env.pop("SHADERMATRIX_FORBID_TOOLS", None)   # the docs' commands run the tools and open the device
    env.pop("SHADERMATRIX_FORBID_DEVICE", None)
    env.pop("VIRTUAL_ENV", None)
    env["PATH"] = f"{REPO / '.venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["TMPDIR"] = str(tmp_path)
    env[NESTED] = "1"
    return env


@pytest.mark.toolchain
@pytest.mark.lavapipe
@pytest.mark.parametrize("cmd", [_param(c) for c in COMMANDS])
def test_doc_command(cmd: Command, tmp_path):
    if os.environ.get(NESTED):
        pytest.skip("a docs command's own pytest run: the docs' commands run in the outer one")
    if NOT_RUN.match(cmd.text):
        target = re.match(r"^make (\S+)", cmd.text)
        if target:
            targets = re.findall(r"^([A-Za-z_-]+):", (REPO / "Makefile").read_text(), re.M)
            assert target.group(1) in targets, f"{cmd.id}: `{cmd.text}` names no target of the Makefile"
        return
    r = subprocess.run(["bash", "-c", cmd.text], cwd=REPO, env=_env(tmp_path), capture_output=True, text=True,
                       timeout=SLOW_TIMEOUT if cmd.slow else TIMEOUT)
    assert r.returncode == cmd.exit, (
        f"{cmd.id}: `{cmd.text}` exited {r.returncode}, the page expects {cmd.exit} — fix the command or the "
        f"code, or mark it (`# exit N`, `# slow`)\n--- stderr ---\n{r.stderr[-3000:]}\n--- stdout ---\n"
        f"{r.stdout[-1500:]}")


def test_the_docs_have_commands():
    assert COMMANDS, "no ```sh block found in README.md or docs/ — the docs test would pass on nothing"


def test_commands_are_parsed_as_the_convention_says():
    page = "\n".join([
        "text", "```sh", "# a comment line", "", "shadermatrix build scenes/example.toml \\",
        "    --out out/x  # slow", "shadermatrix costs s.toml --budget alu=1  # exit 1",
        "make demo  # slow, exit 2", "echo '# exit 5'", "```", "```text", "shadermatrix build SCENE", "```"])
    got = [(c.line, c.text, c.exit, c.slow) for c in commands_of("p.md", page)]
    assert got == [(5, "shadermatrix build scenes/example.toml --out out/x  # slow", 0, True),
                   (7, "shadermatrix costs s.toml --budget alu=1  # exit 1", 1, False),
                   (8, "make demo  # slow, exit 2", 2, True),
                   (9, "echo '# exit 5'", 0, False)]
    with pytest.raises(ValueError, match="not closed"):
        commands_of("p.md", "```sh\nls\n")
    assert NOT_RUN.match("make test  # slow") and NOT_RUN.match("make distclean")
    assert not NOT_RUN.match("make demo") and not NOT_RUN.match("make testing")


def _anchors(text: str) -> set[str]:
    """GitHub's anchors of a page's headings: lower case, punctuation dropped, spaces to hyphens, -1, -2 … for
    repeats (headings inside fenced blocks are not headings)."""
    seen: dict[str, int] = {}
    out = set()
    for title in re.findall(r"^#{1,6}\s+(.+?)\s*#*\s*$", re.sub(r"```.*?```", "", text, flags=re.S), re.M):
        slug = re.sub(r"[^\w\- ]", "", re.sub(r"`", "", title).lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


def test_relative_links_lead_to_a_file_and_heading():
    broken = []
    for page in pages():
        text = page.read_text(encoding="utf-8")
        prose = re.sub(r"```.*?```", "", text, flags=re.S)
        for target in re.findall(r"\]\(([^)\s]+)\)", prose):
            if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto:
                continue
            path, _, frag = target.partition("#")
            dest = (page.parent / path).resolve() if path else page
            where = f"{page.relative_to(REPO)}: ({target})"
            if not dest.exists():
                broken.append(f"{where}: no such file")
            elif not dest.is_relative_to(REPO):
                broken.append(f"{where}: outside the repository")
            elif frag and dest.suffix == ".md" and frag not in _anchors(dest.read_text(encoding="utf-8")):
                broken.append(f"{where}: no heading #{frag} there")
    assert not broken, "links that lead nowhere:\n" + "\n".join(broken)

