"""Dynamic light sets in a TOML scene (generator/scene/light_sets.py): the key carries the set's model, not its
lights, so any number of lights of those pairs is one shader per material; every wrong entry is one located line."""
from __future__ import annotations

import pytest

from generator.lang import SourceError


def _scene(n_points: int, table: str, extra_lights: str = "") -> str:
    lights = "".join(f'[lights.p{i}]\ntype = "point"\nparams = {{ position = [{i * 0.1}, 1.0, 0.0] }}\n'
                     for i in range(n_points))
    return (f'[materials.m]\nbrdf = "lambert"\n\n{lights}{extra_lights}\n{table}\n'
            '[[objects]]\nname = "o"\nmaterial = "m"\nlights = "crowd"\n')


def _crowd(n: int, more: str = "") -> str:
    names = ", ".join(f'"p{i}"' for i in range(n))
    return f"[light_sets.crowd]\ndynamic = true\nlights = [{names}]\n{more}"


def _load(tmp_path, text):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path, load_scene(path, load_library())


def test_the_key_is_the_model_so_4_and_40_lights_are_one_shader(tmp_path):
    _, four = _load(tmp_path, _scene(4, _crowd(4)))
    _, forty = _load(tmp_path, _scene(40, _crowd(40)))  # more than a static set may hold
    assert list(four.permutations) == list(forty.permutations)
    (key,) = [p.canonical() for p in four.permutations.values()]
    assert "lights=*point/none;" in key, key
    assert forty.dynamic_sets["crowd"].max == 256  # the default capacity
    assert forty.objects[0]["lights"] == [f"p{i}" for i in range(40)]


def test_a_model_is_sorted_and_may_name_pairs_no_light_has_yet(tmp_path):
    spot = '[lights.s]\ntype = "spot"\n'
    _, scene = _load(tmp_path, _scene(2, _crowd(2, 'model = ["spot/none", "point/none"]\nmax = 8\n'), spot))
    (key,) = [p.canonical() for p in scene.permutations.values()]
    assert "lights=*point/none,*spot/none;" in key, key
    assert scene.dynamic_sets["crowd"].max == 8


