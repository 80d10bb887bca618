"""The renderer draws the scene's own textures: the build's KTX2 artifacts with their mip chains, through the
samplers the manifest spells for Vulkan (runtime/material_textures.py), on the validated lavapipe device.

The pattern tests draw one glTF quad facing the camera, lit head-on, whose base colour texture is a ramp
along u (16 texels, grey 40 … 235) and whose UVs run 0 … 4: along the middle image row, REPEAT shows four
ramps with a fall of a texel between them, MIRRORED_REPEAT two rises and two falls as gradual as the rises,
CLAMP_TO_EDGE one ramp and then the edge texel. The mip test minifies a 1-texel black/white checker (UVs
0 … 128, several texels per pixel): trilinear sampling of the build's chain draws what a flat image of the
sRGB-correct mean draws (linear 0.5, code 188; not the 128 of averaged codes), sampling level 0 alone
(glTF's LINEAR min filter: maxLod 0) aliases. The renders draw the same image in the specialized and the
ubershader modes, which bind the same images and samplers.

Measured (lavapipe, Mesa 25.0.7, 192 × 128): the minified checker's middle 105.0 (std 0), as the flat 188
image's (the flat 128 one: 46.0), std 33 at level 0 alone; REPEAT's largest step at a fall 118-124, at a
rise 11-12; MIRRORED's 11-12 at both.
"""
from __future__ import annotations

import copy
import json

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)
from tests.scene.test_gltf import Doc, png_data_uri

pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]
W, H = 192, 128
REPEAT, MIRRORED, CLAMP = 10497, 33648, 33071
LINEAR, LINEAR_MIPMAP_LINEAR = 9729, 9987
RAMP = 40 + 13 * np.arange(16)  # the ramp's grey codes along u


def _png(texels: np.ndarray) -> bytes:
    import io

    from PIL import Image
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(texels.astype(np.uint8))).save(buf, format="PNG")
    return buf.getvalue()


def _quad_scene(path, texels, uv_max, wrap, min_filter=LINEAR_MIPMAP_LINEAR, transform=None):
    """A glTF of one double-sided quad in the xy plane facing +z, UVs 0 … uv_max, lit head-on by a directional
    light, its base colour texture `texels` read through a sampler of wrap `wrap` on both axes (and through
    KHR_texture_transform `transform`, if given)."""
    g = Doc()
    g.d["images"].append({"uri": png_data_uri(_png(texels))})
    g.d["samplers"] = [{"magFilter": LINEAR, "minFilter": min_filter, "wrapS": wrap, "wrapT": wrap}]
    g.d["textures"].append({"source": 0, "sampler": 0})
    info = {"index": 0}
    if transform is not None:
        info["extensions"] = {"KHR_texture_transform": transform}
    m = g.material(name="tex", doubleSided=True, pbrMetallicRoughness={
        "baseColorTexture": info, "metallicFactor": 0, "roughnessFactor": 1})
    g.d["extensionsUsed"] = ["KHR_lights_punctual"] + (["KHR_texture_transform"] if transform is not None else [])
    g.d["extensions"] = {"KHR_lights_punctual": {"lights": [{"name": "sun", "type": "directional", "intensity": 0.8}]}}
    g.node(name="sun", extensions={"KHR_lights_punctual": {"light": 0}})  # along −z: onto the quad's face
    attrs = {"POSITION": g.accessor([[-1, 1, 0], [1, 1, 0], [1, -1, 0], [-1, -1, 0]], "VEC3"),
             "NORMAL": g.accessor([[0, 0, 1]] * 4, "VEC3"), "TANGENT": g.accessor([[1, 0, 0, 1]] * 4, "VEC4"),
             "TEXCOORD_0": g.accessor([[0, 0], [uv_max, 0], [uv_max, uv_max], [0, uv_max]], "VEC2")}
    g.d["meshes"].append({"name": "quad", "primitives": [
        {"attributes": attrs, "indices": g.accessor([0, 2, 1, 0, 3, 2], "SCALAR", 5123, 34963), "material": m}]})
    g.node(name="quad", mesh=0)
    return g.write_gltf(path)


