"""Placement files (SCENE.placement.toml beside a scene): the example's courtyard, the row fallback, clear errors.

NumPy only, except the one CLI check at the end (it stops before any device is opened).
"""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


@pytest.fixture(scope="module")
def example(lib):
    from generator.scene.load import load_scene
    return load_scene(EXAMPLE, lib)


def test_the_example_is_a_courtyard_every_object_standing_on_a_12_by_12_ground(example):
    from generator.runtime.placement import load_placement, placement_path

    assert placement_path(EXAMPLE) == REPO / "scenes" / "example.placement.toml"
    pl = load_placement(example)
    assert pl.source == placement_path(EXAMPLE)
    assert [o.name for o in pl.objects] == [o["name"] for o in example.objects]
    by = {o.name: o for o in pl.objects}
    ground = by["ground"]
    assert ground.mesh == "plane"
    c = ground.corners()
    np.testing.assert_allclose(c[:, 1], -1.0)
    np.testing.assert_allclose([np.ptp(c[:, 0]), np.ptp(c[:, 2])], [12.0, 12.0])
    for o in pl.objects:
        if o is ground:
            continue
        c = o.corners()
        assert c[:, 1].min() == pytest.approx(-1.0), f"{o.name} stands on the ground"
        assert (np.abs(c[:, [0, 2]]) < 6.0).all(), f"{o.name} is inside the courtyard"
    assert {o.mesh for o in pl.objects} == {"plane", "sphere", "box"}
    assert len(set(by["bucket"].scale)) > 1, "one object is scaled non-uniformly (normals: the inverse transpose)"
    eye, vp = pl.camera(256, 160)
    for o in pl.objects:  # every object's centre is in view
        p = vp @ np.append(o.translate, 1.0)
        assert p[3] > 0 and (np.abs(p[:2] / p[3]) < 1.0).all() and 0 < p[2] / p[3] < 1, o.name


def test_model_is_translate_rotate_y_scale():
    from generator.runtime.placement import Placed

    o = Placed("x", "box", (1.0, 2.0, 3.0), (2.0, 1.0, 0.5), 90.0)
    np.testing.assert_allclose(o.model @ [1.0, 0.0, 0.0, 1.0], [1.0, 2.0, 1.0, 1.0], atol=1e-12)  # +x → −z
    np.testing.assert_allclose(o.model @ [0.0, 0.0, 1.0, 1.0], [1.5, 2.0, 3.0, 1.0], atol=1e-12)  # +z → +x


def test_without_a_placement_file_the_objects_stand_in_a_row(lib, tmp_path):
    from generator.scene.load import load_scene
    from generator.runtime.placement import camera, load_placement, placement

    shutil.copy(EXAMPLE, tmp_path / "bare.toml")
    scene = load_scene(tmp_path / "bare.toml", lib)
    pl = load_placement(scene)
    n = len(scene.objects)
    assert pl.source is None and {o.mesh for o in pl.objects} == {"sphere"}
    for i in range(n):
        np.testing.assert_array_equal(pl.model(i), placement(i, n))
    for a, b in zip(pl.camera(96, 48), camera(n, 96, 48)):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(Exception, match="no such placement file"):
        load_placement(scene, tmp_path / "missing.placement.toml")


GOOD = """[objects.ground]
mesh = "plane"
scale = [6.0, 1.0, 6.0]
"""
OTHERS = "".join(f"\n[objects.{n}]\nmesh = \"sphere\"\n" for n in ("bench", "statue", "bucket", "door", "chair"))

