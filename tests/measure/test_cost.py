"""Cost analysis: hand-assembled SPIR-V with known answers, bricks of known cost, the costs CLI.

Fixtures in tests/fixtures/spirv/*.spvasm are assembled with the real
`spirv-as` (and validated with `spirv-val`); their comments state the
answers asserted here. Bricks in tests/bricks/cost cost what their
docstrings say by construction.
"""
from __future__ import annotations

import json
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import require_tool

REPO = Path(__file__).resolve().parents[2]
FIXTURES = REPO / "tests" / "fixtures" / "spirv"
COST_BRICKS = REPO / "tests" / "bricks" / "cost"
EXAMPLE = REPO / "scenes" / "example.toml"
COMPILERS = ("glslc", "naga", "spirv-val", "spirv-opt")


def assemble(name: str, tmp_path: Path) -> bytes:
    """A fixture assembled by spirv-as and checked by spirv-val."""
    spirv_as, spirv_val = require_tool("spirv-as"), require_tool("spirv-val")
    out = tmp_path / f"{name}.spv"
    subprocess.run([spirv_as, "--target-env", "vulkan1.1", str(FIXTURES / f"{name}.spvasm"), "-o", str(out)],
                   check=True, capture_output=True)
    subprocess.run([spirv_val, "--target-env", "vulkan1.1", str(out)], check=True, capture_output=True)
    return out.read_bytes()


def names(mod, ids) -> set[str]:
    return {mod.name(i) for i in ids}


def block_liveness(data: bytes):
    from generator.analysis import read
    from generator.analysis.liveness import analyze_function
    mod = read(data)
    fn = mod.functions[mod.entry_points["main"][1]]
    lv = analyze_function(mod, fn)
    live = {mod.name(b.label): (names(mod, lv.live_in[b.label]), names(mod, lv.live_out[b.label]))
            for b in fn.blocks}
    return live, lv.peak


# ------------------------------------------------------------------ SPIR-V fixtures

@pytest.mark.toolchain
def test_counts_fixture_classes_and_scalar_rules(tmp_path):
    from generator.analysis import entry_cost
    c = entry_cost(assemble("counts", tmp_path))
    assert (c.alu, c.transcendental, c.texture, c.branches, c.loads, c.stores, c.other) == (8, 4, 1, 1, 4, 1, 7)
    assert c.instructions == 26  # merge declarations are not counted
    # FAdd 3 + Dot 5 + VectorTimesScalar 3 + FClamp 2 + mat4*vec4 28 + compare 1 + vec4*scalar 4 + FMul 4
    # + the ALU part of Normalize(vec3) 8 and Length(vec3) 5
    assert c.alu_scalar == 63
    assert c.transcendental_scalar == 4  # Pow, Normalize's rsqrt, Length's sqrt, Exp
    assert (c.loads_scalar, c.stores_scalar) == (3 + 3 + 2 + 16, 4)
    assert c.opcodes["OpLoad(handle)"] == 1 and c.opcodes["OpSwitch"] == 1  # neither a load nor a branch
    assert c.loads_by_storage == {"Input": 4}
    # peak: %sum (3) defined while %a, %b (3 + 3), %uv (2) and the mat4 %m (16) are still live
    assert c.registers == 27
    assert c.calls == 0


@pytest.mark.toolchain
def test_branch_liveness_carries_a_value_through_both_arms(tmp_path):
    live, peak = block_liveness(assemble("branch", tmp_path))
    assert live == {
        "entry": (set(), {"x", "y"}),
        "then": ({"x", "y"}, {"t", "y"}),
        "else": ({"y"}, {"e", "y"}),     # y is not read here but after the join
        "merge": ({"r", "y"}, set()),    # the phi's result is live from the top of its block
    }
    assert peak == 6


@pytest.mark.toolchain
def test_loop_liveness_reaches_a_fixpoint(tmp_path):
    live, peak = block_liveness(assemble("loop", tmp_path))
    assert live == {
        "entry": (set(), {"n", "k", "a0"}),   # a0 is read by the header's phi on the entry edge
        "header": ({"i", "acc", "n", "k"}, {"i", "acc", "n", "k"}),
        "body": ({"i", "acc", "n", "k"}, {"i", "acc1", "n", "k"}),
        "continue": ({"i", "acc1", "n", "k"}, {"i1", "acc1", "n", "k"}),  # phi operands on the back edge
        "exit": ({"acc", "k"}, set()),
    }
    assert peak == 9  # i 1 + n 1 + acc 2 + k 4 + cond 1 at the loop test


