"""KHR_texture_transform as part of the packing: the glTF packings' optional slot `uv`, filled by
bricks/packing/uv/texture_transform.py; generator/scene/texture_transform.py maps the extension to it.

- the filler, emitted to NumPy, is the extension's affine map uv' = T(offset) · R(rotation) · S(scale) · uv, written
  here from the extension (3 × 3 matrices; the rotation as the extension's own example needs it: the lower-left
  quadrant, turned 90° clockwise);
- shade() in NumPy, the specialized glue's and the ubershader's, samples every texture of the material (base colour,
  metallic-roughness, normal map, emissive, the coverage's alpha) at uv', exactly where the material without the
  slot samples them when given uv';
- a glTF material using the extension imports to `…(normal=…,uv=texture_transform)` with the file's values, builds in
  every language (the normal build: glslc, naga, spirv-val), and its uploads hold the values;
- a material without it, with the identity, or with one only on a texture it does not sample keeps its key (and so
  its shader); different transforms on one material's textures, a second UV set and an unsupported extension are
  errors at their JSON pointer.
"""
from __future__ import annotations

import copy
import json
import math
import struct

import numpy as np
import pytest

from generator.lang import SourceError
from tests.conftest import require_tool
from tests.scene.test_gltf import BRDF, run, sample_doc

TT = "KHR_texture_transform"
MOVE = {"offset": [0.2, 0.4], "scale": [0.6, 0.5], "rotation": 0.4}  # keeps uv' of [0, 1]² inside [0.17, 0.95]
SIZE = 4


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def spec_map(uv, offset, scale, rotation):
    """The extension's uv' = (T · R · S · (u, v, 1)).xy, R rotating "counter-clockwise" in v-down UV space:
    rows (cos r, sin r), (−sin r, cos r) (its GLSL listing, read column-major, has the transpose)."""
    c, s = math.cos(rotation), math.sin(rotation)
    T = np.array([[1.0, 0.0, offset[0]], [0.0, 1.0, offset[1]], [0.0, 0.0, 1.0]])
    R = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    S = np.diag([scale[0], scale[1], 1.0])
    uv = np.asarray(uv, np.float64)
    return (np.concatenate([uv, np.ones((len(uv), 1))], 1) @ (T @ R @ S).T)[:, :2]


def _perm(lib, packing, **state):
    from generator.spec.permutation import LightKey, Permutation, canonical, parse_brdf, parse_spec
    from generator.spec.surface import Surface
    return Permutation(canonical(parse_brdf(BRDF, lib)), (LightKey("directional", "none"),),
                       canonical(parse_spec(packing, lib, ("packing",))), surface=Surface(**state))


def _numpy(program):
    from generator.backends.numpy.emit import NumpyTarget
    t = NumpyTarget()
    return t.load(t.emit(program.structs, program.functions, program.globals), np.float64)


# ------------------------------------------------------------------ the filler is the extension's map


def test_the_filler_is_the_extensions_affine_map(lib):
    from generator.link import link_permutation
    lp = link_permutation(_perm(lib, "albedo_texture(uv=texture_transform)"), lib)
    map_uv = _numpy(lp.program)["texture_transform_map_uv"]
    rng = np.random.default_rng(1)
    uv = rng.uniform(-1.0, 2.0, (300, 2))
    for _ in range(20):
        offset, scale, rot = rng.uniform(-2, 2, 2), rng.uniform(-3, 3, 2), rng.uniform(-7, 7)
        got = map_uv(uv, np.tile(offset, (300, 1)), np.tile(scale, (300, 1)), np.full(300, rot))
        np.testing.assert_allclose(got, spec_map(uv, offset, scale, rot), rtol=1e-13, atol=1e-14)
    # the extension's examples: "only the lower left quadrant of the source image, rotated clockwise 90°" ...
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    got = map_uv(corners, np.tile([0.0, 1.0], (4, 1)), np.tile([0.5, 0.5], (4, 1)), np.full(4, math.pi / 2))
    np.testing.assert_allclose(got, [[0.0, 1.0], [0.0, 0.5], [0.5, 1.0], [0.5, 0.5]], atol=1e-15)
    # ... and "inverts the T axis": offset [0, 1], scale [1, −1]
    got = map_uv(corners, np.tile([0.0, 1.0], (4, 1)), np.tile([1.0, -1.0], (4, 1)), np.zeros(4))
    np.testing.assert_array_equal(got, [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]])


# ------------------------------------------------------------------ shade() samples every texture at uv'


