"""The manifest's conventions (top-level ``conventions``, per permutation ``output``) are the platform classes'
declarations and true of the generated shaders.

- Each platform written is stated once, from its class; the Object block's binding is where every
  permutation's reflection puts it (gl: null there, since its block numbers depend on the blocks a program
  has: each reflection holds its own); what the block holds is what the renderer writes (runtime/camera.py object_bytes) and
  what the sources and their SPIR-V reflection declare.
- Every permutation names its output brick, what it encodes and the attachment for it.
- GL: no vertex stage of the gl or essl dialect remaps gl_Position (depth range -1..1 without glClipControl,
  NDC +y up): each writes frame.view_proj × world once, as the Vulkan GLSL does, whose conventions the
  renderer's lavapipe tests check (tests/runtime/test_render_state.py).
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"


@pytest.fixture(scope="module")
def example(tmp_path_factory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("conventions") / "out"
    r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(EXAMPLE), "--out", str(out), "-q"],
                       cwd=REPO, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    return out, json.loads((out / "manifest.json").read_text())


@pytest.mark.toolchain
def test_every_platform_written_states_its_conventions_from_its_class(example):
    from generator.assemble.platforms import PLATFORM_TABLE
    from generator.link.interface import FRAME_BLOCK
    from generator.runtime.pipeline_state import frame_block, object_block
    _, m = example
    conv = m["conventions"]
    assert list(conv["platforms"]) == m["platforms"] == list(PLATFORM_TABLE)
    assert conv["object_block"] == object_block() and conv["frame_block"] == frame_block()
    assert [(x["name"], x["offset"], x["size"]) for x in conv["frame_block"]["members"]] == \
        [(x["name"], x["offset"], x["size"]) for x in FRAME_BLOCK]  # what every permutation's Frame declares
    for name, p in PLATFORM_TABLE.items():
        c = conv["platforms"][name]
        assert c == p.conventions_section()
        assert c["clip"] == {"depth_range": p.conventions.depth_range, "ndc_y": p.conventions.ndc_y,
                             "framebuffer_origin": p.conventions.framebuffer_origin}
        assert c["front_face"]["winding"] == p.conventions.front_face == "ccw"
    assert conv["platforms"]["d3d12"]["front_face"]["state"] == {"FrontCounterClockwise": True}  # not D3D12's default
    assert conv["platforms"]["gl"]["clip"]["depth_range"] == "-1..1" and "glClipControl" in \
        conv["platforms"]["gl"]["state"]["depth_range_0_1"]
    # the same depth pass matrix convention the lights' depth passes premultiply by
    for light in m["lights"].values():
        for name, pre in light.get("depth_pass", {}).get("matrix", {}).get("premultiply", {}).items():
            gl_like = conv["platforms"][name]["clip"]["depth_range"] == "-1..1"
            assert (pre[2] == [0.0, 0.0, 2.0, -1.0]) == gl_like, name


@pytest.mark.toolchain
def test_the_object_block_binds_where_every_reflection_puts_it(example):
    from generator.backends.gl.emit import gl_bindings
    from generator.link.interface import Block
    _, m = example
    conv = m["conventions"]["platforms"]
    gl_numbers = set()
    for e in m["permutations"]:
        refl = {p: d["reflection"] for p, d in e["platforms"].items()}
        vk = next(d for d in refl["vulkan"]["descriptors"] if d["name"] == "Object")
        assert {"set": vk["set"], "binding": vk["binding"]} == conv["vulkan"]["object_block"]
        dx = next(r for r in refl["d3d12"]["resources"] if r["name"] == "Object")
        assert {"register": dx["register"], "space": dx["space"]} == conv["d3d12"]["object_block"]
        wg = next(g for g in refl["webgpu"]["bind_groups"] if g["name"] == "Object")
        assert {"group": wg["group"], "binding": wg["binding"]} == conv["webgpu"]["object_block"]
        gl = next(b for b in refl["gl"]["uniform_blocks"] if b["name"] == "Object")
        blocks = [Block(b["name"], b["set"], b["binding"], "uniform", []) for b in e["interface"]["frag"]
                  ["uniform_blocks"] + e["interface"]["vert"]["uniform_blocks"]]
        unique = {(b.set, b.binding): b for b in blocks}.values()
        assert gl["binding"] == gl_bindings(unique, [])["uniform"][(vk["set"], vk["binding"])]
        gl_numbers.add(gl["binding"])
    assert conv["gl"]["object_block"] == {"binding": None} and gl_numbers == {3}  # Frame, Lights, Material first
    # why gl states none: a program without a Lights block (a light set with no lights) numbers Object 2
    unlit = [Block(n, s_, b_, "uniform", []) for n, s_, b_ in (("Frame", 0, 0), ("Material", 1, 0), ("Object", 2, 0))]
    assert gl_bindings(unlit, [])["uniform"][(2, 0)] == 2


@pytest.mark.toolchain
def test_the_object_block_holds_what_the_renderer_writes_and_the_shaders_read(example):
    """Decoded as the manifest says (std140, column-major mat4s at their offsets), the renderer's bytes are the
    model matrix and its inverse transpose; the sources and their SPIR-V reflection declare the same members."""
    from generator.runtime.camera import object_bytes
    _, m = example
    ob = m["conventions"]["object_block"]
    assert (ob["name"], ob["layout"], ob["matrices"], ob["size"]) == ("Object", "std140", "column_major", 128)
    rng = np.random.default_rng(7)
    model = np.eye(4)
    model[:3, :3] = rng.normal(size=(3, 3)) @ np.diag([0.5, 2.0, 3.0])  # rotation, shear, non-uniform scale
    model[:3, 3] = [1.0, -2.0, 3.0]
    raw = np.frombuffer(object_bytes(model), "<f4")
    assert raw.nbytes == ob["size"]
    got = {mb["name"]: raw[mb["offset"] // 4:(mb["offset"] + mb["size"]) // 4].reshape(4, 4).T for mb in ob["members"]}
    assert np.allclose(got["model"], model, atol=1e-6)
    n = got["normal_matrix"]
    assert np.allclose(n[:3, :3], np.linalg.inv(model[:3, :3]).T, atol=1e-5)
    assert np.allclose(n[3], [0, 0, 0, 1]) and np.allclose(n[:, 3], [0, 0, 0, 1])
    for e in m["permutations"]:  # the SPIR-V reflection's Object block (checked against the module by the build)
        block = next(b for b in e["interface"]["vert"]["uniform_blocks"] if b["name"] == "Object")
        assert [(x["name"], x["type"], x["offset"], x["size"]) for x in block["members"]] == \
            [(x["name"], x["type"], x["offset"], x["size"]) for x in ob["members"]]


@pytest.mark.toolchain
def test_every_permutation_names_its_output_and_the_attachment_for_it(example):
    from generator.library.bricks import load_library
    _, m = example
    lib = load_library()
    for e in m["permutations"]:
        brick = re.search(r"output=(\w+)", e["id"])[1]
        assert e["output"] == {"brick": brick, "encodes": lib.get("output", brick).encodes,
                               "attachment": "srgb" if lib.get("output", brick).encodes == "linear" else "unorm"}
    assert {e["output"]["attachment"] for e in m["permutations"]} == {"srgb"}  # the example's output is linear
    for c in m["conventions"]["platforms"].values():
        assert set(c["attachments"]["color"]) == {"srgb", "unorm"}


def test_the_output_bricks_declare_what_they_encode_and_only_they_may():
    from generator.lang import SourceError
    from generator.library.bricks import load_brick, load_library
    lib = load_library()
    assert {b.id: b.encodes for b in lib.of_kind("output")} == {"linear": "linear", "srgb": "srgb", "sqrt_gamma": "sqrt"}
    bad = REPO / "bricks" / "light" / "point.py"
    text = bad.read_text().replace('BRICK = {', 'BRICK = {\n    "encodes": "srgb",', 1)
    with pytest.raises(SourceError, match=r"'encodes' is declared by a light brick") as e:
        load_brick(bad, text=text)
    assert e.value.line == text.splitlines().index('    "encodes": "srgb",') + 1


@pytest.mark.toolchain
def test_no_vertex_stage_remaps_the_position_on_any_platform(example):
    """The conventions hold because the shaders pass clip space through: each vertex source writes its position
    once, frame.view_proj × world (world = Object.model × (position, 1)), in the gl and essl dialects (no z
    remap to -1..1, no y flip: an OpenGL engine's projection or glClipControl does it) and in GLSL, HLSL and
    WGSL alike."""
    out, m = example
    writes = {"glsl": r"gl_Position\s*(\.\w+)?\s*=", "gl": r"gl_Position\s*(\.\w+)?\s*=",
              "essl": r"gl_Position\s*(\.\w+)?\s*=", "hlsl": r"\bo\.position\s*(\.\w+)?\s*=",
              "wgsl": r"\bo\.position\s*(\.\w+)?\s*="}
    whole = {"glsl": "gl_Position = frame.view_proj * world;", "gl": "gl_Position = frame.view_proj * world;",
             "essl": "gl_Position = frame.view_proj * world;", "hlsl": "o.position = mul(view_proj, world);",
             "wgsl": "o.position = frame.view_proj * world;"}
    model = {"glsl": "object_data.model * vec4(a_position, 1.0)", "gl": "object_data.model * vec4(a_position, 1.0)",
             "essl": "object_data.model * vec4(a_position, 1.0)", "hlsl": "mul(model, float4(i.a_position, 1.0))",
             "wgsl": "object_data.model * vec4<f32>(a_position, 1.0)"}
    seen = set()
    for e in m["permutations"]:
        paths = {lang: e["languages"][lang]["vert"]["source"] for lang in ("glsl", "hlsl", "wgsl")}
        gl = e["platforms"]["gl"]["stages"]["vert"]
        paths.update({"gl": gl["glsl"]["path"], "essl": gl["essl"]["path"]})
        for lang, rel in paths.items():
            text = (out / rel).read_text()
            assert len(re.findall(writes[lang], text)) == 1 and whole[lang] in text, (lang, rel)
            assert model[lang] in text and "gl_ClipControl" not in text, (lang, rel)
            seen.add(lang)
    assert seen == set(writes)