@pytest.mark.toolchain
def test_calls_count_the_callee_per_call_site(tmp_path):
    from generator.analysis import entry_cost
    c = entry_cost(assemble("call", tmp_path))
    assert (c.calls, c.alu, c.alu_scalar) == (2, 3, 3)  # two inlined-equivalent FMul + one FAdd
    assert c.registers == 3  # y and the first result live across the second call, plus its peak


@pytest.mark.toolchain
def test_big_endian_module_reads_the_same(tmp_path):
    from generator.analysis import entry_cost
    data = assemble("counts", tmp_path)
    words = struct.unpack(f"<{len(data) // 4}I", data)
    assert entry_cost(struct.pack(f">{len(words)}I", *words)) == entry_cost(data)


@pytest.mark.toolchain
def test_malformed_modules_are_errors(tmp_path):
    from generator.analysis import SpirvError, entry_cost
    data = assemble("branch", tmp_path)
    with pytest.raises(SpirvError, match="magic"):
        entry_cost(b"\0" * 40)
    with pytest.raises(SpirvError):
        entry_cost(data[:-6])  # not a whole number of words
    with pytest.raises(SpirvError, match="word count"):
        entry_cost(data + struct.pack("<I", (5 << 16) | 61))  # an OpLoad that claims 5 words, has 1
    with pytest.raises(SpirvError, match="no entry point 'other'"):
        entry_cost(data, "other")


def _dis_ops(spirv_dis: str, data: bytes, tmp_path: Path) -> list[tuple[str, str | None]]:
    path = tmp_path / "m.spv"
    path.write_bytes(data)
    text = subprocess.run([spirv_dis, "--raw-id", "--no-header", str(path)], check=True,
                          capture_output=True, text=True).stdout
    out = []
    for line in text.splitlines():
        toks = line.split()
        if not toks or toks[0].startswith(";"):
            continue
        has_result = len(toks) > 2 and toks[1] == "="
        op = toks[2] if has_result else toks[0]
        out.append((op, toks[5] if op == "OpExtInst" else None))
    return out


@pytest.mark.toolchain
def test_opcode_table_agrees_with_spirv_dis(tmp_path):
    """Every instruction of the fixtures and of real compiled shaders decodes to spirv-dis's name."""
    for t in COMPILERS:
        require_tool(t)
    spirv_dis = require_tool("spirv-dis")
    from generator.library.bricks import load_library
    from generator.compose import compose_eval
    from generator.analysis.spirv import GLSL_STD_450, OPCODES, instructions
    from generator.toolchain import CompileJob, compile_many
    lib = load_library()
    modules = [assemble(n, tmp_path) for n in ("counts", "branch", "loop", "call")]
    jobs = [CompileJob(f"e{i}.{s.language}", s.language, "comp", s.text)
            for i, spec in enumerate(["lambert+microfacet(ndf=beckmann,fresnel=schlick,vis=torrance_sparrow)",
                                      "phong_normalized"])
            for s in compose_eval(spec, lib).sources]
    modules += [r.spirv for r in compile_many(jobs).values()]
    for data in modules:
        mine = [("Op" + OPCODES.get(op, f"?{op}"), GLSL_STD_450.get(w[3]) if op == 12 else None)
                for op, w in instructions(data)]
        assert mine == _dis_ops(spirv_dis, data, tmp_path)


# ------------------------------------------------------------------ bricks

@pytest.fixture(scope="module")
def fixture_brick_rows():
    for t in COMPILERS:
        require_tool(t)
    from generator.measure.plans import brick_rows, load_cost_library
    return brick_rows(load_cost_library([COST_BRICKS]))


def _rows(rows, subject, table="brick"):
    found = {r.language: r for r in rows if r.subject == subject and r.table == table}
    assert set(found) == {"hlsl", "glsl", "wgsl"}, f"no {table} rows for {subject}"
    assert not any(r.error for r in found.values()), [r.error for r in found.values()]
    return found


@pytest.mark.toolchain
def test_brick_of_known_cost_five_multiplications(fixture_brick_rows):
    for lang, r in _rows(fixture_brick_rows, "five_muls").items():
        c = r.cost
        assert (c.alu_scalar, c.transcendental, c.texture, c.branches, c.loads) == (15, 0, 0, 0, 1), lang
        # spirv-opt -O contracts the last multiply and the BRDF's sum (diffuse + specular) into one
        # Fma (2 scalar operations), which replaces the baseline's add: 4 instructions, 15 operations.
        assert (c.alu, c.opcodes.get("Fma"), c.opcodes.get("OpFMul"), c.opcodes.get("OpFAdd")) == (4, 1, 4, -1), lang
        assert (r.measured, r.baseline) == ("five_muls+standin_specular", "standin_diffuse+standin_specular")