def _textures(rng):
    n = rng.uniform(-0.4, 0.4, (SIZE, SIZE, 3)) + [0.0, 0.0, 1.0]
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    return {"t_base_color_map": rng.uniform(0.05, 1.0, (SIZE, SIZE, 4)),
            "t_orm_map": rng.uniform(0.1, 1.0, (SIZE, SIZE, 4)),
            "t_normal_map": np.concatenate([(n + 1.0) / 2.0, np.ones((SIZE, SIZE, 1))], -1),
            "t_emissive_map": rng.uniform(0.0, 1.0, (SIZE, SIZE, 4))}


def _samples(rng, n):
    from generator.eval.shade import _surface
    Ng = np.tile([0.0, 0.0, 1.0], (n, 1)) + rng.uniform(-0.2, 0.2, (n, 3))
    V = Ng + rng.uniform(-0.6, 0.6, (n, 3))
    T = np.concatenate([np.cross(Ng, rng.normal(size=(n, 3))), np.ones((n, 1))], 1)
    return _surface(np.zeros((n, 3)), Ng, V, T, rng.uniform(0.0, 1.0, (n, 2)))


VALUES = {"m_base_color": [0.9, 0.7, 0.5], "m_metallic": 0.3, "m_roughness": 0.6, "m_base_alpha": 0.8,
          "m_emissive": [0.2, 0.1, 0.3], "l0_direction": [0.3, 0.2, 0.93], "l0_color": [2.0, 1.8, 1.5]}


def _shade(lib, perm, local, values):
    from generator.link import link_permutation
    lp = link_permutation(perm, lib)
    fn = _numpy(lp.program)["shade"]
    return np.asarray(fn(*[local[k] if k in local else values[k] for k, _ in lp.glue.signature]), np.float64)


def test_shade_samples_every_texture_at_the_transformed_uv(lib):
    packing = "gltf_metallic_roughness(normal=normal_map{})"
    state = {"alpha": "blend", "emissive": "texture"}  # the emissive texture and the coverage's A are sampled too
    moved, plain = _perm(lib, packing.format(",uv=texture_transform"), **state), _perm(lib, packing.format(""), **state)
    rng = np.random.default_rng(2)
    local, tex = _samples(rng, 400), _textures(rng)
    params = {"m_uv_offset": MOVE["offset"], "m_uv_scale": MOVE["scale"], "m_uv_rotation": MOVE["rotation"]}
    got = _shade(lib, moved, local, {**VALUES, **params, **tex})
    there = {**local, "uv": spec_map(local["uv"], **MOVE)}
    want = _shade(lib, plain, there, {**VALUES, **tex})
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-14)
    untransformed = _shade(lib, plain, local, {**VALUES, **tex})
    for c in range(4):  # colour and coverage both move with the texture coordinates
        assert np.abs(untransformed[:, c] - want[:, c]).max() > 0.02 * np.abs(want[:, c]).max()
    # the default parameters are the identity: the slot filled with them shades as the empty slot
    same = _shade(lib, moved, local, {**VALUES, "m_uv_offset": [0.0, 0.0], "m_uv_scale": [1.0, 1.0],
                                      "m_uv_rotation": 0.0, **tex})
    np.testing.assert_allclose(same, untransformed, rtol=1e-13, atol=1e-15)


def test_the_ubershader_transforms_only_the_variant_whose_slot_is_filled(lib):
    from generator.eval.shade import uber_entries
    from generator.link.uber import link_ubershader
    moved, plain = _perm(lib, "albedo_texture(normal=normal_map,uv=texture_transform)"), \
        _perm(lib, "albedo_texture(normal=normal_map)")
    u = link_ubershader([moved, plain], lib)
    assert [v.packing for v in u.variants] == [moved.packing, plain.packing] and "uv" in u.surface
    params = {"m_rho_d": [0.8, 0.6, 0.4], "m_alpha": 0.3, "m_f0": [0.04] * 3}
    offset32 = [float(np.float32(x)) for x in MOVE["offset"]]  # the entries hold float32
    scale32 = [float(np.float32(x)) for x in MOVE["scale"]]
    rot32 = float(np.float32(MOVE["rotation"]))
    mats, lights = uber_entries(u, [(0, {**params, "m_uv_offset": MOVE["offset"], "m_uv_scale": MOVE["scale"],
                                         "m_uv_rotation": MOVE["rotation"]}), (1, params)],
                                [("directional", "none", {"direction": VALUES["l0_direction"],
                                                          "color": VALUES["l0_color"]})])
    from generator.backends.numpy.emit import NumpyTarget
    t = NumpyTarget()
    shade = t.load(t.emit(u.program.structs, u.program.functions, u.program.globals), np.float64,
                   resources={"material_buffer": mats, "light_buffer": lights})["shade"]
    rng = np.random.default_rng(3)
    local, tex = _samples(rng, 300), _textures(rng)
    tex = {"t_albedo_map": tex["t_base_color_map"], "t_normal_map": tex["t_normal_map"]}

    def run_uber(surface, material):
        args = {**surface, "material": np.full(300, material, np.int32), **tex}
        return np.asarray(shade(*[args[k] for k, _ in u.signature]), np.float64)

    got = run_uber(local, 0)
    want = run_uber({**local, "uv": spec_map(local["uv"], offset32, scale32, rot32)}, 1)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-7)  # float32 parameters: the same uv' up to rounding
    assert np.abs(run_uber(local, 1) - want).max() > 0.02 * np.abs(want).max()


