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


BUILD_CODE = ("generator/assemble/checks.py", "generator/assemble/write.py", "generator/assemble/samplers.py",
              "generator/assemble/pack.py", "generator/assemble/outputs.py", "generator/cli/commands/check.py",
              "generator/cli/pytest_plugin.py")


def test_the_build_code_names_no_platform_but_through_the_table():
    """Adding a platform is adding its class: the build's code outside platforms.py reads the classes'
    declarations (checked_from, dialects, binary_step, spell_sampler, ubershader, LANGUAGE_TREE), and no code
    there compares with a platform's or a dialect's name (docstrings and help texts may name them)."""
    import ast

    from generator.assemble.platforms import PLATFORM_TABLE
    names = {*PLATFORM_TABLE, *(d for p in PLATFORM_TABLE.values() for d in p.dialects)}
    found = []
    for rel in BUILD_CODE:
        tree = ast.parse((REPO / rel).read_text(encoding="utf-8"))
        docs = {id(n.body[0].value) for n in ast.walk(tree)
                if isinstance(n, (ast.Module, ast.FunctionDef, ast.ClassDef)) and n.body
                and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
        helps = {id(k.value) for n in ast.walk(tree) if isinstance(n, ast.Call) for k in n.keywords if k.arg == "help"}
        for n in ast.walk(tree):
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs | helps:
                if n.value in names or any(n.value.startswith(f"{x}/") for x in names):
                    found.append(f"{rel}:{n.lineno}: {n.value!r}")
            if isinstance(n, ast.JoinedStr) and n.values and isinstance(n.values[0], ast.Constant) \
                    and any(str(n.values[0].value).startswith(f"{x}/") for x in names):
                found.append(f"{rel}:{n.lineno}: f{n.values[0].value!r}…")
    assert found == []


def test_a_dialect_platform_checks_its_optional_dialect_as_a_note_and_spells_samplers_by_its_class(composed):
    """The generic check of a platform with dialects (assemble/checks.py): a required dialect's errors fail
    it, an optional one's are a note naming it by its class's title and its source is not listed; a sampler
    state is spelled by the class's spell_sampler, for every platform the table holds."""
    from generator.assemble import platforms as P
    from generator.assemble.checks import Check, _dialects
    from generator.assemble.samplers import spell
    from generator.toolchain.jobs import job_key
    h, c = composed
    gl = P.PLATFORM_TABLE["gl"]
    check = Check(h, "gl", ())
    ok = {job_key(h, s.stage, s.language): [] for s in c.dialects}
    sources, notes = {}, []
    assert _dialects(check, gl, c.dialects, ok, sources, notes) == [] and notes == []
    assert sorted(sources) == sorted(f"gl/{h}.{s.stage}.{P.EXT[s.language]}" for s in c.dialects)
    es = {**ok, job_key(h, "frag", "essl"): ["x.py:1:1: no ES"], job_key(h, "vert", "gl"): ["y.py:2:1: no core"]}
    sources, notes = {}, []
    assert _dialects(check, gl, c.dialects, es, sources, notes) == ["y.py:2:1: no core"]
    assert notes == ["GLSL ES 3.10 unsupported (the build ships GLSL 4.50 core only): x.py:1:1: no ES"]
    assert sorted(sources) == sorted(f"gl/{h}.{s.stage}.glsl" for s in c.dialects if s.language == "gl")
    state = {"mag_filter": "linear", "min_filter": "nearest", "mipmap": "none", "wrap_u": "repeat",
             "wrap_v": "clamp", "anisotropy": 1, "lod_bias": 0.0, "compare": None}
    spelled = spell(state)
    assert list(spelled) == list(P.PLATFORM_TABLE)
    assert spelled == {n: p.spell_sampler(state) for n, p in P.PLATFORM_TABLE.items()}
    assert spelled["vulkan"]["addressModeV"] == "VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE"
    assert spelled["gl"]["GL_TEXTURE_MIN_FILTER"] == "GL_NEAREST" and spelled["webgpu"]["lodMaxClamp"] == 0.25