def _render(device, lib, path, out, modes=("specialized", "ubershader")):
    """The frame of each mode (H, W, 3) and the specialized report, drawn from the scene's texture artifacts."""
    from PIL import Image

    from generator.assemble.render_inputs import scene_textures
    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene

    scene = load_scene(path, lib)
    build = scene_textures(scene, out / "build")
    frames, reports = {}, {}
    for mode in modes:
        reports[mode] = render_scene(scene, lib, mode, 1, out / mode, (W, H), device=device, build=build)
        frames[mode] = np.asarray(Image.open(out / mode / "frame_0000.png").convert("RGB")).astype(int)
    for mode in modes[1:]:
        assert (frames[mode] == frames[modes[0]]).all(), f"{mode} binds other textures or samplers than {modes[0]}"
    return frames[modes[0]], reports[modes[0]]


def _row(img) -> np.ndarray:
    """The middle image row's grey across the quad (the pixels brighter than the clear colour), left to right."""
    row = img[H // 2, :, 0]
    drawn = np.nonzero(_drawn(img[H // 2]))[0]
    assert len(drawn) > 60, "the quad spans the image"
    return row[drawn[0] + 1:drawn[-1]].astype(float)  # its edge pixels are partly the clear colour


CLEAR = np.round(np.array([0.06, 0.07, 0.09]) * 255)  # the renderer's clear colour


def _drawn(img) -> np.ndarray:
    """Where the image is not the clear colour."""
    return np.abs(img - CLEAR).max(-1) > 2


def _crossings(p) -> tuple[list[float], list[float]]:
    """(rising, falling): the slope of the profile where it crosses its mid level upwards and downwards."""
    mid = 0.5 * (p.min() + p.max())
    up, down = [], []
    for x in range(1, len(p)):
        if (p[x - 1] < mid) != (p[x] < mid):
            slope = np.abs(np.diff(p[max(x - 2, 0):x + 2])).max()  # the largest step next to it
            (up if p[x] > p[x - 1] else down).append(slope)
    return up, down


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def test_repeat_draws_the_ramp_four_times(device, lib, tmp_path):
    img, rep = _render(device, lib, _quad_scene(tmp_path / "q.gltf", _ramp(), 4, REPEAT), tmp_path)
    up, down = _crossings(_row(img))
    assert len(up) == 4 and len(down) == 3, (up, down)  # four periods, three wraps inside the quad
    assert min(down) > 4 * max(up), "each wrap falls from the last texel to the first within a texel"
    (row,) = rep.textures["tex"].values()
    assert row["levels"] == 5 and row["path"].startswith("textures/16x2.srgb8.")  # the build's chain


def test_khr_texture_transform_s_scale_repeats_the_texture_as_such_uvs_do(device, lib, tmp_path):
    """UVs 0 … 1 scaled by 4 in the shader (KHR_texture_transform) draw the image UVs 0 … 4 draw."""
    scaled, _ = _render(device, lib, _quad_scene(tmp_path / "t.gltf", _ramp(), 1, REPEAT, transform={
        "scale": [4, 4]}), tmp_path / "transform")
    plain, _ = _render(device, lib, _quad_scene(tmp_path / "q.gltf", _ramp(), 4, REPEAT), tmp_path / "uvs")
    up, down = _crossings(_row(scaled))
    assert len(up) == 4 and len(down) == 3, (up, down)
    d = np.abs(scaled - plain)
    assert d.max() <= 1 and (d > 0).mean() < 0.01, f"max {d.max()}, {(d > 0).sum()} channels differ"


def test_mirrored_repeat_draws_mirrored_periods(device, lib, tmp_path):
    img, _ = _render(device, lib, _quad_scene(tmp_path / "q.gltf", _ramp(), 4, MIRRORED), tmp_path)
    up, down = _crossings(_row(img))
    assert len(up) == 2 and len(down) == 2, (up, down)  # up, down, up, down
    assert max(down) < 2 * min(up) and max(up) < 2 * min(down), "the falls are the rises mirrored"


def test_clamp_to_edge_draws_the_edge_texel_past_one(device, lib, tmp_path):
    img, _ = _render(device, lib, _quad_scene(tmp_path / "q.gltf", _ramp(), 4, CLAMP), tmp_path)
    p = _row(img)
    up, down = _crossings(p)
    assert len(up) == 1 and not down, (up, down)
    tail = p[int(0.4 * len(p)):]  # u > 1 (perspective: u is not linear in x, but well past 1 here)
    assert tail.max() - tail.min() <= 1 and tail.min() >= p.max() - 1, "the last texel, constant"


def _ramp() -> np.ndarray:
    t = np.zeros((2, 16, 4), np.uint8)
    t[..., :3] = RAMP[None, :, None]
    t[..., 3] = 255
    return t


def test_a_minified_checker_is_the_srgb_correct_grey_with_mips_and_aliases_without(device, lib, tmp_path):
    """The checker drawn far smaller than its texels, against flat images of its sRGB-correct mean (code 188,
    linear 0.5) and of the mean of its codes (128): with the build's mips it is the first, at level 0 alone
    it is neither, and not flat."""
    checker = np.zeros((8, 8, 4), np.uint8)
    checker[..., :3] = (255 * ((np.arange(8)[:, None] + np.arange(8)[None, :]) % 2))[..., None]
    checker[..., 3] = 255
    cases = {"mips": (checker, LINEAR_MIPMAP_LINEAR), "level0": (checker, LINEAR),
             "flat188": (np.full((8, 8, 4), 188, np.uint8), LINEAR_MIPMAP_LINEAR),
             "flat128": (np.full((8, 8, 4), 128, np.uint8), LINEAR_MIPMAP_LINEAR)}
    got = {}
    for name, (texels, min_filter) in cases.items():
        path = _quad_scene(tmp_path / f"{name}.gltf", texels, 128, REPEAT, min_filter)
        img, rep = _render(device, lib, path, tmp_path / name, modes=("specialized",))
        rows, cols = np.nonzero(_drawn(img))
        r0, r1, c0, c1 = rows.min(), rows.max(), cols.min(), cols.max()
        # the middle half of the quad's box: inside the quad, away from its edges
        got[name] = img[(3 * r0 + r1) // 4:(r0 + 3 * r1) // 4, (3 * c0 + c1) // 4:(c0 + 3 * c1) // 4, 0].astype(float)
        assert got[name].size > 1000
    mipped, level0, flat = got["mips"], got["level0"], got["flat188"]
    assert abs(mipped.mean() - flat.mean()) <= 2 and mipped.std() <= flat.std() + 1.5, (mipped.mean(), flat.mean(),
                                                                                          mipped.std())
    assert got["flat128"].mean() < flat.mean() - 20, "averaged codes would be darker"
    assert level0.std() > 10 * max(mipped.std(), 1), f"level 0 alone aliases (std {level0.std():.1f})"


def test_the_textured_scene_draws_its_images_and_samplers(device, lib, tmp_path):
    """scenes/textured.toml: its three PNGs as the build's KTX2 chains, four distinct samplers (anisotropy 8 on
    lavapipe: the device has samplerAnisotropy, nothing clamped), the same image through the ubershader; the
    brick wall is red and the tiles' spheres are not."""
    from pathlib import Path

    scene = Path(__file__).resolve().parents[2] / "scenes" / "textured.toml"
    img, rep = _render(device, lib, scene, tmp_path)
    assert {m: sorted(t) for m, t in rep.textures.items()} == {
        "brick": ["albedo_map", "normal_map"], "floor": ["albedo_map"], "mirrored_tiles": ["albedo_map"],
        "sign": ["albedo_map"]}
    assert rep.textures["brick"]["albedo_map"]["levels"] == 7 and rep.textures["floor"]["albedo_map"]["levels"] == 6
    assert len({t["sampler"] for m in rep.textures.values() for t in m.values()}) == 4
    assert rep.texture_notes == []
    report = json.loads((tmp_path / "specialized" / "report.json").read_text())
    assert report["textures"] == rep.textures
    left = img[:, : W // 4].reshape(-1, 3)
    lit = left[left.sum(-1) > 120]
    assert len(lit) > 50 and (lit[:, 0] > lit[:, 2] + 20).mean() > 0.5, "the wall (leftmost) shows its red brick"


def test_a_baked_table_is_read_through_the_sampler_its_row_names(device, lib, tmp_path):
    """A factored BRDF's table (oren_nayar_factored: on_sin_sin) is drawn through the sampler of its row of the
    build's ``tables``: the row as written draws what the renderer's default sampler draws (the same state),
    one whose sampler row says nearest draws another image."""
    from PIL import Image

    from generator.assemble.render_inputs import scene_textures
    from generator.runtime.material_textures import BuildOutputs
    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene

    path = tmp_path / "t.toml"
    path.write_text('[scene]\nname = "t"\n[materials.m]\nbrdf = "oren_nayar_factored"\n[lights.sun]\n'
                    'type = "directional"\n[light_sets]\nall = ["sun"]\n[[objects]]\nname = "o"\n'
                    'material = "m"\nlights = "all"\n')
    scene = load_scene(path, lib)
    build = scene_textures(scene, tmp_path / "b", lib)
    (row,) = [t for t in build.manifest["tables"] if t["texture"] == "on_sin_sin"]
    state = build.manifest["samplers"][row["sampler"]["index"]]
    assert (state["mipmap"], state["wrap_u"], state["mag_filter"]) == ("none", "clamp", "linear")

    def frame(name, b):
        render_scene(scene, lib, "specialized", 1, tmp_path / name, (W, H), device=device, build=b)
        return np.asarray(Image.open(tmp_path / name / "frame_0000.png").convert("RGB")).astype(int)

    plain = frame("none", None)
    assert (frame("row", build) == plain).all(), "the table's row is the renderer's default state"
    nearest = copy.deepcopy(build.manifest)
    vk = nearest["samplers"][row["sampler"]["index"]]["platforms"]["vulkan"]
    vk.update(magFilter="VK_FILTER_NEAREST", minFilter="VK_FILTER_NEAREST")
    assert (frame("nearest", BuildOutputs(nearest, build.root)) != plain).any(), "the row's state is the one drawn"


def test_what_the_device_cannot_do_is_clamped_and_said(device):
    from generator.assemble.samplers import spell
    from generator.runtime.images import Sampler
    from generator.scene.textures import Sampler as State

    state = spell(State(anisotropy=16, lod_bias=2.0).as_dict(), ["vulkan"])["vulkan"]
    s = Sampler(device, {**state, "maxAnisotropy": 64.0, "mipLodBias": 99.0})
    try:
        top, bias = device.limits.maxSamplerAnisotropy, device.limits.maxSamplerLodBias
        assert s.state["maxAnisotropy"] == top and s.state["mipLodBias"] == bias
        assert len(s.notes) == 2 and "maxSamplerAnisotropy" in s.notes[0] and "maxSamplerLodBias" in s.notes[1]
    finally:
        s.destroy()
    plain = Sampler(device, state)
    try:
        assert plain.notes == [] and plain.state["anisotropyEnable"] and plain.state["maxAnisotropy"] == 16
    finally:
        plain.destroy()


def test_a_build_that_does_not_match_its_files_or_the_scene_is_refused(device, lib, tmp_path):
    from generator.assemble.render_inputs import scene_textures
    from generator.lang.errors import UserError
    from generator.runtime.material_textures import BuildOutputs
    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene

    scene = load_scene(_quad_scene(tmp_path / "q.gltf", _ramp(), 4, REPEAT), lib)
    with pytest.raises(UserError, match="draws them from a build's KTX2 artifacts"):
        render_scene(scene, lib, "specialized", 1, tmp_path / "none", (W, H), device=device)
    build = scene_textures(scene, tmp_path / "b")
    ((name, row),) = build.manifest["materials"]["tex"]["textures"].items()
    f = tmp_path / "b" / row["path"]
    last = f.read_bytes()[-1]
    f.write_bytes(f.read_bytes()[:-1] + bytes([last ^ 1]))
    with pytest.raises(UserError, match="is not the manifest's"):
        render_scene(scene, lib, "specialized", 1, tmp_path / "bad", (W, H), device=device, build=build)
    f.write_bytes(f.read_bytes()[:-1] + bytes([last]))  # the file as built
    stale = copy.deepcopy(build.manifest)
    stale["materials"]["tex"]["textures"][name].update(set=7, binding=9)  # where another build's shader binds it
    with pytest.raises(UserError, match="is at set 7, binding 9 of the permutation"):
        render_scene(scene, lib, "specialized", 1, tmp_path / "stale", (W, H), device=device,
                     build=BuildOutputs(stale, build.root))
    other = load_scene(_quad_scene(tmp_path / "m.gltf", _ramp(), 4, MIRRORED), lib)
    with pytest.raises(UserError, match="is not the scene's"):
        render_scene(other, lib, "specialized", 1, tmp_path / "other", (W, H), device=device,
                     build=BuildOutputs(build.manifest, build.root))