def test_an_empty_slot_declares_nothing(lib):
    from generator.compose import compose_permutation
    for packing in ("albedo_texture(normal=normal_map)", "gltf_metallic_roughness(normal=vertex)"):
        c = compose_permutation(_perm(lib, packing, alpha="mask", emissive="texture"), lib)
        text = "\n".join(s.text for s in c.sources)
        assert "uv_t" not in text and "texture_transform" not in text and "uv_rotation" not in text
        assert not [s for s in c.material if s.param.startswith("uv_")]
    c = compose_permutation(_perm(lib, "albedo_texture(normal=normal_map,uv=texture_transform)"), lib)
    assert [s.param for s in c.material if s.param.startswith("uv_")] == ["uv_offset", "uv_scale", "uv_rotation"]


# ------------------------------------------------------------------ glTF import


def _with(mutate):
    g = sample_doc()
    mutate(g.d)
    return g


def _on(info: dict, ext: dict) -> None:
    info.setdefault("extensions", {})[TT] = copy.deepcopy(ext)


def _metal_moved(d, ext=MOVE):
    m = d["materials"][0]  # textured_metal: base colour, ORM, normal (and occlusion, not sampled)
    for info in (m["pbrMetallicRoughness"]["baseColorTexture"], m["pbrMetallicRoughness"]["metallicRoughnessTexture"],
                 m["normalTexture"]):
        _on(info, ext)
    d["extensionsUsed"].append(TT)


def _load(tmp_path, g, lib):
    from generator.scene.load import load_scene
    return load_scene(g.write_gltf(tmp_path / "model.gltf"), lib)


def _keys(scene) -> dict[str, str]:
    return {o["name"]: scene.permutations[o["permutation"]].canonical() for o in scene.objects}


def test_a_transformed_material_maps_to_the_uv_slot_with_the_files_values(tmp_path, lib):
    plain = _keys(_load(tmp_path, sample_doc(), lib))
    scene = _load(tmp_path, _with(_metal_moved), lib)
    keys = _keys(scene)
    assert {k for k in keys if keys[k] != plain[k]} == {"statue"}
    assert "packing=gltf_metallic_roughness(normal=normal_map,uv=texture_transform);" in keys["statue"]
    assert keys["statue"] == plain["statue"].replace("(normal=normal_map)", "(normal=normal_map,uv=texture_transform)")
    m = scene.materials["textured_metal"]
    assert {k: m.params[k] for k in ("uv_offset", "uv_scale", "uv_rotation")} == {
        "uv_offset": [0.2, 0.4], "uv_scale": [0.6, 0.5], "uv_rotation": 0.4}
    assert any(n.startswith(f"extension {TT} accepted") for n in scene.notes)


def _identity(d):
    _metal_moved(d, {"offset": [0, 0], "scale": [1, 1], "rotation": 0})


def _occlusion_only(d):  # textured_metal's occlusionTexture is not read
    _on(d["materials"][0]["occlusionTexture"], MOVE)


def _dark_emissive(d):  # an emissiveTexture under emissiveFactor 0 is not sampled
    d["materials"][2]["emissiveTexture"] = {"index": 0}
    _on(d["materials"][2]["emissiveTexture"], MOVE)


def _texcoord_overridden(d):  # the extension's texCoord 0 overrides the textureInfo's 1 (its fallback set)
    info = d["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"]
    info["texCoord"] = 1
    _on(info, {"texCoord": 0})


@pytest.mark.parametrize("mutate", [_identity, _occlusion_only, _dark_emissive, _texcoord_overridden],
                         ids=["identity", "occlusion-only", "unsampled-emissive", "texcoord-overridden"])
def test_a_transform_that_changes_nothing_drawn_keeps_every_key(tmp_path, lib, mutate):
    plain = _keys(_load(tmp_path, sample_doc(), lib))
    scene = _load(tmp_path, _with(mutate), lib)
    assert _keys(scene) == plain
    assert not any(k.startswith("uv_") for m in scene.materials.values() for k in m.params)


def _differ(d):
    _metal_moved(d)
    d["materials"][0]["normalTexture"]["extensions"][TT]["rotation"] = 0.5