@pytest.mark.toolchain
def test_brick_of_known_cost_two_exponentials(fixture_brick_rows):
    for lang, r in _rows(fixture_brick_rows, "two_exps").items():
        c = r.cost
        assert (c.transcendental, c.transcendental_scalar, c.alu, c.alu_scalar) == (2, 2, 3, 5), lang
        assert (c.texture, c.branches, c.loads) == (0, 0, 2), lang  # its parameters f0 and k


@pytest.mark.toolchain
def test_every_brick_and_slot_filler_has_a_row_and_no_stand_in_does(fixture_brick_rows):
    from generator.library.bricks import load_library
    subjects = {r.subject for r in fixture_brick_rows if r.table == "brick"}
    assert not any("standin" in s.split("=")[-1].split("(")[0] for s in subjects)
    for (kind, bid), b in load_library().bricks.items():
        if kind in ("ndf", "fresnel", "visibility"):
            assert any(s.endswith(f"={bid}") for s in subjects), bid
        elif b.slots and kind in ("diffuse", "specular"):
            assert any(s.startswith(f"{bid}(") for s in subjects), bid  # named with its default fillers
        else:  # a brick with an array parameter is named with its count: lafortune(lobes=4,K=4)
            assert bid in subjects or any(s.startswith(f"{bid}(") for s in subjects), bid
    shadow = _rows(fixture_brick_rows, "shadow_map")
    assert all(r.cost.texture == 1 and r.stage == "frag" for r in shadow.values())


@pytest.mark.toolchain
def test_course_models_are_data_and_a_new_brick_adds_its_row(fixture_brick_rows):
    for model, tables in {"Blinn-Phong": {("shift-invariant", 0, "7"), ("shift-variant", 1, "15")},
                          "Cook-Torrance": {("shift-invariant", 0, "35"), ("shift-variant", 1, "40")},
                          "Banks": {("shift-invariant", 0, "12"), ("shift-variant", 1, "25")}}.items():
        rows = [r for r in fixture_brick_rows if r.table == "model" and r.subject == model
                and r.course.form == "direct"]
        assert {(r.course.table, r.course.texture, r.course.alu) for r in rows} == tables
        variant = [r for r in rows if r.course.table == "shift-variant"]
        assert all(r.cost.texture == 1 for r in variant)  # the albedo texture
    from generator.measure.plans import course_models
    assert "Ashikhmin-Shirley" in {m.name for m in course_models()[0]}
    # every model has its bricks: the direct forms and the factored ones
    for model in ("Ashikhmin-Shirley", "Lafortune"):
        rows = [r for r in fixture_brick_rows if r.table == "model" and r.subject == model]
        assert {r.course.table for r in rows} == {"shift-invariant", "shift-variant"} and not any(r.error for r in rows)
    factored = {(r.subject, r.course.table): r for r in fixture_brick_rows if r.course and r.course.form == "factored"}
    assert {m for m, _ in factored} == {"Blinn-Phong", "Banks", "Ashikhmin-Shirley"}
    # the course's texture counts hold for the invariant forms: the tables each reads
    assert [factored[(m, "shift-invariant")].cost.texture for m in ("Blinn-Phong", "Banks", "Ashikhmin-Shirley")] \
        == [1, 1, 4]


# ------------------------------------------------------------------ CLI, scene, manifest

