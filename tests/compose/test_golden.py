"""Linked programs and emitted sources equal the checked-in goldens; the goldens compile to the recorded
SPIR-V sizes; a brick's comment or docstring edit changes no golden, and a code edit does."""
import ast
import json
import re
import shutil
from pathlib import Path

import pytest

from tests.conftest import require_tool
from tests.regen_goldens import GOLDEN, LANGUAGE_DIRS, REPO, checked_in, golden_files, main, normalize, spirv_summary

HINT = "run `make goldens` and review `git diff tests/golden`"
EDITED = "brdf/specular/microfacet.py"  # a host brick: eval cases, three of the example's materials, the switch


@pytest.fixture(scope="module")
def goldens():
    return golden_files()


@pytest.mark.golden
def test_every_golden_is_current(goldens):
    assert checked_in() == set(goldens), f"golden files added or removed — {HINT}"
    for rel, g in goldens.items():
        assert (GOLDEN / rel).read_text() == g.text, f"{rel} drifted — {HINT}"


@pytest.mark.golden
def test_goldens_cover_every_language_and_stage(goldens):
    seen = {(g.language, g.stage) for g in goldens.values() if g.language != "ir"}
    assert seen == {(lang, s) for lang in LANGUAGE_DIRS for s in ("vert", "frag", "comp")}


@pytest.mark.golden
def test_every_golden_case_has_its_ir_and_no_name_is_a_hash(goldens):
    cases = {re.sub(r"^\w+/(.*)\.(?:vert|frag|comp)\.\w+$", r"ir/\1.ir", rel)
             for rel, g in goldens.items() if g.language != "ir"}
    assert cases == {rel for rel, g in goldens.items() if g.language == "ir"}
    names = {rel.split("/")[-1].split(".")[0] for rel in goldens}
    assert not [n for n in names if re.fullmatch(r"[0-9a-f]{12}", n)]
    assert {"painted_wood", "polished_gold", "ubershader"} <= names


@pytest.mark.golden
def test_normalization_rewrites_only_the_provenance_hashes_and_line_directives():
    emitted = "\n".join([
        "// brick bricks/brdf/diffuse/lambert.py sha256:571e572632b7",
        "// template glsl/fragment.glsl.j2 sha256:35dbc3ce7a17",
        '#line 19 "bricks/brdf/diffuse/lambert.py"',
        "vec3 f() {",
        '#line 22 "bricks/brdf/diffuse/lambert.py"',  # the same file after a gap: dropped
        "}",
        '#line 3 "<glue>"',
        "// hash: 3492f48173ec",
        "    float x = 19.0; // brick bricks/a.py sha256:571e572632b7",  # code, not a header line
        '    #line 19 "indented"',  # not the shape the emitters write: kept, so it would show in a diff
        "// brick bricks/a.py sha256:571e572632b7 trailing",
        '#line 4 "bricks/brdf/diffuse/lambert.py"',  # back to a file: kept
    ])
    assert normalize(emitted).split("\n") == [
        "// brick bricks/brdf/diffuse/lambert.py sha256:<elided>",
        "// template glsl/fragment.glsl.j2 sha256:<elided>",
        '#line N "bricks/brdf/diffuse/lambert.py"',
        "vec3 f() {",
        "}",
        '#line N "<glue>"',
        *emitted.split("\n")[7:11],
        '#line N "bricks/brdf/diffuse/lambert.py"',
    ]


@pytest.mark.golden
def test_a_normalized_golden_differs_from_the_emitted_text_only_in_those_lines(goldens):
    """Without #line lines the two are equal but for the hashes; the directives kept are one per change of file."""
    directive = re.compile(r'^#line (?:[0-9]+|N) ("[^"]*")$')
    header = re.compile(r"^// (brick|template) [^ ]+ sha256:[0-9a-f]{12}$")
    for rel, g in goldens.items():
        before = [x for x in g.emitted.split("\n") if not directive.match(x)]
        after = [x for x in g.text.split("\n") if not directive.match(x)]
        assert len(before) == len(after) and all(a == b or header.match(a) for a, b in zip(before, after)), rel
        files = [m.group(1) for x in g.emitted.split("\n") if (m := directive.match(x))]
        kept = [m.group(1) for x in g.text.split("\n") if (m := directive.match(x))]
        assert kept == [f for i, f in enumerate(files) if i == 0 or files[i - 1] != f], rel


