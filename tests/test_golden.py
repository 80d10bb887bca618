"""Emitted sources equal the checked-in goldens; the goldens compile to the recorded SPIR-V sizes."""
import json

import pytest

from tests.conftest import require_tool
from tests.regen_goldens import GOLDEN, golden_sources, spirv_summary

HINT = "run `make goldens` and review `git diff tests/golden`"


@pytest.fixture(scope="module")
def sources():
    return golden_sources()


@pytest.mark.golden
def test_every_golden_is_current(sources):
    on_disk = {str(p.relative_to(GOLDEN)) for p in GOLDEN.glob("*/**/*.*") if p.is_file()}
    assert on_disk == set(sources), f"golden files added or removed — {HINT}"
    for rel, (_, _, text) in sources.items():
        assert (GOLDEN / rel).read_text() == text, f"{rel} drifted — {HINT}"


@pytest.mark.golden
def test_goldens_cover_every_language_and_stage(sources):
    seen = {(lang, stage) for lang, stage, _ in sources.values()}
    assert seen == {(lang, s) for lang in ("glsl", "hlsl", "wgsl") for s in ("vert", "frag", "comp")}


@pytest.mark.golden
@pytest.mark.toolchain
def test_goldens_compile_to_the_recorded_spirv_sizes(sources):
    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    recorded = json.loads((GOLDEN / "spirv.json").read_text())
    now = spirv_summary(sources)
    assert now["tools"] == recorded["tools"], f"tool versions changed — {HINT}"
    assert now["spirv_words"] == recorded["spirv_words"], f"optimized SPIR-V sizes changed — {HINT}"