def _one_without(d):
    _metal_moved(d)
    del d["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]["extensions"]


def _emissive_differs(d):  # the emissive texture is sampled (a factor ≠ 0): its transform counts
    _metal_moved(d)
    d["materials"][0]["emissiveFactor"] = [1, 1, 1]
    d["materials"][0]["emissiveTexture"] = {"index": 0}


def _set1(d):
    _on(d["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"], {"texCoord": 1, "scale": [2, 2]})


def _bad_offset(d):
    _on(d["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"], {"offset": [1, 2, 3]})


def _bad_rotation(d):
    _on(d["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"], {"rotation": "90deg"})


def _sheen(d):
    _metal_moved(d)
    d["materials"][0]["extensions"] = {"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1]}}


M0, LEAF = "/materials/0", "/materials/1/pbrMetallicRoughness/baseColorTexture"
BAD = [  # (id, mutate, pointer in the message, words)
    ("different-rotation", _differ, f"{M0}/normalTexture/extensions/{TT}",
     f"differs from {M0}/pbrMetallicRoughness/baseColorTexture's"),
    ("one-without", _one_without, f"{M0}/pbrMetallicRoughness/metallicRoughnessTexture",
     f"this texture's {TT} (none) differs"),
    ("sampled-emissive-without", _emissive_differs, f"{M0}/emissiveTexture", f"this texture's {TT} (none) differs"),
    ("texcoord-1", _set1, f"{LEAF}/extensions/{TT}/texCoord", "texture coordinate set 1 is not supported"),
    ("offset-of-three", _bad_offset, f"{LEAF}/extensions/{TT}/offset", "must be 2 finite numbers"),
    ("rotation-a-string", _bad_rotation, f"{LEAF}/extensions/{TT}/rotation", "must be a finite number"),
    ("unsupported-extension", _sheen, f"{M0}/extensions/KHR_materials_sheen",
     "extension KHR_materials_sheen changes shading and is not supported"),
]


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_what_cannot_be_drawn_is_an_error_at_its_pointer(tmp_path, lib, case):
    _, mutate, where, words = case
    path = _with(mutate).write_gltf(tmp_path / "model.gltf")
    from generator.scene.load import load_scene
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert str(e.value).startswith(f"{path}: {where}: "), str(e.value)
    assert words in str(e.value) and " — " in str(e.value) and "\n" not in str(e.value)


def test_a_toml_scene_fills_the_slot_too(tmp_path, lib):
    from generator.scene.load import load_scene
    p = tmp_path / "tiled.toml"
    p.write_text('[scene]\nname = "tiled"\n\n[materials.floor]\nbrdf = "lambert"\n'
                 'packing = "albedo_texture(uv=texture_transform)"\n'
                 'params = { rho_d = [0.8, 0.8, 0.8], uv_scale = [4.0, 4.0] }\n\n'
                 '[lights.sun]\ntype = "directional"\nparams = { direction = [0.0, 1.0, 0.0], color = [1.0, 1.0, 1.0] }\n\n'
                 '[light_sets]\nday = ["sun"]\n\n[[objects]]\nname = "floor"\nmaterial = "floor"\nlights = "day"\n')
    scene = load_scene(p, lib)
    (perm,) = scene.permutations.values()
    assert perm.packing == "albedo_texture(normal=vertex,uv=texture_transform)"


# ------------------------------------------------------------------ the normal build, every language


@pytest.mark.toolchain
def test_a_transformed_gltf_builds_in_every_language_with_its_values_uploaded(tmp_path):
    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    path = _with(_metal_moved).write_gltf(tmp_path / "model.gltf")
    out = tmp_path / "out"
    r = run("build", path, "--out", out, "--no-cache", "-j", "2")
    assert r.returncode == 0, r.stderr + r.stdout
    m = json.loads((out / "manifest.json").read_text())
    assert len(m["permutations"]) == 4 and m["ubershader"]
    for p in m["permutations"]:
        assert p["status"] == "ok" and set(p["languages"]) == {"glsl", "hlsl", "wgsl"}
    (p,) = [p for p in m["permutations"] if "uv=texture_transform" in p["id"]]
    assert p["objects"] == ["statue"]
    block = next(b for b in p["interface"]["frag"]["uniform_blocks"] if b["name"] == "Material")
    at = {q["name"]: q["offset"] for q in block["parameters"]}
    data = bytes.fromhex(p["uploads"][0]["Material"])

    def floats(name, n):
        return list(struct.unpack_from(f"<{n}f", data, at[name]))
    assert floats("uv_offset", 2) == [np.float32(0.2), np.float32(0.4)]
    assert floats("uv_scale", 2) == [np.float32(0.6), np.float32(0.5)]
    assert floats("uv_rotation", 1) == [np.float32(0.4)]
    frag = (out / p["languages"]["wgsl"]["frag"]["source"]).read_text()
    assert "texture_transform_map_uv" in frag
