"""The matrix model: spec strings, canonical keys, and which permutations a scene must and must not get."""
import pytest

from generator.library.bricks import load_library
from generator.spec.permutation import LightKey, Permutation, SpecError, canonical, parse_brdf, parse_spec
from generator.scene.load import load_scene
from tests.regen_goldens import REPO


@pytest.fixture(scope="module")
def lib():
    return load_library()


@pytest.mark.parametrize("spec,canon", [
    ("lambert", "lambert"),
    (" lambert + blinn_phong_normalized ", "lambert+blinn_phong_normalized"),
    ("blinn_phong_normalized+lambert", "lambert+blinn_phong_normalized"),  # diffuse first
    ("microfacet", "microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)"),  # defaults written out
    ("microfacet(vis=implicit, ndf=beckmann)", "microfacet(ndf=beckmann,fresnel=schlick,vis=implicit)"),  # slot order
])
def test_canonical_spec(lib, spec, canon):
    assert canonical(parse_brdf(spec, lib)) == canon


@pytest.mark.parametrize("spec,col,words", [
    ("lambert+", 9, "expected a brick id"),
    ("lambert+lambert", 1, "at most one diffuse"),
    ("microfacet(ndf=ggx,ndf=beckmann)", 20, "filled twice"),
    ("microfacet(ndf=lambert)", 16, "unknown ndf brick 'lambert'"),
    ("lambert(ndf=ggx)", 9, "'lambert' has no slot 'ndf'"),
    ("microfacet(ndf=ggx", 19, "expected ',' or ')'"),
    ("lambert$", 8, "unexpected character"),
])
def test_bad_specs_name_the_column(lib, spec, col, words):
    with pytest.raises(SpecError) as e:
        parse_brdf(spec, lib)
    assert e.value.col == col and words in str(e.value), str(e.value)


def test_permutation_hash_is_stable_and_canonical():
    p = Permutation("lambert", (LightKey("point", "none"),), "constants(normal=vertex)")
    assert p.canonical() == "brdf=lambert;lights=point/none;packing=constants(normal=vertex);output=linear;precision=fp32"
    # The hash names files: it must never change for the same key (caches and goldens depend on it).
    assert p.hash == "5c7df38482fa"  # sha256(canonical)[:12]
    assert Permutation("lambert", (LightKey("point", "none"), LightKey("point", "none")), "constants(normal=vertex)").hash != p.hash


def test_example_scene_truth_table(lib):
    scene = load_scene(REPO / "scenes" / "example.toml", lib)
    got = {p.canonical(): sorted(scene.users[h]) for h, p in scene.permutations.items()}
    outdoor = "lights=directional/shadow_map,point/none"
    indoor = "lights=point/none,point/none"
    tail = "output=linear;precision=fp32"
    assert got == {
        f"brdf=lambert+phong_normalized;{outdoor};packing=albedo_texture(normal=vertex);{tail}": ["bench", "chair"],
        f"brdf=lambert+microfacet(ndf=beckmann,fresnel=schlick,vis=torrance_sparrow);{outdoor};"
        f"packing=albedo_texture(normal=normal_map);{tail}": ["ground"],
        f"brdf=microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick);{outdoor};packing=constants(normal=vertex);{tail}": ["statue"],
        f"brdf=lambert+blinn_phong_normalized;{indoor};packing=constants(normal=vertex);{tail}": ["bucket"],
        f"brdf=lambert+microfacet(ndf=blinn_phong,fresnel=none,vis=implicit);{indoor};packing=constants(normal=vertex);{tail}": ["door"],
    }
    # Never generated: materials with light sets no object pairs them with.
    assert not any("red_plastic" in o["material"] and o["lights"] == ["sun", "lamp"] for o in scene.objects)


def test_packing_must_fit_the_brdf(lib, tmp_path):
    from generator.lang import SourceError
    p = tmp_path / "s.toml"
    p.write_text('[materials.m]\nbrdf = "blinn_phong_normalized"\npacking = "albedo_texture"\n')
    with pytest.raises(SourceError, match="provides rho_d, which BRDF 'blinn_phong_normalized' does not read"):
        load_scene(p, lib)


def test_packing_spec_fills_the_normal_slot(lib):
    assert canonical(parse_spec("albedo_texture", lib, ("packing",))) == "albedo_texture(normal=vertex)"
