"""spec.resolve: a permutation resolved once into a frozen value, and errors located where it was asked for."""
from __future__ import annotations

import copy
import dataclasses
import sys
from pathlib import Path

import pytest

from generator.lang import SourceError
from generator.library.bricks import load_library
from generator.scene.load import load_scene
from generator.spec.params import spec_params
from generator.spec.permutation import LightKey, Permutation
from generator.spec.resolve import resolve

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
PERM = Permutation("lambert+microfacet(ndf=beckmann)", (LightKey("directional", "shadow_map"), LightKey("point", "none")),
                   "albedo_texture(normal=normal_map)")


@pytest.fixture(scope="module")
def lib():
    return load_library()


def _line_of(path: Path, text: str) -> int:
    return next(i + 1 for i, line in enumerate(path.read_text().splitlines()) if line.strip() == text)


def test_a_resolved_permutation_is_frozen(lib):
    r = resolve(PERM, lib)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.key = "brdf=lambert"
    with pytest.raises(TypeError, match="frozen"):
        r.brdf_params["alpha"] = None
    with pytest.raises(TypeError, match="frozen"):
        r.lights[0].params.pop("color")
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.brdf[0].fillers = ()


def test_it_holds_what_the_key_means(lib):
    r = resolve(PERM, lib)
    assert r.key == PERM.canonical() and r.hash == PERM.hash
    assert r.brdf_key == "lambert+microfacet(ndf=beckmann,fresnel=schlick,vis=smith_schlick)"
    assert list(r.brdf_params) == ["rho_d", "alpha", "f0"] and list(r.output_params) == []
    assert r.brdf_params.flat[0][:2] == ("rho_d", "rho_d")
    assert [lt.brick.id for lt in r.lights] == ["directional", "point"] and r.lights[0].textures == ("shadow_map",)
    assert "shadow_bias" in r.lights[0].params and "shadow_bias" in r.lights[0].shadow_params
    assert "direction" in r.lights[0].light_params and "shadow_bias" not in r.lights[0].light_params
    assert set(r.textures) == {"albedo_map", "normal_map"} and r.normal.brick.id == "normal_map"
    assert r.problems == () and r.tangent == () and r.packing_tangent


def test_it_is_computed_once(lib):
    r = resolve(PERM, lib)
    assert resolve(PERM, lib) is r
    assert resolve(dataclasses.replace(PERM), lib) == r  # an equal key made again: the same value
    # a brick replaced in the library since: resolved again, with the new brick
    edited = copy.copy(lib.bricks[("ndf", "beckmann")])
    other = load_library()
    r1 = resolve(PERM, other)
    other.bricks[("ndf", "beckmann")] = edited
    r2 = resolve(PERM, other)
    assert r2 is not r1 and r2.brdf[1].fillers[0][1].brick is edited


def test_the_parameter_policy_runs_once_per_permutation_during_one_compose():
    from generator.compose import compose_permutation

    code = spec_params.__code__
    callers = []

    def profile(frame, event, arg):
        if event == "call" and frame.f_code is code:
            callers.append(frame.f_back.f_code.co_filename)

    lib = load_library()  # nothing resolved yet
    sys.setprofile(profile)
    try:
        compose_permutation(PERM, lib, ("glsl",))
        once = len(callers)
        compose_permutation(PERM, lib, ("hlsl",))
    finally:
        sys.setprofile(None)
    assert once == 1, callers
    assert len(callers) == 1  # the second compose reads the resolved value
    assert all(Path(c).parent.name == "spec" for c in callers), callers


def test_a_link_error_names_the_scene_key_that_asked_for_the_permutation(lib):
    """The example's painted_wood samples albedo_map, and a shade kernel binds no textures: before, the error
    pointed at "<key>":1:1; now at the material's packing key."""
    from generator.compose import compose_shade_kernel

    scene = load_scene(EXAMPLE, lib)
    h = next(o["permutation"] for o in scene.objects if o["material"] == "painted_wood")
    with pytest.raises(SourceError) as e:
        compose_shade_kernel(scene.permutations[h], lib)
    line = _line_of(EXAMPLE, 'packing = "albedo_texture"')
    assert str(e.value).startswith(f"{EXAMPLE}:{line}:1: a shade kernel binds no textures"), str(e.value)
    assert "<key>" not in str(e.value)


def test_a_scene_key_error_points_at_the_part_that_is_wrong(lib, tmp_path):
    """A permutation of a scene whose light type is unknown to the library linking it: the light's `type` key."""
    from generator.link import link_permutation

    scene = load_scene(EXAMPLE, lib)
    h = next(o["permutation"] for o in scene.objects if o["material"] == "cobblestone")
    poorer = load_library()
    del poorer.bricks[("light", "point")]
    with pytest.raises(SourceError) as e:
        link_permutation(scene.permutations[h], poorer)
    text = EXAMPLE.read_text().splitlines()
    lamp = text.index("[lights.lamp]") + 1
    line = next(i + 1 for i in range(lamp, len(text)) if text[i].startswith("type ="))
    assert str(e.value).startswith(f"{EXAMPLE}:{line}:1: unknown light brick 'point'"), str(e.value)


def test_a_spec_string_error_names_the_column_of_its_brick(tmp_path):
    from generator.link import eval_program

    (tmp_path / "shadowed_lambert.py").write_text(
        '"""Lambert darkened by a depth compare (a test brick)."""\n'
        'BRICK = {"kind": "diffuse", "cite": "a test", "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], '
        '"default": [0.5, 0.5, 0.5]}}, "textures": {"occluder": {"srgb": False}}}\n\n\n'
        'def diffuse(rho_d: vec3, occluder: texture2d_shadow) -> vec3:\n'
        '    return rho_d * INV_PI * sample_compare(occluder, vec2(0.5), 0.5)\n')
    lib = load_library([tmp_path])
    with pytest.raises(SourceError) as e:
        eval_program("microfacet+shadowed_lambert", lib)
    assert str(e.value).startswith("spec string 'microfacet+shadowed_lambert':1:12: the BRDF reads 'occluder'")


def test_a_key_made_by_code_points_into_its_own_text(lib):
    perm = Permutation("lambert", (), "constants", "no_such_output")
    with pytest.raises(SourceError) as e:
        resolve(perm, lib)
    key = perm.canonical()
    assert str(e.value).startswith(f"permutation key '{key}':1:{key.index('output=') + 1}: unknown output brick")