def cli(*args):
    return subprocess.run([sys.executable, "-m", "generator.cli", "costs", *map(str, args)],
                          cwd=REPO, capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def scene_json():
    for t in COMPILERS:
        require_tool(t)
    r = cli(EXAMPLE, "--format", "json")
    assert r.returncode == 0, r.stderr
    return r.stdout


@pytest.mark.toolchain
def test_scene_costs_json_rows_and_stability(scene_json):
    doc = json.loads(scene_json)
    rows = doc["rows"]
    assert len(rows) == (5 + 1) * 2 * 3  # (permutations + the ubershader) x stages x languages
    assert sum(r["table"] == "ubershader" for r in rows) == 2 * 3
    for r in rows:
        for key in ("subject", "language", "alu", "transcendental", "texture", "branches", "registers",
                    "instructions", "loads", "stores", "alu_scalar"):
            assert r[key] is not None, key
    course = {(r["subject"], r["course_model"], r["course_table"]) for r in rows if r["course_model"]}
    rows = [r for r in rows if r["table"] == "permutation"]
    ids = {r["subject"]: r["key"] for r in rows}
    for subject, model, table in course:
        assert model in ("Blinn-Phong", "Cook-Torrance")
        assert (table == "shift-variant") == ("albedo_texture" in ids[subject])
    assert len(course) == 2
    assert doc["differences"] and all(d["why"] for d in doc["differences"])
    again = cli(EXAMPLE, "--format", "json")
    assert again.stdout == scene_json  # costs of the example scene are identical across runs


@pytest.mark.toolchain
def test_scene_costs_markdown_and_csv(scene_json):
    md = cli(EXAMPLE)
    assert md.returncode == 0, md.stderr
    assert "| permutation | materials | objects | stage | tex | ALU |" in md.stdout
    assert "## Where the languages differ" not in md.stdout and "course tex" not in md.stdout
    more = cli(EXAMPLE, "--course", "--explain-languages")
    assert "## Where the languages differ" in more.stdout and "| course tex / ALU |" in more.stdout
    csv_out = cli(EXAMPLE, "--format", "csv")
    assert csv_out.returncode == 0
    lines = csv_out.stdout.splitlines()
    assert lines[0].startswith("table,subject,kind,stage,language,instructions,alu,transcendental,texture")
    assert len(lines) == 1 + 36


@pytest.mark.toolchain
def test_manifest_carries_the_same_costs(scene_json, tmp_path):
    from generator.library.bricks import load_library
    from generator.assemble import BuildContext, build
    from generator.analysis import entry_cost
    from generator.scene.load import load_scene
    lib = load_library()
    res = build(load_scene(EXAMPLE, lib), tmp_path, BuildContext(lib))
    assert res.ok
    by_key = {(r["subject"], r["stage"], r["language"]): r for r in json.loads(scene_json)["rows"]}
    for p in res.manifest["permutations"]:
        for lang, stages in p["languages"].items():
            for stage, item in stages.items():
                cost = item["cost"]
                assert cost == entry_cost((tmp_path / item["spirv"]).read_bytes()).as_dict(histograms=False)
                row = by_key[(p["hash"], stage, lang)]
                assert {k: row[k] for k in cost} == cost


@pytest.mark.toolchain
def test_bricks_table_markdown_shows_course_figures():
    for t in COMPILERS:
        require_tool(t)
    assert "## The course's models" not in cli("--per-brick").stdout  # behind --course
    r = cli("--per-brick", "--course")
    assert r.returncode == 0, r.stderr
    assert re.search(r"\| Blinn-Phong \| direct \| shift-invariant \| `lambert\+blinn_phong_normalized` \| 0 \| 7 \|",
                     r.stdout)
    m = re.search(r"\| Banks \| factored \| shift-invariant \| `lambert\+banks_factored` \| 1 \| 5 \| 1 \|.*\| "
                  r"([0-9.e+-]+) \|\n", r.stdout)  # measured, with its error against the direct Banks
    assert m and 0 < float(m.group(1)) < 0.06, r.stdout
    assert "| Lafortune | direct | shift-invariant | `lambert+lafortune` | 0 | 10 + 5n |" in r.stdout
    assert "standin" not in r.stdout.split("## The course's models")[0].split("## Per brick")[1]


def test_cli_usage_errors(tmp_path):
    assert cli().returncode == 2
    assert cli(EXAMPLE, "--per-brick").returncode == 2
    assert cli(EXAMPLE, "--brick-dir", tmp_path).returncode == 2  # one spelling: --bricks DIR
    assert cli(EXAMPLE, "--format", "xml").returncode == 2
    missing = cli(tmp_path / "nope.toml")
    assert missing.returncode == 1 and "nope.toml" in missing.stderr
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "broken.py").write_text('"""Broken."""\nBRICK = {"kind": "nonsense", "cite": "x"}\n')
    r = cli("--per-brick", "--bricks", bad)
    assert r.returncode == 1 and "broken.py" in r.stderr


def test_stand_ins_stay_out_of_the_brick_list_and_scenes():
    from generator.library.bricks import load_library
    assert not any(bid.startswith("standin") for _, bid in load_library().bricks)
    out = subprocess.run([sys.executable, "-m", "generator.cli", "bricks", "--json"], cwd=REPO,
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and "standin" not in out.stdout