def test_matrix_counts_the_model_as_one_light_configuration(tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.explain import report
    _, scene = _load(tmp_path, _scene(3, _crowd(3)))
    rep = report(scene, load_library())
    lights = [a for a in rep["axes"] if a["axis"] == "lights"]
    assert [a["value"] for a in lights] == ["*point/none"] and lights[0]["kept"]


CASES = [  # (id, table, extra lights, line of the error, words of the message)
    ("light-outside-the-model", _crowd(2, 'model = ["spot/none"]\n'), "", 13,
     "light 'p0' (point/none) is not in the model of dynamic light set 'crowd' (spot/none)"),
    ("unknown-quoted-key", _crowd(2) + '"p1" = 0\n', "", 14, "unknown key 'p1' in light set 'crowd'"),
    ("typo-in-a-key", _crowd(2, "maximum = 8\n"), "", 14, "unknown key 'maximum' in light set 'crowd'",
     "did you mean 'max'?"),
    ("pcf-past-2048-layers", "[light_sets.crowd]\ndynamic = true\nlights = []\nmodel = [\"point/pcf\"]\nmax = 400\n",
     "", 9, "point/pcf lights take 2400 shadow-map layers at max = 400", "lower max to at most 341"),
    ("pcf-in-a-switch-loop", "[light_sets.crowd]\ndynamic = true\nlights = []\nmodel = [\"point/pcf\"]\n"
     "loop = \"switch\"\n", "", 8, "a switch loop cannot shadow its lights yet", 'use loop = "types"'),
    ("malformed-model-entry", _crowd(2, 'model = ["point"]\n'), "", 14, "model entry 'point' is not TYPE/SHADOW"),
    ("unknown-type-in-model", _crowd(2, 'model = ["lamp/none"]\n'), "", 14, "unknown light type 'lamp'"),
    ("empty-model", "[light_sets.crowd]\ndynamic = true\nlights = []\nmodel = []\n", "", 14,
     "dynamic light set 'crowd' has an empty model"),
    ("max-below-the-lights", _crowd(2, "max = 1\n"), "", 14, "holds 2 lights, more than its max = 1"),
    ("max-zero", _crowd(2, "max = 0\n"), "", 14, "max is 0, not between 1 and"),
    ("max-not-whole", _crowd(2, "max = 2.5\n"), "", 14, "'light_sets.crowd.max' must be a whole number"),
    ("dynamic-false", "[light_sets.crowd]\ndynamic = false\nlights = []\n", "", 12, "only a dynamic set is"),
    ("unknown-light", _crowd(1).replace('"p0"', '"p7"'), "", 13, "names unknown light 'p7'"),
    ("not-a-list-nor-a-table", "[light_sets]\ncrowd = 3\n", "", 12, "'light_sets.crowd' must be an array or a table"),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_a_wrong_dynamic_set_is_one_located_error(case, tmp_path):
    _, table, extra, line, *words = case
    n = 2 if "pcf" not in table else 0
    text = _scene(n, table, extra)
    with pytest.raises(SourceError) as e:
        _load(tmp_path, text)
    msg = str(e.value)
    assert msg.startswith(f"{tmp_path / 'scene.toml'}:{line}:") and " — " in msg, (msg, text)
    assert all(w in msg for w in words), msg
    assert "\n" not in msg


def test_a_shadowed_light_in_a_dynamic_set_is_accepted(tmp_path):
    """Its pair reads one shadow array (tests/runtime/test_dynamic_shadows.py draws it)."""
    lamp = '[lights.lamp]\ntype = "spot"\nshadow = "shadow_map"\n'
    table = '[light_sets.crowd]\ndynamic = true\nlights = ["lamp"]\n'
    _, scene = _load(tmp_path, _scene(0, table, lamp))
    assert [k.canonical() for k in scene.dynamic_sets["crowd"].model] == ["*spot/shadow_map"]


def test_a_static_set_past_32_lights_points_at_dynamic_sets(tmp_path):
    names = ", ".join(f'"p{i}"' for i in range(33))
    with pytest.raises(SourceError) as e:
        _load(tmp_path, _scene(33, f"[light_sets]\ncrowd = [{names}]\n"))
    assert "make it dynamic" in str(e.value)


# ---------------------------------------------------------------- glTF: SCENE.lights.toml beside the scene

def _gltf(tmp_path, sidecar: str | None):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from tests.scene.test_gltf import sample_doc
    path = sample_doc(extra_lights=True).write_gltf(tmp_path / "model.gltf")
    if sidecar is not None:
        (tmp_path / "model.lights.toml").write_text(sidecar)
    return load_scene(path, load_library(()))


def test_a_gltf_lights_file_gives_shadows_and_a_dynamic_set(tmp_path):
    static = _gltf(tmp_path, None)
    assert [static.lights[n].shadow for n in ("sun", "bulb", "torch")] == ["none"] * 3 and not static.dynamic_sets
    shadowed = _gltf(tmp_path, '[lights.sun]\nshadow = "pcf"\n')
    assert shadowed.lights["sun"].shadow == "pcf" and "lights=directional/pcf," in next(
        iter(shadowed.permutations.values())).canonical()
    dyn = _gltf(tmp_path, '[light_set]\ndynamic = true\nmax = 16\nmodel = ["spot/none", "directional/none", '
                          '"point_range/none", "point/none"]\n')
    assert dyn.dynamic_sets["main"].max == 16
    keys = {p.canonical().split(";")[1] for p in dyn.permutations.values()}
    assert keys == {"lights=*directional/none,*point/none,*point_range/none,*spot/none"}
    assert [str(p) for p in dyn.extra["inputs"]] == [str(tmp_path / "model.lights.toml")]


@pytest.mark.parametrize("sidecar, line, words", [
    ('[lights.sunn]\nshadow = "pcf"\n', 1, ["the glTF scene has no light 'sunn'", "did you mean 'sun'?"]),
    ('[lights.sun]\nshadows = "pcf"\n', 2, ["unknown key 'shadows' in [lights.sun]", "did you mean 'shadow'?"]),
    ('[light_set]\ndynamic = true\nmaxx = 4\n', 3, ["unknown key 'maxx' in [light_set]", "did you mean 'max'?"]),
    ('[light_set]\ndynamic = true\nmodel = ["point/none"]\n', 3, ["light 'sun' (directional/none) is not in the model"]),
    ('[lights.sun]\nshadow = "pcf"\n[light_set]\ndynamic = true\nmax = 4000\n', 5,
     ["directional/pcf lights take 4000 shadow-map layers", "lower max to at most 2048"]),
    ('[light_set]\nmax = 4\n', 2, ["'max' is for a dynamic light set"]),
    ('[light_set]\ndynamic = true\nmax = 2\n', 3, ["holds 3 lights, more than its max = 2"]),
])
def test_a_wrong_gltf_lights_file_is_one_located_error(tmp_path, sidecar, line, words):
    with pytest.raises(SourceError) as e:
        _gltf(tmp_path, sidecar)
    msg = str(e.value)
    assert msg.startswith(f"{tmp_path / 'model.lights.toml'}:{line}:") and " — " in msg, msg
    assert all(w in msg for w in words), msg


@pytest.mark.toolchain
def test_a_new_max_or_light_reaches_the_manifest_though_no_shader_changes(tmp_path):
    """max and the set's lights are not in any key: a rebuild that composes nothing still describes them anew."""
    import json

    from generator.assemble import BuildContext, build
    from generator.io import Store
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib, out = load_library(), tmp_path / "out"
    for n, cap in ((2, 8), (2, 16), (3, 16)):
        path = tmp_path / "scene.toml"
        path.write_text(_scene(n, _crowd(n, f"max = {cap}\n")))
        build(load_scene(path, lib), out, BuildContext(lib, platforms=("vulkan",), store=Store(tmp_path / "cache")))
        table = json.loads((out / "manifest.json").read_text())["dynamic_light_sets"]["crowd"]
        assert table["max"] == cap and table["pairs"][0]["lights"] == [f"p{i}" for i in range(n)], table
