"""The front page and the docs tree stay navigable: README is short and names every command with its page,
every page is reachable from the docs index, and every `shadermatrix …` shown, in a ```sh block or inline,
names a real command and only options it takes.

Running the commands of the pages' ```sh blocks, and resolving every link and anchor, is tests/project/test_docs.py's.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
README = REPO / "README.md"
DOCS = REPO / "docs"
FENCE = re.compile(r"^```.*?^```", re.S | re.M)
# The pages this file holds to its rules; docs/reference/ is generated from the code and checked by its own test.
PAGES = [README] + sorted(p for p in DOCS.rglob("*.md") if "reference" not in p.relative_to(DOCS).parts)


def _rel(p: Path) -> str:
    return str(p.relative_to(REPO))


def _prose(text: str) -> str:
    """The text outside fenced blocks (a `# comment` in a sh block is no heading, a `](x)` in TOML no link)."""
    return FENCE.sub("", text)


def _links(page: Path) -> list[tuple[str, str]]:
    """(target path or '', anchor or '') of every relative link in the page's prose."""
    out = []
    for target in re.findall(r"\]\(([^)\s]+)\)", _prose(page.read_text())):
        if re.match(r"[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        out.append((path, anchor))
    return out


def _commands_shown(text: str) -> list[str]:
    """Every `shadermatrix …` in inline code and in sh blocks, with its trailing comment cut off."""
    shown = re.findall(r"`(shadermatrix [^`\n]+)`", _prose(text))
    for block in re.findall(r"^```sh\n(.*?)^```", text, re.S | re.M):
        shown += [ln.split("  #")[0].strip() for ln in block.splitlines() if ln.startswith("shadermatrix ")]
    return shown


def test_readme_fits_on_three_screens():
    n = len(README.read_text().splitlines())
    assert n <= 150, f"README.md has {n} lines: move detail into docs/ and link it"


def test_readme_shows_the_two_commands_and_the_first_three():
    text = README.read_text()
    blocks = "\n".join(re.findall(r"^```sh\n(.*?)^```", text, re.S | re.M))
    lines = [ln.split("  #")[0].strip() for ln in blocks.splitlines()]
    assert "make demo" in lines and "make test" in lines
    assert any(ln.startswith(". .venv/bin/activate && shadermatrix") for ln in lines)  # how to run the CLI
    for first in ("shadermatrix build scenes/example.toml", "shadermatrix costs scenes/example.toml",
                  "shadermatrix accuracy scenes/example.toml"):
        assert any(ln.startswith(first) for ln in lines), first
    assert "3.11.2" in text, "README states the supported Python versions (Debian 12's 3.11.2 among them)"


def test_readme_gives_every_command_one_line_with_its_page():
    from generator.cli import parser

    choices = next(a for a in parser()._actions if a.dest == "command").choices
    rows = {m[1]: m[2] for m in re.finditer(r"^\| `shadermatrix ([a-z]+)` \|.*\[[^\]]+\]\(([^)#]+)", README.read_text(),
                                             re.M)}
    assert set(rows) == set(choices), f"README's command table: missing {set(choices) - set(rows)}, " \
                                      f"unknown {set(rows) - set(choices)}"
    for sub, page in rows.items():
        assert (REPO / page).is_file(), f"README links `shadermatrix {sub}` to {page}, which does not exist"


def test_every_page_is_reachable_from_the_docs_index():
    reached, todo = set(), [DOCS / "README.md"]
    while todo:
        page = todo.pop()
        if page in reached or not page.is_file() or page.suffix != ".md":
            continue
        reached.add(page)
        for path, _ in _links(page):
            if path:
                target = (page.parent / path).resolve()
                todo.append(target / "README.md" if target.is_dir() else target)
    orphans = [_rel(p) for p in PAGES[1:] if p.resolve() not in reached]
    assert not orphans, f"pages no link from docs/README.md leads to: {orphans}"


@pytest.mark.parametrize("page", PAGES, ids=_rel)
def test_commands_shown_name_real_subcommands_and_options(page):
    from generator.cli import parser

    choices = next(a for a in parser()._actions if a.dest == "command").choices
    for cmd in _commands_shown(page.read_text()):
        sub = cmd.split()[1]
        if sub.startswith("-"):  # `shadermatrix --version`
            assert sub in ("--version", "--help"), f"{_rel(page)} shows `{cmd}`"
            continue
        assert sub in choices, f"{_rel(page)} shows `shadermatrix {sub}`, which is no command"
        known = {o for a in choices[sub]._actions for o in a.option_strings}
        for opt in re.findall(r"(?<![\w-])--?[a-zA-Z][a-z-]*", cmd):
            assert opt in known, f"{_rel(page)} shows {opt} for `shadermatrix {sub}`, which does not take it"


def test_no_page_points_at_the_notes_file_that_became_docs_design():
    for page in PAGES:
        assert "NOTES.md" not in page.read_text(), f"{_rel(page)} names NOTES.md: link docs/design/ instead"
    assert not (REPO / "NOTES.md").exists(), "NOTES.md moved into docs/design/, by subsystem"
