"""`costs --budget`'s grammar: a family prefix holds until the next one, bare names before any are SPIR-V counts,
and every bad item is one usage error naming the closest valid name."""
from __future__ import annotations

import pytest

from generator.lang.errors import UsageError
from generator.measure.budget import Limit, families, parse, radv_value


def test_a_family_prefix_holds_until_the_next_one_and_bare_names_before_any_are_spirv_counts():
    got = parse("alu=60,texture=4,navi21.vgprs=32,spills=0,polaris10.vgprs=64,waves_per_simd=4,spirv.registers=40")
    assert got == (Limit(None, "alu", 60), Limit(None, "texture", 4), Limit("navi21", "vgprs", 32),
                   Limit("navi21", "spills", 0), Limit("polaris10", "vgprs", 64),
                   Limit("polaris10", "waves_per_simd", 4), Limit(None, "registers", 40))
    assert families(got) == ("navi21", "polaris10")
    # `instructions` is both: the scope says which
    assert parse("instructions=300,navi21.instructions=200") == (Limit(None, "instructions", 300),
                                                                  Limit("navi21", "instructions", 200))
    assert parse("gfx1030.vgprs=32") == (Limit("navi21", "vgprs", 32),)  # a gfx IP name is its family
    # the same statistic for two families is two limits; twice in one scope is an error (below)
    assert len(parse("navi21.vgprs=32,navi31.vgprs=32")) == 2


def test_a_floor_for_occupancy_and_a_ceiling_for_everything_else():
    waves, vgprs, alu = parse("navi21.waves_per_simd=8,vgprs=32,spirv.alu=60")
    assert waves.at_least and waves.breaks(4) and not waves.breaks(8) and waves.text() == "navi21 waves_per_simd ≥ 8"
    assert not vgprs.at_least and vgprs.breaks(40) and not vgprs.breaks(32) and vgprs.text() == "navi21 vgprs ≤ 32"
    assert alu.text() == "alu ≤ 60"
    stats = {"Spilled VGPRs": 3, "Spilled SGPRs": 2, "VGPRs": 40}
    assert radv_value(stats, "spills") == 5 and radv_value(stats, "vgprs") == 40
    assert radv_value(stats, "latency") is None and radv_value(None, "vgprs") is None


@pytest.mark.parametrize("text, says", [
    ("navi21.vgprz=32", "did you mean 'vgprs'?"),
    ("navi2.vgprs=32", "did you mean 'navi21'?"),
    ("alu=60,navi21.vgprs=32,alu=60", "write spirv.alu=60"),  # the prefix still holds for the bare `alu`
    ("vgprs=32", "needs a family — write navi21.vgprs=32"),
    ("texure=4", "did you mean 'texture'?"),
    ("navi21.vgprs=lots", "N a whole number"),
    ("navi21.vgprs", "not [FAMILY.]NAME=N"),
    ("navi21.vgprs=32,vgprs=40", "navi21 vgprs is limited twice"),
    ("alu=60,spirv.alu=50", "alu is limited twice"),
])
def test_a_bad_item_is_one_usage_error_with_the_closest_name(text, says):
    with pytest.raises(UsageError) as e:
        parse(text)
    assert says in str(e.value) and "\n" not in str(e.value), str(e.value)
