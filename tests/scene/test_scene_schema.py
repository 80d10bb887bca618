"""Scene files against their schema: every wrong key or type is one located line with what to do,
checked before any value is interpreted (generator/scene/schema.py); each case below was a traceback, or a
scene accepted that builds something else."""
from __future__ import annotations

from pathlib import Path

import pytest

from generator.lang import SourceError

REPO = Path(__file__).resolve().parents[2]
BASE = (REPO / "scenes" / "example.toml").read_text()

CASES = [  # (id, what replaces what, line of the error, words of the message)
    ("material-is-a-list", ('material = "painted_wood"', "material = ['a']"), 50,
     "'objects.0.material' must be a string, not an array"),
    ("scene-is-a-number", ('[scene]\nname = "courtyard"\noutput = "linear"\nprecision = "fp32"', "scene = 1"), 1,
     "'scene' must be a table, not a number"),
    ("output-is-a-list", ('output = "linear"', "output = []"), 6, "'scene.output' must be a string, not an array"),
    ("object-name-is-a-number", ('name = "bench"', "name = 5"), 49, "'objects.0.name' must be a string, not a number"),
    ("scene-name-is-a-date", ('name = "courtyard"', "name = 1979-05-27"), 5, "must be a string, not a date or time"),
    ("typo-in-scene", ('output = "linear"', 'ouput = "linear"'), 6, "unknown key 'ouput' in [scene]",
     "did you mean 'output'?"),
    ("typo-in-light", ('shadow = "shadow_map"', 'shadows = "shadow_map"'), 33, "unknown key 'shadows' in [lights.sun]",
     "did you mean 'shadow'?"),
    ("duplicate-object-names", ('name = "ground"', 'name = "bench"'), 54, "object name 'bench' is used twice"),
    ("second-shadow-dropped", ('shadow = "shadow_map"', 'shadow = "shadow_map+none"'), 33,
     "a shadow filter is one brick, and 'shadow_map+none' names 2"),
    ("params-not-a-table", ('params = { alpha = 0.15, f0 = [1.0, 0.71, 0.29] }', 'params = "x"'), 20,
     "'materials.polished_gold.params' must be a table, not a string"),
    ("param-is-a-boolean", ("alpha = 0.15", "alpha = true"), 20, "must be a number or an array of numbers"),
    ("light-set-not-a-list", ('outdoor = ["sun", "lamp"]', "outdoor = 3"), 45, "'light_sets.outdoor' must be an array"),
    ("control-character-in-a-name", ('name = "bench"', 'name = "be\\u2028nch"'), 49, "holds a control character"),
    ("param-is-nan", ("alpha = 0.15", "alpha = nan"), 20, "parameter 'alpha': nan is not a finite float32 number"),
    ("param-holds-inf", ("f0 = [1.0, 0.71, 0.29]", "f0 = [1.0, inf, 0.29]"), 20,
     "parameter 'f0': inf is not a finite float32 number"),
    ("param-past-float32", ("alpha = 0.15", "alpha = 1e39"), 20, "1e+39 is not a finite float32 number"),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_a_malformed_scene_is_one_located_error(case, tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    _, (old, new), line, *words = case
    assert old in BASE
    path = tmp_path / "scene.toml"
    path.write_text(BASE.replace(old, new, 1))
    with pytest.raises(SourceError) as e:
        load_scene(path, load_library())
    text = str(e.value)
    assert text.startswith(f"{path}:{line}:") and " — " in text, text
    assert all(w in text for w in words), text
    assert "\n" not in text


def test_deeply_nested_toml_is_one_located_error(tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    path = tmp_path / "deep.toml"
    path.write_text("x = " + "[" * 2000 + "]" * 2000 + "\n")
    with pytest.raises(SourceError) as e:
        load_scene(path, load_library())
    assert "nests arrays or tables too deeply" in str(e.value)


def test_an_array_parameter_is_an_array_of_vectors_in_a_scene(tmp_path):
    """A brick parameter with a count (tests/bricks/link/specular/lobes.py) takes one vector per element."""
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    path = tmp_path / "lobes.toml"
    path.write_text('[materials.m]\nbrdf = "lobes(lobes=2)"\nparams = { lobes = [[-1.0, 1.0, 8.0, 0.5], '
                    '[0.0, 1.0, 16.0, 0.25], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]] }\n[lights.s]\ntype = "point"\n[light_sets]\na = ["s"]\n'
                    '[[objects]]\nname = "o"\nmaterial = "m"\nlights = "a"\n')
    scene = load_scene(path, load_library([REPO / "tests" / "bricks" / "link"]))
    assert scene.materials["m"].params["lobes"][1] == [0.0, 1.0, 16.0, 0.25]


def test_a_name_with_a_trailing_line_break_is_refused(tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    path = tmp_path / "nl.toml"
    path.write_text(BASE.replace('name = "bench"', 'name = "bench\\n"', 1))
    with pytest.raises(SourceError) as e:
        load_scene(path, load_library())
    assert "control character or a line break" in str(e.value) and "\n" not in str(e.value)


def test_the_shipped_scenes_pass_the_schema():
    import tomllib

    from generator.scene.schema import SCENE_SCHEMA
    from jsonschema import Draft202012Validator
    Draft202012Validator.check_schema(SCENE_SCHEMA)
    for p in [REPO / "scenes" / "example.toml", REPO / "tests" / "scenes" / "shadow.toml"]:
        assert not list(Draft202012Validator(SCENE_SCHEMA).iter_errors(tomllib.loads(p.read_text())))


def test_a_light_set_past_the_limit_is_one_located_error(tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import MAX_LIGHTS_PER_SET, load_scene

    n = MAX_LIGHTS_PER_SET + 1
    lights = "".join(f'[lights.l{i}]\ntype = "point"\n' for i in range(n))
    names = ", ".join(f'"l{i}"' for i in range(n))
    path = tmp_path / "many.toml"
    path.write_text(f'[materials.m]\nbrdf = "lambert"\n{lights}[light_sets]\nmany = [{names}]\n'
                    '[[objects]]\nname = "o"\nmaterial = "m"\nlights = "many"\n')
    with pytest.raises(SourceError) as e:
        load_scene(path, load_library())
    assert f"light set 'many' has {n} lights, more than the {MAX_LIGHTS_PER_SET}" in str(e.value)
    assert str(e.value).startswith(f"{path}:{4 + 2 * n}:")  # the line of many = [...]


TOML_FORMS = [  # (id, what replaces what, the line:col of the error) — each was located at 1:1 before
    ("params-sub-table", ('params = { alpha = 0.15, f0 = [1.0, 0.71, 0.29] }',
                          '[materials.polished_gold.params]\nalpha = 0.15\nrougness = 0.3'), "22:1"),
    ("dotted-key", ('params = { alpha = 0.15, f0 = [1.0, 0.71, 0.29] }', 'params.alpha = 0.15\nparams.rougness = 0.3'),
     "21:8"),
    ("quoted-table-name", ('[materials.polished_gold]\nbrdf', '[materials."polished_gold"]\nshadows = 1\nbrdf'), "19:1"),
]


@pytest.mark.parametrize("case", TOML_FORMS, ids=[c[0] for c in TOML_FORMS])
def test_errors_in_other_toml_forms_are_located_at_the_key(case, tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    _, (old, new), where = case
    assert old in BASE
    path = tmp_path / "scene.toml"
    path.write_text(BASE.replace(old, new, 1))
    with pytest.raises(SourceError) as e:
        load_scene(path, load_library())
    assert str(e.value).startswith(f"{path}:{where}: "), str(e.value)


def test_the_first_error_reported_is_the_first_in_the_file(tmp_path):
    """Two violations: the one nearer the top is reported, whatever the order of the schema's key paths."""
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    path = tmp_path / "scene.toml"
    text = BASE.replace('name = "bench"', 'name = "bench"\ncolour = 1')  # objects come after materials in the file
    text = text.replace('shadow = "shadow_map"', 'shadows = "shadow_map"')  # [lights.sun], before the objects
    objects_first = "[[objects]]\n" + text.split("[[objects]]\n", 1)[1]
    text = objects_first + "\n" + text.split("[[objects]]\n", 1)[0]  # now the objects come first
    path.write_text(text)
    with pytest.raises(SourceError) as e:
        load_scene(path, load_library())
    assert "unknown key 'colour' in object 1" in str(e.value), str(e.value)


def test_loading_is_linear_in_the_objects(tmp_path, monkeypatch):
    """10,000 objects over five permutations: the scene's text is indexed once, an object's position is looked up
    only for the first object of each permutation (and for errors), and plain objects skip jsonschema (it walked
    every object: 1 s of the 10,000). Counted, not timed: benchmarks/build.py times it."""
    from generator.library.bricks import load_library
    from generator.scene import schema
    from generator.scene.load import Locator, load_scene

    head, rest = BASE.split("[[objects]]", 1)
    objects = ["[[objects]]" + o for o in ("[[objects]]" + rest).split("[[objects]]")[1:]]
    text = head + "".join(o.replace('name = "', f'name = "n{i}_', 1)
                          for i, o in enumerate(objects[k % len(objects)] for k in range(10_000)))
    path = tmp_path / "big.toml"
    path.write_text(text)
    calls = {"find": 0, "validated": 0}
    find, plain = Locator.find, schema._plain_object

    def counted_find(self, *a, **k):
        calls["find"] += a[0] == "objects"  # the materials' and lights' keys are looked up once each
        return find(self, *a, **k)

    def counted_plain(o):
        calls["validated"] += not plain(o)
        return plain(o)
    monkeypatch.setattr(Locator, "find", counted_find)
    monkeypatch.setattr(schema, "_plain_object", counted_plain)
    scene = load_scene(path, load_library())
    assert len(scene.objects) == 10_000 and len(scene.permutations) == 5
    assert calls == {"find": 5, "validated": 0}
    assert {h: text.splitlines()[line - 1] for h, (line, _) in scene.where.items()} == {
        o["permutation"]: f'material = "{o["material"]}"' for o in reversed(scene.objects)}
