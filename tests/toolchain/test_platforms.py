"""`build --platform`: one tree per platform, and reflection in each platform's binding model.

The example scene and a glTF scene (written here) build for all four platforms; each platform's
reflection in the manifest is checked against the artifacts themselves: read back from the SPIR-V for
vulkan, parsed from the HLSL text (`register(xN, spaceM)`) for d3d12, from the GLSL text
(`layout(binding = N)`) for gl, from the WGSL text (`@group(G) @binding(B)`) for webgpu.
"""
from __future__ import annotations

import hashlib
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
PLATFORMS = ["vulkan", "d3d12", "gl", "webgpu"]

pytestmark = pytest.mark.toolchain


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _build(lib, scene_path, out) -> dict:
    from generator.assemble import BuildContext, build
    from generator.scene.load import load_scene
    res = build(load_scene(scene_path, lib), out, BuildContext(lib))
    assert res.ok, res.failures
    return json.loads((out / "manifest.json").read_text())


@pytest.fixture(scope="module", params=["example", "gltf"])
def built(request, lib, tmp_path_factory):
    """(out, manifest) of a build for every platform: the example scene, and the sample glTF scene."""
    tmp = tmp_path_factory.mktemp(request.param)
    if request.param == "example":
        scene = EXAMPLE
    else:
        from tests.scene.test_gltf import sample_doc
        scene = sample_doc().write_gltf(tmp / "model.gltf")
    out = tmp / "out"
    return out, _build(lib, scene, out)


def _artifacts(out: Path, manifest: dict, platform: str):
    for p in manifest["permutations"]:
        for stage, item in p["platforms"][platform]["stages"].items():
            yield p, stage, item


def test_one_tree_per_platform_with_every_artifact_named_and_hashed(built):
    out, m = built
    assert m["platforms"] == PLATFORMS
    # beside the platform trees: the materials' texture artifacts, shared by every platform
    assert sorted(d.name for d in out.iterdir() if d.is_dir() and d.name != "textures") == sorted(PLATFORMS)
    assert sorted(d.name for d in (out / "vulkan").iterdir()) == ["glsl", "hlsl", "wgsl"]
    for platform in PLATFORMS:
        kinds = set()
        for p, stage, item in _artifacts(out, m, platform):
            assert p["status"] == "ok" and stage in ("vert", "frag")
            for kind, art in item.items():
                assert art["path"].startswith(f"{platform}/")
                assert hashlib.sha256((out / art["path"]).read_bytes()).hexdigest() == art["sha256"]
                kinds.add(kind)
        want = {"vulkan": {"spirv", "glsl", "hlsl", "wgsl"}, "d3d12": {"hlsl"}, "gl": {"glsl", "essl"},
                "webgpu": {"wgsl"}}[platform]
        assert kinds == want  # no dxc on this machine: HLSL only
        entry = m["permutations"][0]["platforms"][platform]
        assert entry["tools"] and ("cost" in entry) == (platform != "gl")
    d3d = m["permutations"][0]["platforms"]["d3d12"]
    assert d3d["profiles"] == {"vert": "vs_6_0", "frag": "ps_6_0"} and d3d["dxil"].startswith("no dxc on PATH")
    assert m["permutations"][0]["platforms"]["gl"]["essl"] == "ok"


def test_vulkan_reflection_is_what_the_spirv_declares(built):
    from generator.analysis.reflect import reflect
    out, m = built
    for p, stage, item in _artifacts(out, m, "vulkan"):
        spirv = reflect((out / item["spirv"]["path"]).read_bytes()).entry(stage)
        refl = p["platforms"]["vulkan"]["reflection"]
        want = sorted((d["set"], d["binding"]) for d in refl["descriptors"] if stage in d["stages"])
        assert sorted((r.set, r.binding) for r in spirv.resources) == want, (p["hash"], stage)
        if stage == "vert":
            assert sorted(v.location for v in spirv.inputs) == [v["location"] for v in refl["vertex_inputs"]]


_REGISTER = re.compile(r"\b(\w+)\s*:\s*register\(([btsu])(\d+), space(\d+)\)")


def test_d3d12_reflection_is_what_the_hlsl_declares(built):
    out, m = built
    for p, stage, item in _artifacts(out, m, "d3d12"):
        text = (out / item["hlsl"]["path"]).read_text()
        declared = {(f"{c}{n}", int(s)) for _, c, n, s in _REGISTER.findall(text)}
        refl = p["platforms"]["d3d12"]["reflection"]
        assert declared == {(r["register"], r["space"]) for r in refl["resources"] if stage in r["visibility"]}
        for r in refl["resources"]:  # the class matches the register letter
            assert r["register"][0] == {"CBV": "b", "SRV": "t", "Sampler": "s"}[r["type"]]