def _edit(tmp_path, change) -> Path:
    """A copy of bricks/ with EDITED rewritten by change(text, tree)."""
    root = tmp_path / "bricks"
    shutil.copytree(REPO / "bricks", root)
    path = root / EDITED
    text = path.read_text()
    path.write_text(change(text, ast.parse(text)))
    return root


def _comments_and_docstrings(text: str, tree) -> str:
    """A comment line on top, a line more in the module docstring, a function docstring, and a comment and
    a blank line between the first function's first two statements: every line below the top moves, and
    two statements that were adjacent no longer are (the emitters add a #line directive between them)."""
    lines = text.split("\n")
    doc = tree.body[0]
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef))
    first, second = fn.body[0], fn.body[1]
    assert isinstance(doc, ast.Expr) and doc.end_lineno > doc.lineno and not isinstance(first, ast.Expr) \
        and second.lineno == first.end_lineno + 1, \
        f"{EDITED} no longer has a multi-line module docstring and an undocumented function: pick another brick"
    pad = " " * first.col_offset
    lines[second.lineno - 1:second.lineno - 1] = [f"{pad}# a comment the test adds between statements", ""]
    lines[first.lineno - 1:first.lineno - 1] = [f'{pad}"""What this function does (a docstring the test adds)."""']
    lines[doc.lineno:doc.lineno] = ["A line the test adds to the module docstring.", ""]
    return "\n".join(["# a comment line the test adds above the docstring", *lines])


def _code(text: str, tree) -> str:
    """A real edit: the first function's result halved."""
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef))
    ret = next(s for s in fn.body if isinstance(s, ast.Return))
    lines = text.split("\n")
    assert ret.lineno == ret.end_lineno, f"{EDITED}: pick a brick whose return fits on one line"
    line = lines[ret.lineno - 1]
    value = line[ret.value.col_offset:ret.value.end_col_offset]
    lines[ret.lineno - 1] = line[:ret.value.col_offset] + f"0.5 * ({value})" + line[ret.value.end_col_offset:]
    return "\n".join(lines)


def _regenerate(bricks, out) -> dict[str, str]:
    assert main(["--bricks", str(bricks), "--out", str(out), "--no-spirv"]) == 0
    return {rel: (out / rel).read_text() for rel in checked_in(out)}


@pytest.mark.golden
def test_a_brick_comment_or_docstring_edit_changes_no_golden(tmp_path, goldens):
    bricks = _edit(tmp_path, _comments_and_docstrings)
    edited = golden_files(bricks)
    moved = [rel for rel, g in edited.items() if g.emitted != goldens[rel].emitted]
    assert any(rel.startswith("glsl/example/") for rel in moved), "the edit should move #line numbers and hashes"
    regenerated = _regenerate(bricks, tmp_path / "golden")
    assert set(regenerated) == checked_in()
    changed = sorted(rel for rel, text in regenerated.items() if text != (GOLDEN / rel).read_text())
    assert changed == [], f"a comment and docstring edit of bricks/{EDITED} changed goldens: {changed[:5]}"


@pytest.mark.golden
def test_a_brick_code_edit_changes_its_goldens_and_only_those(tmp_path, goldens):
    regenerated = _regenerate(_edit(tmp_path, _code), tmp_path / "golden")
    changed = {rel for rel, text in regenerated.items() if text != (GOLDEN / rel).read_text()}
    # every golden naming the brick, but vertex shaders: they list the program's bricks and emit none of them
    using = {rel for rel, g in goldens.items() if f"bricks/{EDITED}" in g.emitted and g.stage != "vert"}
    assert {"ir/example/polished_gold.ir", "glsl/example/polished_gold.frag.glsl",
            "wgsl/example/polished_gold.frag.wgsl"} <= changed
    assert "ir/eval/lambert.ir" not in changed and "glsl/example/painted_wood.frag.glsl" not in changed
    assert changed == using, "a brick's code edit changes exactly the goldens that link it"


@pytest.mark.golden
@pytest.mark.toolchain
def test_goldens_compile_to_the_recorded_spirv_sizes(goldens):
    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    recorded = json.loads((GOLDEN / "spirv.json").read_text())
    now = spirv_summary(goldens)
    assert now["tools"] == recorded["tools"], f"tool versions changed — {HINT}"
    assert now["spirv_words"] == recorded["spirv_words"], f"optimized SPIR-V sizes changed — {HINT}"
