"""docs/reference/ is generated from the code (scripts/gen_reference.py) and must be current.

The pages are regenerated into a temporary directory and compared byte for byte with the committed ones;
the manifest page's field descriptions are checked against a real build of scenes/example.toml: every key
that build writes is described, and every field described as always there is written.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs" / "reference"
SCRIPT = REPO / "scripts" / "gen_reference.py"
REGENERATE = "make reference"
sys.path.insert(0, str(SCRIPT.parent))

import gen_reference  # noqa: E402
import reference_manifest  # noqa: E402


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("reference")
    r = subprocess.run([sys.executable, str(SCRIPT), str(out), "--no-build"], cwd=REPO, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, f"scripts/gen_reference.py failed:\n{r.stderr[-3000:]}"
    return out


@pytest.mark.parametrize("page", gen_reference.PAGES)
def test_page_is_current(page, regenerated):
    fresh = (regenerated / page).read_text()
    committed = DOCS / page
    assert committed.is_file(), f"docs/reference/{page} is missing — run `{REGENERATE}`"
    assert committed.read_text() == fresh, f"docs/reference/{page} is stale — run `{REGENERATE}`"


def test_no_page_is_left_over():
    extra = sorted(p.name for p in DOCS.glob("*.md") if p.name not in gen_reference.PAGES)
    assert not extra, f"docs/reference/ holds {extra}, which nothing generates — remove them or generate them"


def test_every_command_and_option_is_on_the_cli_page():
    from generator.cli import parser
    page = gen_reference.render_cli()
    for name, sp in gen_reference._subcommands(parser()).items():
        assert f"## shadermatrix {name}\n" in page, name
        for action in sp._actions:
            for opt in [] if action.dest == "help" else action.option_strings:
                assert f"`{opt}" in page.split(f"## shadermatrix {name}\n", 1)[1], f"{name} {opt}"


def test_every_brick_is_in_the_catalogue():
    from generator.library.bricks import load_library
    page = gen_reference.render_bricks()
    for (kind, bid), b in load_library(()).bricks.items():
        assert f"### {bid} ({kind})\n" in page and f"`{b.display_path}`" in page, f"{kind} {bid}"


def test_every_intrinsic_kind_and_input_is_on_the_language_page():
    from generator.lang.intrinsics import INTRINSICS
    from generator.library.inputs import INPUTS
    from generator.library.kinds import KINDS
    page = gen_reference.render_language()
    for name in [*INTRINSICS, *KINDS, *(i.name for i in INPUTS)]:
        assert f"| `{name}` |" in page, name


def test_the_manifest_check_finds_undescribed_and_unwritten_fields():
    problems = reference_manifest.check({"generator": "shadermatrix 0", "bogus": 1, "tools": {"naga": "1"}})
    assert any(p.startswith("manifest.json .bogus: not described") for p in problems), problems
    assert any("describes 'scene', which the example build does not write" in p for p in problems), problems
    assert not any(".tools.naga" in p for p in problems), problems  # a key that is a name: described as <tool>


@pytest.mark.toolchain
def test_every_key_of_the_example_manifest_is_described(tmp_path):
    manifest = reference_manifest.example_manifest(tmp_path / "out")
    problems = reference_manifest.check(manifest)
    assert not problems, "\n".join(problems) + f"\n(then run `{REGENERATE}`)"
