"""docs/reference/ is generated from the code (scripts/gen_reference.py) and must be current.

The pages are regenerated into a temporary directory and compared byte for byte with the committed ones;
the manifest page is rendered from the manifest's JSON Schema, which a real build of scenes/example.toml must
validate against (tests/assemble/test_manifest_schema.py checks the schema itself).
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
    extra = sorted(p.name for p in DOCS.glob("*.md") if p.name not in gen_reference.PAGES + gen_reference.HANDWRITTEN)
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


def test_the_manifest_page_has_a_section_per_object_and_a_row_per_field():
    s = reference_manifest.schema()
    page = reference_manifest.render("")
    for name, d in s["$defs"].items():
        section = page.split(f"\n## {d['title']}\n", 1)
        assert len(section) == 2, f"no section for $defs/{name}"
        body = section[1].split("\n## ", 1)[0]
        for k in d.get("properties", {}):
            assert f"| `{k}`" in body, f"$defs/{name}: no row for {k}"
    assert (DOCS / "manifest.schema.json").read_text() == reference_manifest.schema_text()


@pytest.mark.toolchain
def test_the_example_manifest_validates_against_the_schema():
    problems = reference_manifest.check_example_build()
    assert not problems, "\n".join(problems) + f"\n(then run `{REGENERATE}`)"