CASES = [  # (placement text, expected line:col, words of the message)
    (GOOD.replace('mesh = "plane"', 'mesh = "plane"\ncolour = 3') + OTHERS, "3:1",
     ["unknown key of objects.ground 'colour'", "known: mesh, translate, scale, rotate_y"]),
    (GOOD.replace("scale =", "scael =") + OTHERS, "3:1",
     ["unknown key of objects.ground 'scael'", "did you mean 'scale'"]),
    (GOOD.replace('"plane"', '"cube"') + OTHERS, "2:1", ["unknown mesh 'cube'", "sphere, plane, box"]),
    (GOOD.replace("[6.0, 1.0, 6.0]", "[6.0, 0.0, 6.0]") + OTHERS, "3:1", ["scale must be > 0"]),
    (GOOD.replace("[6.0, 1.0, 6.0]", "[6.0, 1.0]") + OTHERS, "3:1", ["scale must be three numbers"]),
    (GOOD + OTHERS + "\n[objects.bnech]\nmesh = \"box\"\n", "20:1", ["the scene has no object 'bnech'",
                                                                     "did you mean 'bench'"]),
    (GOOD + OTHERS.replace("[objects.chair]", "[objects.bench2]"), "17:1", ["no object 'bench2'"]),
    (GOOD + OTHERS.split("\n[objects.chair]")[0], "1:1", ["object 'chair' of the scene has no placement",
                                                          "add [objects.chair]"]),
    (GOOD + OTHERS + "\n[camera]\neye = [0, 1, 2]\nfov = 30\n", "22:1", ["unknown key of camera 'fov'",
                                                                        "did you mean 'fov_y'"]),
    (GOOD + OTHERS + "\n[camera]\nfov_y = 200\n", "21:1", ["fov_y 200.0 is not between 0 and 180"]),
    (GOOD + OTHERS + "\n[lights]\nx = 1\n", "20:2", ["unknown section 'lights'", "known: camera, objects"]),
    (GOOD.replace("mesh = ", "mesh = = ") + OTHERS, "2:8", ["TOML syntax error"]),
    (GOOD + OTHERS.replace('mesh = "sphere"\n', 'mesh = "sphere"\nrotate_y = "left"\n', 1), "7:1",
     ["rotate_y must be a number"]),
]


@pytest.mark.parametrize("text,where,words", CASES, ids=[c[2][0][:40] for c in CASES])
def test_placement_mistakes_are_path_line_col_errors_that_say_what_to_do(example, tmp_path, text, where, words):
    from generator.lang import SourceError
    from generator.runtime.placement import load_placement

    path = tmp_path / "example.placement.toml"
    path.write_text(text)
    with pytest.raises(SourceError) as e:
        load_placement(example, path)
    msg = str(e.value)
    assert msg.startswith(f"{path}:{where}: "), msg
    assert " — " in msg, f"says what to do: {msg}"
    for w in words:
        assert w in msg, msg


def test_the_render_command_reports_a_bad_placement_in_one_line(tmp_path):
    shutil.copy(EXAMPLE, tmp_path / "yard.toml")
    (tmp_path / "yard.placement.toml").write_text(GOOD.replace("scale", "size") + OTHERS)
    r = subprocess.run([sys.executable, "-m", "generator.cli", "render", str(tmp_path / "yard.toml"), "--out",
                        str(tmp_path / "out")], capture_output=True, text=True, timeout=120, cwd=REPO)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 1 and len(lines) == 1, r.stderr
    assert lines[0].startswith(f"error: {tmp_path / 'yard.placement.toml'}:3:1: unknown key of objects.ground 'size'")


def test_non_finite_placements_are_located_errors(tmp_path):
    from generator.lang import SourceError
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from generator.runtime.placement import load_placement

    lib = load_library()
    scene = load_scene(Path(__file__).resolve().parents[2] / "scenes" / "example.toml", lib)
    text = (Path(__file__).resolve().parents[2] / "scenes" / "example.placement.toml").read_text()
    for old, new, what in [("translate = [0.0, 0.0, -0.8]", "translate = [0.0, inf, -0.8]", "not finite"),
                           ("eye = [0.0, 3.4, 7.2]", "eye = [0.0, nan, 7.2]", "not finite")]:
        assert old in text
        bad = tmp_path / "p.toml"
        bad.write_text(text.replace(old, new, 1))
        with pytest.raises(SourceError, match=what):
            load_placement(scene, bad)