_GL_BLOCK = re.compile(r"^layout\(binding = (\d+), std140\) uniform (\w+) \{", re.M)
_GL_SAMPLER = re.compile(r"^layout\(binding = (\d+)\) uniform (sampler\w+) (\w+);", re.M)


def test_gl_reflection_is_what_the_glsl_declares_without_vulkan_features(built):
    out, m = built
    for p, stage, item in _artifacts(out, m, "gl"):
        refl = p["platforms"]["gl"]["reflection"]
        for kind in ("glsl", "essl"):
            text = (out / item[kind]["path"]).read_text()
            assert text.startswith({"glsl": "#version 450 core\n", "essl": "#version 310 es\n"}[kind])
            for vulkan_only in ("set =", "texture2D", "sampler2D(", "GL_GOOGLE", "constant_id", "#line"):
                assert vulkan_only not in text, (kind, vulkan_only)
            blocks = {name: int(b) for b, name in _GL_BLOCK.findall(text)}
            assert blocks == {b["name"]: b["binding"] for b in refl["uniform_blocks"] if stage in b["stages"]}
            samplers = {name: (int(u), ty) for u, ty, name in _GL_SAMPLER.findall(text)}
            assert samplers == ({s["name"]: (s["unit"], s["type"]) for s in refl["samplers"]} if stage == "frag" else {})
            if kind == "essl" and stage == "frag":
                assert "precision highp float;" in text and "precision highp sampler2D;" in text
    units = [s["unit"] for p in m["permutations"] for s in p["platforms"]["gl"]["reflection"]["samplers"]]
    assert units and min(units) == 0  # flattened per namespace, from 0


_WGSL = re.compile(r"@group\((\d+)\) @binding\((\d+)\) var(?:<(\w+)>)? (\w+)")


def test_webgpu_reflection_is_what_the_wgsl_declares(built):
    out, m = built
    for p, stage, item in _artifacts(out, m, "webgpu"):
        text = (out / item["wgsl"]["path"]).read_text()
        assert text == (out / p["platforms"]["vulkan"]["stages"][stage]["wgsl"]["path"]).read_text()
        declared = {(int(g), int(b)) for g, b, _, _ in _WGSL.findall(text)}
        want = stage.upper().replace("VERT", "VERTEX").replace("FRAG", "FRAGMENT")
        refl = p["platforms"]["webgpu"]["reflection"]["bind_groups"]
        assert declared == {(e["group"], e["binding"]) for e in refl if want in e["visibility"]}
        for e in refl:
            assert len({"buffer", "texture", "sampler"} & set(e)) == 1


def test_gl_validation_errors_name_the_brick_line():
    from generator.toolchain import CompileJob
    from generator.toolchain.platforms import validate_dialects
    good = "#version 450 core\nlayout(location = 0) out vec4 c;\nvoid main() { c = vec4(1.0); }\n"
    bad = "#version 450 core\nlayout(location = 0) out vec4 c;\nvoid main() { c = vec4(nope); }\n"
    es = "#version 310 es\nlayout(location = 0) out vec4 c;\nvoid main() { c = vec4(1.0); }\n"  # no float precision
    jobs = [CompileJob("a.frag.gl", "gl", "frag", good), CompileJob("b.frag.gl", "gl", "frag", bad,
                                                                        line_map=((3, "bricks/x.py", 7),)),
            CompileJob("c.frag.essl", "essl", "frag", es)]
    errors = validate_dialects(jobs)
    assert errors["a.frag.gl"] == []
    assert errors["b.frag.gl"] and errors["b.frag.gl"][0].startswith("bricks/x.py:7:0: error:")
    assert "nope" in errors["b.frag.gl"][0] and not any("compilation terminated" in e for e in errors["b.frag.gl"])
    assert errors["c.frag.essl"] and "precision" in errors["c.frag.essl"][0]


