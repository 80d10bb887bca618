"""Cost analysis: hand-assembled SPIR-V with known answers.

Fixtures in tests/fixtures/spirv/*.spvasm are assembled with the real
`spirv-as` (and validated with `spirv-val`); their comments state the
answers asserted here.
"""
from __future__ import annotations

import struct
import subprocess
from pathlib import Path

import pytest

from tests.conftest import require_tool

REPO = Path(__file__).resolve().parent.parent
FIXTURES = REPO / "tests" / "fixtures" / "spirv"
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
    from generator.cost import read
    from generator.cost.liveness import analyze_function
    mod = read(data)
    fn = mod.functions[mod.entry_points["main"][1]]
    lv = analyze_function(mod, fn)
    live = {mod.name(b.label): (names(mod, lv.live_in[b.label]), names(mod, lv.live_out[b.label]))
            for b in fn.blocks}
    return live, lv.peak


# ------------------------------------------------------------------ SPIR-V fixtures

def test_counts_fixture_classes_and_scalar_rules(tmp_path):
    from generator.cost import entry_cost
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


def test_branch_liveness_carries_a_value_through_both_arms(tmp_path):
    live, peak = block_liveness(assemble("branch", tmp_path))
    assert live == {
        "entry": (set(), {"x", "y"}),
        "then": ({"x", "y"}, {"t", "y"}),
        "else": ({"y"}, {"e", "y"}),     # y is not read here but after the join
        "merge": ({"r", "y"}, set()),    # the phi's result is live from the top of its block
    }
    assert peak == 6


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


def test_calls_count_the_callee_per_call_site(tmp_path):
    from generator.cost import entry_cost
    c = entry_cost(assemble("call", tmp_path))
    assert (c.calls, c.alu, c.alu_scalar) == (2, 3, 3)  # two inlined-equivalent FMul + one FAdd
    assert c.registers == 3  # y and the first result live across the second call, plus its peak


def test_big_endian_module_reads_the_same(tmp_path):
    from generator.cost import entry_cost
    data = assemble("counts", tmp_path)
    words = struct.unpack(f"<{len(data) // 4}I", data)
    assert entry_cost(struct.pack(f">{len(words)}I", *words)) == entry_cost(data)


def test_malformed_modules_are_errors(tmp_path):
    from generator.cost import SpirvError, entry_cost
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


def test_opcode_table_agrees_with_spirv_dis(tmp_path):
    """Every instruction of the fixtures and of real compiled shaders decodes to spirv-dis's name."""
    for t in COMPILERS:
        require_tool(t)
    spirv_dis = require_tool("spirv-dis")
    from generator.bricks import load_library
    from generator.compose import compose_eval
    from generator.cost.spirv import GLSL_STD_450, OPCODES, instructions
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
