"""A scene's textures written by the build (generator/assemble/texture_outputs.py): every binding's image a
content-addressed KTX2 with its full mip chain, shared where the image is, listed per material binding with
its binding, format, size, levels, colour space, sha256, path, source and sampler state (spelled per
platform in the manifest's `samplers`); byte-identical across builds; an image error leaves the last
build's outputs as they were; the depfile names the images."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from generator.assemble.samplers import spell
from generator.io import ktx2, sha256
from generator.scene.textures import Sampler
from tests.scene.test_textures import WOOD, checker, default_images, png, write_scene

REPO = Path(__file__).resolve().parents[2]

SCENE = WOOD + '''
[materials.plain]
brdf = "lambert"
packing = "albedo_texture"
textures = { albedo_map = "tex/wood.png" }

[materials.bare]
brdf = "lambert+phong_normalized"
packing = "albedo_texture(normal=normal_map)"
samplers = { albedo_map = { anisotropy = 8, lod_bias = -0.5 } }
'''
OBJECTS = ("wood", "plain", "bare")


def run(*args, cwd=REPO):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=600)


def tree(out: Path) -> dict[str, bytes]:
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and p.name != ".shadermatrix-lock"}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    d = tmp_path_factory.mktemp("textured")
    path = write_scene(d, SCENE, objects=OBJECTS)
    r = run("build", path, "--out", d / "out", "--depfile", d / "out.d", "--platform", "vulkan,webgpu")
    assert r.returncode == 0, r.stderr
    return d, json.loads((d / "out" / "manifest.json").read_text())


@pytest.mark.toolchain
def test_every_binding_is_listed_with_its_artifact_binding_and_sampler(built):
    d, m = built
    wood = m["materials"]["wood"]["textures"]
    assert set(wood) == {"albedo_map", "normal_map"}
    a = wood["albedo_map"]
    assert (a["set"], a["binding"], a["sampler_binding"]) == (1, 1, 2)  # as the permutation's reflection has it
    perm = next(e for e in m["permutations"] if "wood_obj" in e["objects"])
    bound = {t["name"]: t for t in perm["interface"]["frag"]["textures"]}
    assert (bound["albedo_map"]["set"], bound["albedo_map"]["binding"]) == (a["set"], a["binding"])
    uber = {t["name"]: t for t in m["ubershader"]["interface"]["frag"]["textures"]}
    assert a["ubershader"] == {k: uber["albedo_map"][k] for k in ("set", "binding", "sampler_binding")}
    assert (a["format"], a["width"], a["height"], a["levels"], a["colour_space"]) == ("R8G8B8A8_SRGB", 8, 8, 4, "srgb")
    assert (a["source"], a["generated"], a["holds"]) == ("tex/wood.png", False, "color")
    assert a["sampler"] == {"mag_filter": "nearest", "min_filter": "nearest", "mipmap": "none", "wrap_u": "mirrored",
                            "wrap_v": "clamp", "anisotropy": 1, "lod_bias": 0.0, "compare": None,
                            "index": a["sampler"]["index"]}
    n = wood["normal_map"]
    assert (n["format"], n["levels"], n["holds"], n["colour_space"]) == ("R8G8B8A8_UNORM", 3, "normal", "linear")
    row = m["samplers"][a["sampler"]["index"]]
    assert row["platforms"]["vulkan"]["addressModeU"] == "VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT"
    assert row["platforms"]["vulkan"]["maxLod"] == 0.25 and row["platforms"]["webgpu"]["lodMaxClamp"] == 0.25
    assert set(row["platforms"]) == {"vulkan", "webgpu"}  # the platforms built


@pytest.mark.toolchain
def test_artifacts_are_ktx2_mip_chains_named_by_their_bytes_and_shared(built):
    d, m = built
    out = d / "out"
    wood, plain = m["materials"]["wood"]["textures"]["albedo_map"], m["materials"]["plain"]["textures"]["albedo_map"]
    assert wood["path"] == plain["path"] and wood["sampler"]["index"] != plain["sampler"]["index"]
    files = {t["path"]: t for t in m["textures"]}
    assert sorted(files) == sorted(p.relative_to(out).as_posix() for p in (out / "textures").iterdir())
    assert files[wood["path"]]["used_by"] == ["plain/albedo_map", "wood/albedo_map"] or \
        sorted(files[wood["path"]]["used_by"]) == ["plain/albedo_map", "wood/albedo_map"]
    for path, t in files.items():
        data = (out / path).read_bytes()
        assert sha256(data) == t["sha256"] and len(data) == t["bytes"] and t["sha256"][:12] in path
    levels, fmt, cube = ktx2.decode_levels((out / wood["path"]).read_bytes())
    assert fmt == "srgb8" and not cube and [lv.shape[:2] for lv in levels] == [(8, 8), (4, 4), (2, 2), (1, 1)]
    assert np.array_equal(levels[0][..., :3], checker())  # level 0 is the image's own texels
    # the checker's mean light is ~0.45 in linear: level 3 holds its sRGB code, not the mean of the codes (128)
    assert levels[-1][0, 0, 0] > 170


@pytest.mark.toolchain
def test_a_texture_with_no_image_is_the_generated_artifact(built):
    d, m = built
    bare = m["materials"]["bare"]["textures"]
    assert bare["albedo_map"]["generated"] and bare["albedo_map"]["source"] == "generated"
    assert (bare["albedo_map"]["width"], bare["albedo_map"]["levels"]) == (16, 5)  # the 16 × 16 checker
    assert bare["normal_map"]["generated"] and bare["normal_map"]["width"] == 32
    s = m["samplers"][bare["albedo_map"]["sampler"]["index"]]
    assert s["anisotropy"] == 8 and s["platforms"]["vulkan"]["anisotropyEnable"] is True
    assert s["platforms"]["webgpu"]["unsupported"] == ["lod_bias (WebGPU samplers have none: use textureSampleBias)"]


@pytest.mark.toolchain
def test_the_depfile_names_the_images(built):
    d, _ = built
    text = (d / "out.d").read_text()
    assert "tex/wood.png" in text and "tex/wood_n.png" in text


@pytest.mark.toolchain
def test_two_builds_are_byte_identical_and_a_rebuild_is_up_to_date(built, tmp_path):
    d, _ = built
    for name in ("first", "again"):  # back to back: the keys hash the generator's own sources too
        r = run("build", d / "scene.toml", "--out", tmp_path / name, "--platform", "vulkan,webgpu")
        assert r.returncode == 0, r.stderr
    first, second = tree(tmp_path / "first"), tree(tmp_path / "again")
    assert {k for k in first if k.startswith("textures/")} == {k for k in second if k.startswith("textures/")}
    assert first == second
    r = run("build", d / "scene.toml", "--out", tmp_path / "again", "--platform", "vulkan,webgpu")
    assert r.returncode == 0 and "up to date" in r.stdout, r.stdout


@pytest.mark.toolchain
def test_an_image_error_exits_1_located_and_leaves_the_last_outputs(tmp_path):
    path = write_scene(tmp_path, SCENE, objects=OBJECTS)
    out = tmp_path / "out"
    assert run("build", path, "--out", out, "--platform", "vulkan").returncode == 0
    before = tree(out)
    data = bytearray((tmp_path / "tex/wood.png").read_bytes())
    data[40] ^= 0x20  # one flipped bit: the PNG's CRC fails
    (tmp_path / "tex/wood.png").write_bytes(bytes(data))
    r = run("build", path, "--out", out, "--platform", "vulkan")
    line = path.read_text().splitlines().index(next(x for x in path.read_text().splitlines() if "albedo_map = \"" in x))
    assert r.returncode == 1 and r.stderr.startswith(f"error: {path}:{line + 1}:"), r.stderr
    assert "image 'tex/wood.png': the PNG is corrupt" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert tree(out) == before


@pytest.mark.toolchain
def test_a_changed_image_replaces_its_file_and_the_old_one_goes(tmp_path):
    path = write_scene(tmp_path, SCENE, objects=OBJECTS)
    out = tmp_path / "out"
    assert run("build", path, "--out", out, "--platform", "vulkan").returncode == 0
    old = json.loads((out / "manifest.json").read_text())["materials"]["plain"]["textures"]["albedo_map"]["path"]
    (tmp_path / "tex/wood.png").write_bytes(png(np.full((4, 4, 3), 90, np.uint8)))
    assert run("build", path, "--out", out, "--platform", "vulkan").returncode == 0
    new = json.loads((out / "manifest.json").read_text())["materials"]["plain"]["textures"]["albedo_map"]
    assert new["path"] != old and not (out / old).exists() and (out / new["path"]).is_file() and new["width"] == 4


@pytest.mark.toolchain
def test_a_textured_gltf_lists_its_images_by_pointer_with_its_samplers(tmp_path):
    from tests.scene.test_textures_gltf import textured_doc
    path = textured_doc(tmp_path).write_gltf(tmp_path / "model.gltf")
    r = run("build", path, "--out", tmp_path / "out", "--platform", "vulkan", "--depfile", tmp_path / "out.d")
    assert r.returncode == 0, r.stderr
    m = json.loads((tmp_path / "out" / "manifest.json").read_text())
    floor = m["materials"]["floor"]["textures"]["albedo_map"]
    assert floor["source"] == "/images/0" and (floor["sampler"]["wrap_u"], floor["sampler"]["wrap_v"]) == \
        ("repeat", "mirrored")
    metal = m["materials"]["metal"]["textures"]
    assert metal["base_color_map"]["source"] == "/images/2" and metal["normal_map"]["source"] == "/images/1"
    assert metal["orm_map"]["generated"] and metal["orm_map"]["width"] == 1  # glTF's white
    decal = m["materials"]["decal"]["textures"]["albedo_map"]
    assert decal["path"] == floor["path"] and decal["sampler"]["wrap_u"] == "clamp"
    vk = m["samplers"][floor["sampler"]["index"]]["platforms"]["vulkan"]
    assert (vk["addressModeU"], vk["addressModeV"]) == ("VK_SAMPLER_ADDRESS_MODE_REPEAT",
                                                        "VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT")
    assert "floor tiles.png" in (tmp_path / "out.d").read_text().replace("\\ ", " ")


@pytest.mark.toolchain
def test_shadow_maps_get_their_sampler_in_every_platform_reflection(tmp_path):
    path = write_scene(tmp_path, WOOD)
    text = path.read_text().replace('type = "directional"\n', 'type = "directional"\nshadow = "pcf_hardware"\n', 1)
    text = text.replace('[light_sets]', '[lights.lamp]\ntype = "point"\nshadow = "shadow_map"\n\n[light_sets]')
    path.write_text(text.replace('s = ["sun"]', 's = ["sun", "lamp"]'))
    r = run("build", path, "--out", tmp_path / "out")
    assert r.returncode == 0, r.stderr
    m = json.loads((tmp_path / "out" / "manifest.json").read_text())
    e = m["permutations"][0]
    states = {}
    for platform, p in e["platforms"].items():
        refl = p["reflection"]
        rows = [*refl.get("descriptors", []), *refl.get("resources", []), *refl.get("samplers", []),
                *refl.get("bind_groups", [])]
        got = {d.get("parameter") or re.sub(r"^(_smp_)?l\d+_", "", d["name"]): m["samplers"][d["sampler_state"]]
               for d in rows if "sampler_state" in d}
        assert set(got) == {"shadow_depth", "shadow_map"}, (platform, got)
        states[platform] = got
    for got in states.values():
        assert got["shadow_depth"]["compare"] == "less_or_equal" and got["shadow_map"]["compare"] is None
        assert got["shadow_map"]["wrap_u"] == "clamp" and got["shadow_map"]["mipmap"] == "none"
    cmp = states["vulkan"]["shadow_depth"]["platforms"]
    assert cmp["vulkan"]["compareEnable"] is True and cmp["d3d12"]["Filter"] == "D3D12_FILTER_COMPARISON_MIN_MAG_LINEAR_MIP_POINT"
    assert cmp["gl"]["GL_TEXTURE_COMPARE_FUNC"] == "GL_LEQUAL" and cmp["webgpu"]["compare"] == "less-equal"
    # each depth pass's binds name the same rows (the sampler is described once, in samplers)
    binds = {b["texture"]: m["samplers"][b["sampler_state"]] for light in m["lights"].values()
             for b in light["depth_pass"]["binds"]}
    assert binds == states["vulkan"]


@pytest.mark.parametrize("mn, mag, mip, name", [
    ("linear", "linear", "linear", "D3D12_FILTER_MIN_MAG_MIP_LINEAR"),
    ("nearest", "nearest", "nearest", "D3D12_FILTER_MIN_MAG_MIP_POINT"),
    ("nearest", "nearest", "linear", "D3D12_FILTER_MIN_MAG_POINT_MIP_LINEAR"),
    ("nearest", "linear", "nearest", "D3D12_FILTER_MIN_POINT_MAG_LINEAR_MIP_POINT"),
    ("nearest", "linear", "linear", "D3D12_FILTER_MIN_POINT_MAG_MIP_LINEAR"),
    ("linear", "nearest", "nearest", "D3D12_FILTER_MIN_LINEAR_MAG_MIP_POINT"),
    ("linear", "nearest", "linear", "D3D12_FILTER_MIN_LINEAR_MAG_POINT_MIP_LINEAR"),
    ("linear", "linear", "none", "D3D12_FILTER_MIN_MAG_LINEAR_MIP_POINT"),
])
def test_every_filter_combination_has_its_d3d12_and_gl_names(mn, mag, mip, name):
    s = spell(Sampler(mag, mn, mip).as_dict())
    assert s["d3d12"]["Filter"] == name
    gl_min = f"GL_{mn.upper()}" + ("" if mip == "none" else f"_MIPMAP_{mip.upper()}")
    assert s["gl"]["GL_TEXTURE_MIN_FILTER"] == gl_min and s["gl"]["GL_TEXTURE_MAG_FILTER"] == f"GL_{mag.upper()}"
    assert (s["d3d12"]["MaxLOD"] == 0.25) == (mip == "none") == (s["vulkan"]["maxLod"] == 0.25)


def test_default_images_are_real_pngs():
    assert all(data.startswith(b"\x89PNG") for data in default_images().values())