def test_platform_option_builds_only_those_trees_and_packs(tmp_path):
    out = tmp_path / "out"
    cli = [sys.executable, "-m", "generator.cli", "build", str(EXAMPLE), "--out", str(out), "--no-cache", "-q"]
    r = subprocess.run([*cli, "--platform", "webgpu,gl", "--pack"], capture_output=True, text=True, cwd=REPO)
    assert r.returncode == 0, r.stderr
    m = json.loads((out / "manifest.json").read_text())
    assert m["platforms"] == ["gl", "webgpu"] and [p["platform"] for p in m["packs"]] == ["gl", "webgpu"]
    assert sorted(d.name for d in out.iterdir() if d.is_dir()) == ["gl", "packs", "textures", "webgpu"]
    for p in m["permutations"]:
        assert set(p["platforms"]) == {"gl", "webgpu"}
        for stages in p["languages"].values():  # the SPIR-V checks and costs ran, with nothing to ship
            assert all("cost" in item and "spirv" not in item for item in stages.values())
    bad = subprocess.run([*cli, "--platform", "metal"], capture_output=True, text=True, cwd=REPO)
    assert bad.returncode == 2 and "--platform: 'metal' is not a comma-separated list of vulkan, d3d12, gl, webgpu" \
        in bad.stderr


def test_essl_at_fp16_is_mediump_in_the_fragment_stage_only(lib, tmp_path):
    """fp16: the ES vertex transform stays highp (as the other languages' vertex shaders stay 32-bit), and
    Frame, declared by both stages, is highp in both (an ES program's uniforms match across stages)."""
    from generator.compose import compose_permutation
    from generator.scene.load import load_scene
    from generator.toolchain import CompileJob
    from generator.toolchain.platforms import validate_dialects
    scene_file = tmp_path / "fp16.toml"
    scene_file.write_text(re.sub(r'(?m)^precision = "fp32"$', 'precision = "fp16"', EXAMPLE.read_text()))
    scene = load_scene(scene_file, lib)
    h = sorted(scene.permutations)[0]
    es = {s.stage: s for s in compose_permutation(scene.permutations[h], lib, ("glsl",), ("essl",)).dialects}
    assert "precision highp float;" in es["vert"].text and "precision mediump float;" in es["frag"].text
    for s in es.values():
        assert "uniform Frame { highp mat4 view_proj; highp vec4 camera_pos; }" in s.text
    jobs = [CompileJob(f"{h}.{s.stage}.essl", "essl", s.stage, s.text, line_map=tuple(s.line_map)) for s in es.values()]
    assert validate_dialects(jobs) == {j.key: [] for j in jobs}


def test_a_gl_core_failure_keeps_its_source_beside_like_a_compile_failure(lib, tmp_path):
    """A GL core source that glslangValidator rejects fails the permutation and is written as
    gl/<hash>.<stage>.failed.glsl, named in failed_sources (as vulkan/<lang>/….failed.<lang> for a compile
    error). The failure: a Vulkan-only specialization constant, which GL core has not (backends/gl/emit.py)."""
    import dataclasses

    from generator.assemble.platforms import write_platforms
    from generator.compose import compose_permutation
    from generator.io import atomic_write
    from generator.scene.load import load_scene
    from generator.toolchain import CompileJob
    from generator.toolchain.platforms import validate_dialects
    scene = load_scene(EXAMPLE, lib)
    h = sorted(scene.permutations)[0]
    c = compose_permutation(scene.permutations[h], lib, ("glsl",), ("gl", "essl"))
    bad = "layout(constant_id = 0) const float vk_only = 1.0;\nvoid main() {"
    c.dialects = [dataclasses.replace(s, text=s.text.replace("void main() {", bad))
                  if (s.language, s.stage) == ("gl", "frag") else s for s in c.dialects]
    checked = validate_dialects([CompileJob(f"{h}.{s.stage}.{s.language}", s.language, s.stage, s.text,
                                            line_map=tuple(s.line_map)) for s in c.dialects])
    assert checked[f"{h}.vert.gl"] == [] and "constant_id" in checked[f"{h}.frag.gl"][0]
    entry = {"languages": {"glsl": {}}}
    errs = write_platforms(lambda rel, data: atomic_write(tmp_path / rel, data), h, c, entry, ["gl"], checked, "fp32")
    assert errs == checked[f"{h}.frag.gl"]
    assert entry["failed_sources"] == {"gl.frag": f"gl/{h}.frag.failed.glsl"}
    frag = next(s for s in c.dialects if (s.language, s.stage) == ("gl", "frag"))
    assert (tmp_path / entry["failed_sources"]["gl.frag"]).read_text() == frag.text
    assert not any(".frag." in p.name and ".failed." not in p.name for p in (tmp_path / "gl").iterdir())
