"""Lights in a buffer get shadows: a dynamic set's shadowed pairs read one 2D array per (pair, filter texture), each
light its layers (one for a spot or directional light, six for a point light's faces), its first layer and
matrices in its buffer element; drawn on lavapipe with the validation layer on.

The scene (tests/runtime/test_dynamic_lights.py's floor and ball, plus two boxes): four spot lights with pcf, two
point lights with pcf (six layers each), or two spots, a point light and a directional light with pcf, shadow_map,
vsm and pcf_hardware, as a static set and as a dynamic one: both draw the same frame within the dynamic tests'
tolerance (1 LSB on at most 1 % of channels), in the specialized path and (spots, points) the ubershader and
hybrid, and the shadows are there (the frame differs from the same lights with shadow = "none"). A max whose layers would
exceed 2048 (Vulkan's guaranteed maxImageArrayLayers) is refused at the set's max; the build's element layout holds
the matrices and the first layer, and light k of a pair starts at layer k × its layers.

Measured on lavapipe (Mesa 25), 64 × 40, 128² maps: static and dynamic identical (maximum difference 0) for every
set and mode; without shadows 1,086 (four spots) and 2,346 (mixed) channels differ by more than 8; with every
light's first layer 0, the four spots differ by up to 90 on 1,218 channels.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from generator.lang import SourceError
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]
REPO = Path(__file__).resolve().parents[2]
W, H = 64, 40
SHADOW = 128

SPOTS = [("spot", "pcf", f"position = [{x}, 3.0, {z}], direction = [{-x / 3:.3f}, -1.0, {-z / 3:.3f}], "
          "color = [4.0, 4.0, 4.0], radius = 50.0, inner_angle = 0.5, outer_angle = 0.6, shadow_bias = 0.003")
         for x, z in ((1.5, 1.0), (-1.5, 1.0), (1.5, -1.0), (-1.5, -1.0))]
POINTS = [("point", "pcf", f"position = [{x}, 2.0, 0.3], color = [3.0, 3.0, 3.0]") for x in (-1.0, 1.0)]
MIXED = [SPOTS[0], ("spot", "shadow_map", SPOTS[1][2]),
         ("point", "vsm", "position = [0.3, 2.2, -1.2], color = [3.0, 3.0, 3.0]"),
         ("directional", "pcf_hardware", "direction = [0.4, 1.0, 0.3], color = [0.4, 0.4, 0.4], shadow_bias = 0.01")]


def _scene(lights, dynamic: bool, shadows: bool = True, extra: str = "") -> str:
    out = ['[materials.grey]\nbrdf = "lambert"\nparams = { rho_d = [0.8, 0.8, 0.8] }\n']
    for i, (ty, sh, params) in enumerate(lights):
        if not shadows:
            sh = "none"
            params = ", ".join(p for p in params.split(", ") if not p.startswith("shadow_bias"))
        out.append(f'[lights.l{i}]\ntype = "{ty}"\nshadow = "{sh}"\nparams = {{ {params} }}\n')
    names = ", ".join(f'"l{i}"' for i in range(len(lights)))
    if dynamic:
        out.append(f'[light_sets.all]\ndynamic = true\nlights = [{names}]\nmax = 8\n{extra}')
    else:
        out.append(f"[light_sets]\nall = [{names}]\n")
    for name in ("floor", "ball", "box0", "box1"):
        out.append(f'[[objects]]\nname = "{name}"\nmaterial = "grey"\nlights = "all"\n')
    return "\n".join(out)


PLACEMENT = ('[objects.floor]\nmesh = "plane"\nscale = [4.0, 1.0, 4.0]\n[objects.ball]\nmesh = "sphere"\n'
             'translate = [0.0, 0.8, 0.0]\nscale = 0.5\n[objects.box0]\nmesh = "box"\ntranslate = [1.0, 0.4, 0.6]\n'
             'scale = 0.3\n[objects.box1]\nmesh = "box"\ntranslate = [-1.1, 0.5, -0.7]\nscale = 0.3\n'
             '[camera]\neye = [0.0, 6.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n')


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _render(lib, device, d, text, mode="specialized"):
    from PIL import Image

    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene
    d.mkdir(parents=True, exist_ok=True)
    (d / "s.toml").write_text(text)
    (d / "s.placement.toml").write_text(PLACEMENT)
    scene = load_scene(d / "s.toml", lib)
    rep = render_scene(scene, lib, mode, 1, d / "out", (W, H), device=device, shadow_size=SHADOW)
    return scene, np.asarray(Image.open(d / "out" / "frame_0000.png").convert("RGBA")).astype(int), rep


def _agree(a, b, what):
    diff = np.abs(a - b)
    assert diff.max() <= 1 and (diff > 0).mean() <= 0.01, f"{what}: max {diff.max()}, {(diff > 0).sum()} channels"


@pytest.mark.parametrize("lights", [SPOTS, POINTS, MIXED], ids=["four_spots", "two_points", "mixed"])
def test_shadowed_buffer_lights_draw_what_the_static_set_draws(lib, device, tmp_path, lights):
    _, static, _ = _render(lib, device, tmp_path / "static", _scene(lights, False))
    scene, dyn, rep = _render(lib, device, tmp_path / "dynamic", _scene(lights, True))
    assert scene.dynamic_sets["all"], "the set is dynamic"
    assert set(rep.shadow_maps) == {f"l{i}" for i in range(len(lights))}
    _agree(static, dyn, "static and dynamic")
    _, unshadowed, _ = _render(lib, device, tmp_path / "none", _scene(lights, True, shadows=False))
    assert (np.abs(unshadowed - dyn) > 8).sum() > 100, "the shadows are drawn"


@pytest.mark.parametrize("lights", [SPOTS, POINTS], ids=["four_spots", "two_points"])
def test_the_ubershader_and_hybrid_draw_them_alike(lib, device, tmp_path, lights):
    """The ubershader gives a pair's lights one shadow-map slot, its array, each light's first layer in ids.w."""
    _, static, _ = _render(lib, device, tmp_path / "static", _scene(lights, False))
    for mode in ("ubershader", "hybrid"):
        _, dyn, _ = _render(lib, device, tmp_path / mode, _scene(lights, True), mode)
        _agree(static, dyn, mode)


def test_the_element_holds_the_matrices_and_the_first_layer(lib, tmp_path):
    """The build's element of a point/pcf pair: six matrices and the first layer; light k starts at 6k (no GPU)."""
    from generator.link import link_permutation
    from generator.link.values import first_layer, light_buffers
    from generator.scene.load import load_scene

    d = tmp_path
    lights = [("point", "pcf", f"position = [{x}, 2.0, 0.0], color = [1.0, 1.0, 1.0]") for x in (-1.0, 0.0, 1.0)]
    (d / "s.toml").write_text(_scene(lights, True))
    scene = load_scene(d / "s.toml", lib)
    h = scene.objects[0]["permutation"]
    lp = link_permutation(scene.permutations[h], lib)
    blk = lp.interface.block("LightBuffer0")
    names = [s.param for s in blk.slots]
    assert "shadow_first_layer" in names
    assert [n for n in names if n.startswith("shadow_matrix")] == ["shadow_matrix"] + [f"shadow_matrix_{k}" for k in
                                                                                     range(1, 6)]
    tex, = [t for t in lp.interface.textures if t.group == "light"]
    assert tex.dim == "2d_array"
    first = next(s for s in blk.slots if s.param == "shadow_first_layer")
    data = np.frombuffer(light_buffers(scene, scene.objects[0]["lights"], scene.dynamic_sets["all"], lp)["LightBuffer0"],
                         np.float32).reshape(3, -1)
    assert data[:, first.offset // 4].tolist() == [0.0, 6.0, 12.0]
    assert [first_layer(scene, f"l{k}") for k in range(3)] == [0.0, 6.0, 12.0], "the manifest's params say the same"


def test_a_set_whose_shadow_layers_exceed_2048_is_refused_at_its_max(lib, tmp_path):
    from generator.scene.load import load_scene

    lights = [("point", "pcf", "position = [0.0, 2.0, 0.0], color = [1.0, 1.0, 1.0]")]
    text = _scene(lights, True).replace("max = 8", "max = 400")
    (tmp_path / "s.toml").write_text(text)
    with pytest.raises(SourceError) as e:
        load_scene(tmp_path / "s.toml", lib)
    row = next(i for i, x in enumerate(text.splitlines()) if x.startswith("max = 400")) + 1
    assert str(e.value).startswith(f"{tmp_path / 's.toml'}:{row}:"), e.value
    assert "2400 shadow-map layers" in str(e.value) and "lower max to at most 341" in str(e.value)


def test_the_manifest_says_where_each_buffer_light_lies_in_its_pair_s_array(lib, tmp_path):
    """The build's depth pass of each light of the mixed dynamic set: its pair's index, its first layer and layers,
    the array's capacity and bytes at the contract's size; the manifest passes its schema."""
    import json

    import jsonschema

    from generator.assemble import BuildContext, build
    from generator.runtime.shadow_pass import SHADOW_SIZE
    from generator.scene.load import load_scene

    (tmp_path / "s.toml").write_text(_scene(MIXED, True))
    (tmp_path / "s.placement.toml").write_text(PLACEMENT)
    build(load_scene(tmp_path / "s.toml", lib), tmp_path / "out", BuildContext(lib))
    m = json.loads((tmp_path / "out" / "manifest.json").read_text())
    schema = json.loads((REPO / "generator" / "assemble" / "manifest.schema.json").read_text())
    assert not list(jsonschema.Draft202012Validator(schema).iter_errors(m))
    point, = [b for b in m["lights"]["l2"]["depth_pass"]["binds"]]
    assert point["array"] == {"first_layer": 0, "layers": 6, "capacity_layers": 48,
                              "capacity_bytes": 48 * SHADOW_SIZE ** 2 * 16}, "vsm: RGBA32F moments"
    assert m["lights"]["l2"]["depth_pass"]["faces"]["layers"] == 6
    spot = m["lights"]["l0"]["depth_pass"]["binds"][0]
    assert spot["array"]["layers"] == 1 and spot["array"]["capacity_bytes"] == 8 * SHADOW_SIZE ** 2 * 4


def test_a_light_of_two_sets_has_each_set_s_first_layer(lib, tmp_path):
    """Two dynamic sets of the same three pcf spots in opposite orders: each pair's first_layers is its set's
    (what its buffer holds), and a rebuild that composes nothing (only max changed) recomputes them."""
    import json

    from generator.assemble import BuildContext, build
    from generator.link.values import light_buffers
    from generator.scene.load import load_scene

    text = _scene(SPOTS[:3], True).replace(
        '[[objects]]\nname = "box1"\nmaterial = "grey"\nlights = "all"\n',
        '[[objects]]\nname = "box1"\nmaterial = "grey"\nlights = "back"\n')
    text = text.replace("max = 8\n", 'max = 8\n\n[light_sets.back]\ndynamic = true\nlights = ["l2", "l1", "l0"]\n'
                        "max = 8\n", 1)
    assert 'lights = "back"' in text and "[light_sets.back]" in text
    (tmp_path / "s.toml").write_text(text)
    (tmp_path / "s.placement.toml").write_text(PLACEMENT)

    def manifest():
        build(load_scene(tmp_path / "s.toml", lib), tmp_path / "out", BuildContext(lib))
        return json.loads((tmp_path / "out" / "manifest.json").read_text())

    m = manifest()
    sets = m["dynamic_light_sets"]
    assert sets["all"]["pairs"][0]["lights"] == ["l0", "l1", "l2"] and sets["all"]["pairs"][0]["first_layers"] == [0, 1, 2]
    assert sets["back"]["pairs"][0]["lights"] == ["l2", "l1", "l0"] and sets["back"]["pairs"][0]["first_layers"] == [0, 1, 2]
    # the light's own entry says its first set's layer; the pair's first_layers is what an engine writes
    assert m["lights"]["l0"]["params"]["shadow_first_layer"] == 0 and sets["back"]["pairs"][0]["lights"][2] == "l0"
    # what each set's buffer holds in shadow_first_layer: its pair's first_layers, light by light
    scene = load_scene(tmp_path / "s.toml", lib)
    from generator.link import link_permutation
    for set_name in ("all", "back"):
        obj = next(o for o in scene.objects if o["light_set"] == set_name)
        lp = link_permutation(scene.permutations[obj["permutation"]], lib)
        blk = lp.interface.block("LightBuffer0")
        at = next(s for s in blk.slots if s.param == "shadow_first_layer").offset // 4
        data = np.frombuffer(light_buffers(scene, obj["lights"], scene.dynamic_sets[set_name], lp)["LightBuffer0"],
                             np.float32).reshape(3, -1)
        assert data[:, at].tolist() == sets[set_name]["pairs"][0]["first_layers"]
    (tmp_path / "s.toml").write_text(text.replace('"l0"]\nmax = 8\n', '"l0"]\nmax = 4\n'))
    again = manifest()["dynamic_light_sets"]
    assert again["back"]["max"] == 4 and again["back"]["pairs"][0]["first_layers"] == [0, 1, 2]
