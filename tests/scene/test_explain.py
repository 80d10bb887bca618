"""`shadermatrix matrix SCENE [--explain]`: the pruning stages, and the constraints' truth table."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from generator.library.bricks import load_library
from generator.spec.constraints import CONSTRAINTS
from generator.scene.explain import violations
from generator.spec.permutation import Permutation

REPO = Path(__file__).resolve().parents[2]

LAMBERT_COPY = '''"""A Lambert copy (test)."""
BRICK = {"kind": "diffuse", "cite": "test",
         "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5]}}}


def diffuse(rho_d: vec3) -> vec3:
    return rho_d * INV_PI
'''
TANGENT_READER = '''"""A diffuse term that reads the tangent (test)."""
BRICK = {"kind": "diffuse", "cite": "test",
         "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5]}}}


def diffuse(LdotT: float, rho_d: vec3) -> vec3:
    return rho_d * (INV_PI * (1.0 + 0.0 * LdotT))
'''
FLOAT_ALBEDO = '''"""A packing that gives rho_d as a float (test)."""
BRICK = {"kind": "packing", "cite": "test", "slots": {"normal": {"kind": "normal", "default": "vertex"}}}


def get_rho_d(uv: vec2) -> float:
    return 0.5
'''


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    d = tmp_path_factory.mktemp("bricks")
    (d / "lam_a.py").write_text(LAMBERT_COPY)
    (d / "lam_b.py").write_text(LAMBERT_COPY)
    (d / "aniso_probe.py").write_text(TANGENT_READER)
    (d / "float_albedo.py").write_text(FLOAT_ALBEDO)
    return load_library([d])


# (brdf, packing) -> the constraints it breaks: which permutations must and must not exist
TRUTH = [
    ("lambert", "constants", []),
    ("lambert", "albedo_texture", []),
    ("lambert+blinn_phong_normalized", "albedo_texture(normal=normal_map)", []),
    ("microfacet", "constants", []),
    ("microfacet", "albedo_texture", ["packing-provides-unread"]),
    ("blinn_phong_normalized", "albedo_texture", ["packing-provides-unread"]),
    ("aniso_probe", "constants", ["tangent-frame"]),
    ("aniso_probe", "albedo_texture", ["tangent-frame"]),
    ("aniso_probe", "albedo_texture(normal=vertex_tangent)", []),
    ("aniso_probe", "albedo_texture(normal=normal_map)", []),
    ("lambert", "float_albedo", ["packing-type"]),
    ("microfacet", "float_albedo", ["packing-provides-unread"]),
]


@pytest.mark.parametrize("brdf,packing,broken", TRUTH, ids=lambda x: str(x))
def test_constraints_truth_table(lib, brdf, packing, broken):
    assert [name for name, _why in violations(Permutation(brdf, (), packing), lib)] == broken


def test_every_constraint_is_in_the_truth_table():
    named = {c for _b, _p, broken in TRUTH for c in broken}
    assert named == {c.name for c in CONSTRAINTS}


SCENE = '''[scene]
name = "m"

[materials.a]
brdf = "lam_a"

[materials.b]
brdf = "lam_b"

[materials.unused]
brdf = "lambert"
packing = "albedo_texture"

[lights.sun]
type = "directional"

[lights.lamp]
type = "point"

[light_sets]
day = ["sun"]
night = ["lamp"]

[[objects]]
name = "one"
material = "a"
lights = "day"

[[objects]]
name = "two"
material = "b"
lights = "day"
'''


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "generator.cli", "matrix", *map(str, args)], cwd=REPO,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.toolchain
def test_matrix_counts_every_stage_and_explains_every_value(tmp_path):
    bricks = tmp_path / "bricks"
    bricks.mkdir()
    (bricks / "lam_a.py").write_text(LAMBERT_COPY)
    (bricks / "lam_b.py").write_text(LAMBERT_COPY)
    scene = tmp_path / "m.toml"
    scene.write_text(SCENE)
    r = _cli(scene, "--bricks", bricks, "--explain", "--format", "json", "--cache-dir", tmp_path / "cache")
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    counts = {s["stage"]: s["count"] for s in rep["stages"]}
    # 3 BRDFs × 2 packings × 2 light configurations; all valid; 2 drawn; lam_a and lam_b compile to one shader
    assert counts == {"full product": 12, "valid": 12, "used": 2, "merged": 1}
    why = {(v["axis"], v["value"]): v for v in rep["axes"]}
    assert not why[("brdf", "lambert")]["kept"] and "unused" in why[("brdf", "lambert")]["why"]
    assert not why[("lights", "point/none")]["kept"] and "night" in why[("lights", "point/none")]["why"]
    assert why[("brdf", "lam_a")]["kept"] and "one" in why[("brdf", "lam_a")]["why"]
    perms = {p["materials"][0]: p for p in rep["permutations"]}
    assert perms["b"]["merged_into"] == perms["a"]["hash"] and perms["b"]["objects"] == ["two"]
    md = _cli(scene, "--bricks", bricks, "--explain", "--no-compile")
    assert md.returncode == 0 and "| used | 2 |" in md.stdout and "merged" not in md.stdout.split("##")[0]
    assert "## Axis values" in md.stdout and "dropped: light set(s) night" in md.stdout


def test_surface_states_are_an_axis_of_the_matrix(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE.replace('[lights.lamp]', '[materials.c]\nbrdf = "lambert"\nalpha = "mask"\n'
                                   'double_sided = true\n\n[lights.lamp]'))
    bricks = tmp_path / "bricks"
    bricks.mkdir()
    (bricks / "lam_a.py").write_text(LAMBERT_COPY)
    (bricks / "lam_b.py").write_text(LAMBERT_COPY)
    r = _cli(scene, "--bricks", bricks, "--explain", "--format", "json", "--no-compile")
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    surface = {v["value"]: v for v in rep["axes"] if v["axis"] == "surface"}
    assert set(surface) == {"default", "alpha=mask;double_sided=true"}
    assert surface["default"]["kept"] and not surface["alpha=mask;double_sided=true"]["kept"]
    assert "c" in surface["alpha=mask;double_sided=true"]["why"]
    assert {s["stage"]: s["count"] for s in rep["stages"]}["full product"] == 3 * 2 * 2 * 2


def test_matrix_of_the_example_lists_the_forbidden_pairs():
    r = _cli(REPO / "scenes" / "example.toml", "--explain", "--no-compile")
    assert r.returncode == 0, r.stderr
    assert "| full product | 30 |" in r.stdout and "| used | 5 |" in r.stdout
    assert "packing-provides-unread: packing 'albedo_texture' provides rho_d" in r.stdout
