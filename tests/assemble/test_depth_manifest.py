"""The depth passes in the engine contract: the build writes the depth units as artifacts in every platform's tree
and describes each shadowed light's depth pass (manifest ``depth_shaders`` and ``lights.<name>.depth_pass``).

Built from tests/scenes/depth_mask.toml (a shadow_map sun, a vsm moon, two masked materials) and the example
scene (one shadow_map sun, nothing masked). Checked: every unit's files exist with their sha256 in every
platform's tree and its SPIR-V declares what its reflection says; every unit a depth pass names is written;
the binds are the permutations' own shadow textures; the matrix convention per platform follows the platform's
conventions; the renderer composes the very same depth shaders; a rebuild keeps the units, and a scene without
a shadowed light gets neither key.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
MASK_SCENE = REPO / "tests" / "scenes" / "depth_mask.toml"
EXAMPLE = REPO / "scenes" / "example.toml"
pytestmark = pytest.mark.toolchain


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _build(lib, scene_path, out):
    from generator.assemble import BuildContext, build
    from generator.scene.load import load_scene

    res = build(load_scene(scene_path, lib), out, BuildContext(lib))
    assert res.ok, res.failures
    return res, json.loads((out / "manifest.json").read_text())


@pytest.fixture(scope="module")
def built(lib, tmp_path_factory):
    out = tmp_path_factory.mktemp("depth")
    return out, _build(lib, MASK_SCENE, out)[1]


def test_every_shadowed_light_has_a_depth_pass_naming_written_units(built):
    out, m = built
    units = m["depth_shaders"]
    masked = sorted(e["hash"] for e in m["permutations"] if ";alpha=mask" in e["id"])
    assert len(masked) == 2
    assert sorted(units) == sorted(["depth", "blur", *(f"{h}.{k}" for h in masked for k in ("mask", "mask_moments"))])
    assert all(u["status"] == "ok" for u in units.values())
    sun, moon = m["lights"]["sun"]["depth_pass"], m["lights"]["moon"]["depth_pass"]
    assert sun["kind"] == "depth" and "moments" not in sun and moon["kind"] == "moments"
    assert sun["casters"]["opaque"] == {"unit": "depth", "stages": ["vert"]}
    assert moon["casters"]["opaque"] == {"unit": "depth", "stages": ["vert", "frag"]}
    assert {h: c["unit"] for h, c in sun["casters"]["masked"].items()} == {h: f"{h}.mask" for h in masked}
    assert {h: c["unit"] for h, c in moon["casters"]["masked"].items()} == {h: f"{h}.mask_moments" for h in masked}
    assert moon["moments"]["format"] == "R32G32B32A32_SFLOAT" and moon["moments"]["clear"] == [1.0, 1.0, 0.0, 1.0]
    blur = moon["moments"]["blur"]
    assert blur == {"unit": "blur", "filter": "box", "size": 5, "radius": 2, "edges": "clamp",
                    "passes": [{"axis": [0, 1]}, {"axis": [1, 0]}], "sampler_state": blur["sampler_state"]}
    row = m["samplers"][blur["sampler_state"]]  # its passes read texel centres: bilinear, clamped, level 0
    assert (row["min_filter"], row["mipmap"], row["wrap_u"], row["wrap_v"]) == ("linear", "none", "clamp", "clamp")
    for dp in (sun, moon):
        assert dp["size"] == [512, 512]
        assert dp["depth"] == {"format": "D32_SFLOAT", "clear": 1.0, "compare_op": "less", "write": True, "cull": "none",
                               "bias": {"constant": 0.0, "slope": 0.0, "clamp": 0.0}}
        named = [dp["casters"]["opaque"]["unit"], *(c["unit"] for c in dp["casters"]["masked"].values()),
                 *([dp["moments"]["blur"]["unit"]] if "moments" in dp else [])]
        assert set(named) <= set(units)
    assert sun["shader_bias"] == {"parameter": "shadow_bias", "value": 0.003}  # the scene's value
    assert moon["shader_bias"]["value"] == 0.002 and moon["shader_bias"]["min_variance"]["value"] == 2e-05


def test_a_unit_s_files_are_in_every_platform_tree_and_its_spirv_matches_its_reflection(built):
    from generator.analysis.reflect import reflect
    from generator.io import sha256

    out, m = built
    for name, u in m["depth_shaders"].items():
        assert set(u["platforms"]) == {"vulkan", "d3d12", "gl", "webgpu"}, name
        for p, d in u["platforms"].items():
            for stage, item in d["stages"].items():
                for kind, art in item.items():
                    path = art["path"] if "path" in art else None
                    if path is None:
                        continue
                    assert path.startswith(f"{'vulkan' if p == 'vulkan' else p}/"), path
                    assert sha256((out / path).read_bytes()) == art["sha256"], path
        want = {(x["set"], x["binding"], x["type"]) for x in u["platforms"]["vulkan"]["reflection"]["descriptors"]}
        inputs = [x["location"] for x in u["platforms"]["vulkan"]["reflection"]["vertex_inputs"]]
        read = set()
        for lang, stages in u["languages"].items():
            got = set()
            for stage, item in stages.items():
                entry = reflect((out / item["spirv"]).read_bytes()).entry(stage)
                got |= {(r.set, r.binding, r.kind) for r in entry.resources}
                if stage == "vert":
                    assert [v.location for v in entry.inputs] == inputs, (name, lang)
            assert got <= want, (name, lang)  # nothing read that the reflection does not declare
            read |= got
        # and nothing declared that no language reads (the blur's sampler: GLSL's texelFetch needs one, HLSL's
        # Load and WGSL's textureLoad do not)
        assert read == want, name


def test_the_binds_are_where_each_permutation_reads_the_light_s_map(built):
    out, m = built
    perms = {e["hash"]: e for e in m["permutations"]}
    for ln, index, texture, image in (("sun", 0, "shadow_map", "depth"), ("moon", 1, "shadow_moments", "moments")):
        binds = m["lights"][ln]["depth_pass"]["binds"]
        assert sorted(b["permutation"] for b in binds) == sorted(perms), ln  # every object is lit by both
        for b in binds:
            t = next(t for t in perms[b["permutation"]]["interface"]["frag"]["textures"]
                     if t.get("light") == index and t["name"] == texture)
            assert (b["set"], b["binding"], b["sampler_binding"]) == (t["set"], t["binding"], t["sampler_binding"])
            assert b["texture"] == texture and b["image"] == image and b["light_index"] == index
            # its sampler is the samplers row the permutation's reflection names at sampler_binding (one description)
            (d,) = [d for d in perms[b["permutation"]]["platforms"]["vulkan"]["reflection"]["descriptors"]
                    if (d["set"], d["binding"]) == (b["set"], b["sampler_binding"])]
            assert d["type"] == "sampler" and b["sampler_state"] == d["sampler_state"], (ln, b)
            state = m["samplers"][b["sampler_state"]]
            assert (state["mipmap"], state["wrap_u"], state["compare"]) == ("none", "clamp", None)


def test_the_matrix_convention_maps_the_brick_s_texel_on_every_platform(built):
    """A depth pass drawn with premultiply · shadow_matrix writes, on each platform, the framebuffer row and the
    window depth the brick reads back at uv = clip.xy / w · 0.5 + 0.5 and depth clip.z / w."""
    from generator.assemble.platforms import PLATFORM_TABLE
    from generator.runtime.shadow_pass import VULKAN_CONVENTIONS

    vk = PLATFORM_TABLE["vulkan"].conventions  # what the renderer (before the build stage) draws by
    assert VULKAN_CONVENTIONS == (vk.depth_range, vk.ndc_y, vk.framebuffer_origin)
    out, m = built
    mat = m["lights"]["sun"]["depth_pass"]["matrix"]
    assert mat["parameter"] == "shadow_matrix" and mat["clip"] == "vulkan"
    assert mat["fit"] == {"light_type": "directional", "projection": "orthographic", "margin": 0.02,
                          "bounds": "object_box_corners", "casters": "light_sets",
                          "function": "generator.runtime.shadow_pass.fit_shadow_matrix"}
    clip = np.array([0.3, -0.6, 0.25, 1.0])  # a point the brick reads at uv (0.65, 0.2), depth 0.25
    for p, pre in mat["premultiply"].items():
        c = PLATFORM_TABLE[p].conventions
        x, y, z, w = np.array(pre) @ clip
        ndc_y, depth_ndc = y / w, z / w
        # the API's rasterizer: NDC y → framebuffer row (from the top, or from the bottom), depth range → window z
        frac = (1 - ndc_y) / 2 if c.ndc_y == "up" else (1 + ndc_y) / 2  # from the framebuffer's top
        row_v = frac if c.framebuffer_origin == "top-left" else 1 - frac  # texture v: the map's first row is v = 0
        window_z = (depth_ndc + 1) / 2 if c.depth_range == "-1..1" else depth_ndc
        assert np.isclose(row_v, 0.2) and np.isclose(window_z, 0.25), p


def test_the_renderer_composes_the_shaders_the_build_wrote(lib, built):
    from generator.compose.depth import compose_depth_units
    from generator.io import sha256
    from generator.link import link_permutation
    from generator.runtime.shadow_pass import depth_plan, shadowed_lights
    from generator.scene.load import load_scene
    from generator.spec.resolve import resolve

    out, m = built
    scene = load_scene(MASK_SCENE, lib)
    resolved = {h: resolve(p, lib) for h, p in scene.permutations.items()}
    plan = depth_plan(shadowed_lights(scene, resolved.values()), {h: link_permutation(r, lib) for h, r in resolved.items()})
    units = compose_depth_units(plan, lib, ("glsl",))
    assert sorted(units) == sorted(m["depth_shaders"])
    for name, c in units.items():
        for s in c.sources:
            assert sha256(s.text.encode()) == m["depth_shaders"][name]["languages"]["glsl"][s.stage]["source_sha256"]


def test_a_rebuild_keeps_the_units_and_restores_a_removed_file(lib, built, tmp_path):
    out, m = built
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    victim = copy / m["depth_shaders"]["blur"]["platforms"]["webgpu"]["stages"]["frag"]["wgsl"]["path"]
    victim.unlink()
    res, again = _build(lib, MASK_SCENE, copy)
    assert victim.is_file() and again["depth_shaders"] == m["depth_shaders"]
    res, same = _build(lib, MASK_SCENE, copy)
    assert res.up_to_date and res.written == 0


def test_without_a_shadowed_light_there_is_no_depth_pass(lib, tmp_path):
    d = tmp_path / "unshadowed"
    d.mkdir()
    text = MASK_SCENE.read_text().replace('shadow = "shadow_map"', 'shadow = "none"').replace(
        'shadow = "vsm"', 'shadow = "none"').replace(", shadow_bias = 0.003", "")
    (d / "s.toml").write_text(text)
    _, m = _build(lib, d / "s.toml", tmp_path / "out")
    assert "depth_shaders" not in m and not any("depth_pass" in L for L in m["lights"].values())
    assert not list((tmp_path / "out").rglob("depth.*")), "no depth unit left in any tree"


def test_the_example_s_sun_gets_the_depth_only_pass(lib, tmp_path):
    _, m = _build(lib, EXAMPLE, tmp_path / "ex")
    assert list(m["depth_shaders"]) == ["depth"] and set(m["depth_shaders"]["depth"]["languages"]["glsl"]) == {"vert"}
    shadowed = [ln for ln, L in m["lights"].items() if "depth_pass" in L]
    assert shadowed == ["sun"] and m["lights"]["sun"]["depth_pass"]["casters"]["masked"] == {}
