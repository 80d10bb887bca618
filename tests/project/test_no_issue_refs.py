"""No page, message or code comment sends the reader to a document that is not here, or to a tracker number.

The design document the project was started from is not in the repository, and an issue number says which
piece of work made a thing, not what it is: both are dead ends for a reader. Say what the thing is, and
point to a page of docs/ (docs/design/…, docs/reference/language.md) where more is needed.
"""
from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ROOTS = ("generator", "tests", "bricks", "benchmarks", "scripts", "docs", "README.md", "Makefile", "pyproject.toml")
SKIP_DIRS = {"__pycache__", ".pytest_cache", ".ruff_cache", ".venv", ".venv-alt", ".venv-deb", ".tools", "out"}
TEXT = {".py", ".md", ".toml", ".j2", ".txt", ".sh", ".json", ".cfg", ".ini", ".yml", ".yaml", ".glsl", ".hlsl",
        ".wgsl", ".csv", ".gltf", ""}
# Written so that these lines do not match themselves.
FORBIDDEN = [(re.compile(r"DESIGN\.md"), "names the design document, which is not in the repository"),
             (re.compile(r"\bissues?\s*#?\s*\d+", re.I), "names an issue number")]


def _files():
    for root in ROOTS:
        p = REPO / root
        if p.is_file():
            yield p
        elif p.is_dir():
            for f in sorted(p.rglob("*")):
                if f.is_file() and f.suffix in TEXT and not SKIP_DIRS.intersection(f.relative_to(REPO).parts):
                    yield f


def hits(text: str) -> list[tuple[int, str]]:
    """(line, why) of every forbidden reference in `text`."""
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        for pattern, why in FORBIDDEN:
            if pattern.search(line):
                out.append((n, why))
    return out


def test_no_file_names_the_design_document_or_an_issue_number():
    found = []
    for f in _files():
        try:
            text = f.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue  # not text
        lines = text.splitlines()
        for n, why in hits(text):
            found.append(f"{f.relative_to(REPO)}:{n}: {why}: {lines[n - 1].strip()[:120]}")
    assert not found, ("say what the thing is, not which issue made it; point to a page of docs/ instead of the "
                       "design document:\n" + "\n".join(found))


def test_the_patterns_catch_what_they_are_for():
    design, issue = "DESIGN" + ".md", "iss" + "ue"  # spelt apart, so this file passes its own test
    assert [n for n, _ in hits(f"ok\nsee {design}, Layout\n")] == [2]
    for s in (f"({issue} 12, item 3)", f"{issue.title()} 13: the bricks", f"{issue}s 9 and 10", f"{issue} #7",
              f"{issue}#7"):
        assert hits(s), s
    for s in (f"an {issue} with the driver", f"{issue}d 3 warnings", f"t{issue} 5"):
        assert not hits(s), s
