"""The platform table (generator/assemble/platforms.py): each platform one entry declaring what it is made from,
its dialects, tools and conventions, and the build's loop asking nothing else of it.

A platform added as one entry is parsed from --platform, composed for, written, keyed by its tools and tracked
in the output state with no other change; GLSL ES is "unsupported" where its validation failed; and the Vulkan
conventions are those the runtime renders with.
"""
from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
VALUES = {"depth_range": {"0..1", "-1..1"}, "ndc_y": {"up", "down"},
          "framebuffer_origin": {"top-left", "bottom-left"}, "front_face": {"ccw", "cw"}}


@pytest.fixture(scope="module")
def composed():
    """(hash, Composed) of the example's first permutation in every language and the gl platform's dialects."""
    from generator.backends import LANGUAGES
    from generator.compose import compose_permutation
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    scene = load_scene(EXAMPLE, lib)
    h = sorted(scene.permutations)[0]
    return h, compose_permutation(scene.permutations[h], lib, LANGUAGES, ("gl", "essl"))


def test_every_platform_declares_what_it_is_made_from_and_its_conventions():
    from generator.backends import DIALECTS, LANGUAGES
    from generator.assemble.platform_base import Conventions, Platform
    from generator.assemble.platforms import EXT, PLATFORM_TABLE, PLATFORMS
    assert PLATFORMS == ("vulkan", "d3d12", "gl", "webgpu")
    for name, p in PLATFORM_TABLE.items():
        assert isinstance(p, Platform) and p.name == name
        assert p.made_from in LANGUAGES and p.language in (*LANGUAGES, *DIALECTS), name
        assert set(p.dialects) <= set(DIALECTS), name
        assert p.tools and set(p.tools) <= {"glslc", "glslang", "spirv-tools", "naga", "dxc"}, name
        assert isinstance(p.conventions, Conventions)
        for f in fields(Conventions):
            assert getattr(p.conventions, f.name) in VALUES[f.name], (name, f.name)
        assert p.own_files == bool(p.ext), name  # a platform writing its own tree names its files' extensions
    assert set(EXT) == {"hlsl", "dxil", "gl", "essl", "wgsl"}
    # the APIs' own rules: OpenGL's depth range and window origin, Vulkan's y
    assert {n: (p.conventions.depth_range, p.conventions.ndc_y) for n, p in PLATFORM_TABLE.items()} == {
        "vulkan": ("0..1", "down"), "d3d12": ("0..1", "up"), "gl": ("-1..1", "up"), "webgpu": ("0..1", "up")}


def test_the_vulkan_conventions_are_those_the_runtime_renders_with():
    import numpy as np

    from generator.assemble.platforms import PLATFORM_TABLE
    from generator.runtime.camera import perspective
    c = PLATFORM_TABLE["vulkan"].conventions
    m = perspective(60.0, 1.0, 0.5, 10.0)
    near, far, up = (m @ np.array(v) for v in ([0, 0, -0.5, 1], [0, 0, -10.0, 1], [0, 1, -2.0, 1]))
    assert (near[2] / near[3], far[2] / far[3]) == pytest.approx((0.0, 1.0)) and c.depth_range == "0..1"
    assert up[1] / up[3] < 0 and c.ndc_y == "down"  # world up is image up: NDC +y points down
    graphics = (REPO / "generator" / "runtime" / "graphics.py").read_text()
    assert "frontFace=vk.VK_FRONT_FACE_COUNTER_CLOCKWISE" in graphics and c.front_face == "ccw"


@pytest.mark.toolchain
def test_a_platform_added_as_one_entry_is_parsed_composed_written_keyed_and_tracked(composed, tmp_path, monkeypatch):
    from generator.assemble import platforms as P
    from generator.assemble.platform_base import Conventions, Platform
    from generator.io import atomic_write
    from generator.toolchain import tool_versions

    class EsOnly(Platform):  # GLSL ES alone, in a tree of its own
        name, made_from, language, blob = "gles", "glsl", "essl", "essl"
        dialects, tools, ext = ("essl",), ("glslang",), {"essl": "essl"}
        conventions = Conventions(depth_range="-1..1", ndc_y="up", framebuffer_origin="bottom-left", front_face="ccw")

        def section(self, unit):
            return {"stages": {s: {"essl": self.put(unit, s, unit.text("essl", s), "essl")} for s in unit.stages}}

        def reflection(self, iface):
            return {"vertex_inputs": [v.name for v in iface.vertex_inputs]}

    monkeypatch.setitem(P.PLATFORM_TABLE, "gles", EsOnly())
    assert P.parse_platforms("gles,webgpu") == ["webgpu", "gles"]
    assert P.dialects_of(["gles"]) == ("essl",)
    assert P.all_tools(["gles"]) == {"gles": {"glslang": tool_versions()["glslang"]}}
    h, c = composed
    entry = {"languages": {"glsl": {}}}
    errs = P.write_platforms(lambda rel, data: atomic_write(tmp_path / rel, data), h, c, entry, ["gles"], {}, "fp32")
    assert errs == []
    section = entry["platforms"]["gles"]
    assert list(section) == ["stages", "reflection", "tools"]
    assert section["reflection"] == {"vertex_inputs": [v.name for v in c.interface.vertex_inputs]}
    essl = {s.stage: s.text for s in c.dialects if s.language == "essl"}
    assert set(section["stages"]) == set(essl) == {"vert", "frag"}
    for stage, item in section["stages"].items():
        path = item["essl"]["path"]
        assert path.startswith(f"gles/{h}.{stage}.") and path.endswith(".essl")
        assert (tmp_path / path).read_text() == essl[stage]
    assert sorted(P.platform_files(entry)) == sorted((i["essl"]["path"], i["essl"]["sha256"])
                                                     for i in section["stages"].values())
    # made from a language this build did not build: not written
    skipped = {"languages": {"wgsl": {}}}
    P.write_platforms(lambda rel, data: None, h, c, skipped, ["gles"], {}, "fp32")
    assert skipped["platforms"] == {}


@pytest.mark.toolchain
def test_gl_ships_the_core_text_and_marks_es_unsupported_where_es_failed(composed, tmp_path):
    from generator.assemble.platforms import write_platforms
    from generator.io import atomic_write
    h, c = composed
    es_error = f"bricks/x.py:3:1: error: no ES [glslang] ({h})"
    entry = {"languages": {"glsl": {}}}
    errs = write_platforms(lambda rel, data: atomic_write(tmp_path / rel, data), h, c, entry, ["gl"],
                           {f"{h}.frag.essl": [es_error]}, "fp32")
    assert errs == [] and "failed_sources" not in entry  # ES is where the bricks allow: the permutation builds
    gl = entry["platforms"]["gl"]
    assert gl["essl"] == {"unsupported": [es_error]}
    assert {stage: sorted(item) for stage, item in gl["stages"].items()} == {"vert": ["glsl"], "frag": ["glsl"]}
    assert not list((tmp_path / "gl").glob("*.essl"))
    assert list(gl) == ["stages", "versions", "essl", "reflection", "tools"]
