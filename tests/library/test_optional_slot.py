"""Optional slots (library/bricks.py, spec/permutation.py) and the `uv` kind (library/kinds.py) they were made for.

An optional slot (`{"kind": k, "optional": True}`, no default) left empty has no filler: nothing is linked and the
canonical key does not write it, so a brick that gains one keeps every earlier key; filled, it is written in the
brick's slot order. The glTF packings declare one, `uv`, for KHR_texture_transform
(bricks/packing/uv/texture_transform.py; tests/scene/test_gltf_texture_transform.py shades with it).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from generator.lang import SourceError

REPO = Path(__file__).resolve().parents[2]
GLTF_PACKINGS = ("albedo_texture", "constants", "gltf_metallic_roughness")


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def _canon(spec, lib):
    from generator.spec.permutation import canonical, parse_spec
    return canonical(parse_spec(spec, lib, ("packing",)))


@pytest.mark.parametrize("packing", GLTF_PACKINGS)
def test_an_empty_optional_slot_is_not_in_the_key_and_a_filled_one_is_in_slot_order(lib, packing):
    assert lib.get("packing", packing).slots["uv"] == {"kind": "uv", "optional": True}
    assert _canon(packing, lib) == f"{packing}(normal=vertex)"  # the key the packing had before the slot
    want = f"{packing}(normal=normal_map,uv=texture_transform)"
    assert _canon(f"{packing}(uv=texture_transform,normal=normal_map)", lib) == want
    assert _canon(want, lib) == want


def test_an_empty_optional_slot_links_nothing(lib):
    from generator.spec.permutation import parse_spec
    node = parse_spec("albedo_texture", lib, ("packing",))[0]
    assert [s for s, _ in node.fillers] == ["normal"]
    assert [n.brick.id for n in node.tree] == ["albedo_texture", "vertex"]
    filled = parse_spec("albedo_texture(uv=texture_transform)", lib, ("packing",))[0]
    assert [n.brick.kind for n in filled.tree] == ["packing", "normal", "uv"]


def test_an_unknown_uv_filler_names_the_known_ones(lib):
    from generator.spec.permutation import SpecError, parse_spec
    with pytest.raises(SpecError) as e:
        parse_spec("albedo_texture(uv=affine)", lib, ("packing",))
    assert "unknown uv brick 'affine'" in str(e.value) and "texture_transform" in str(e.value)
    with pytest.raises(SpecError) as e:  # a packing without the slot says which it has
        parse_spec("toksvig_alpha(uv=texture_transform)", lib, ("packing",))
    assert "has no slot 'uv'" in str(e.value)


PACKING = '''"""A packing with an optional uv slot."""
BRICK = {
    "kind": "packing",
    "cite": "test",
    "textures": {"tint_map": {"srgb": True}},
    "slots": {"normal": {"kind": "normal", "default": "vertex"}, SLOT},
}


def get_rho_d(uv: vec2, tint_map: texture2d) -> vec3:
    return sample(tint_map, uv).xyz
'''


def _brick(tmp_path, slot: str) -> Path:
    d = tmp_path / "bricks"
    d.mkdir(exist_ok=True)
    (d / "tinted.py").write_text(PACKING.replace("SLOT", slot))
    return d


def test_a_brick_of_ones_own_may_declare_the_optional_uv_slot(tmp_path):
    from generator.library.bricks import load_library
    lib = load_library((_brick(tmp_path, '"uv": {"kind": "uv", "optional": True}'),))
    assert _canon("tinted", lib) == "tinted(normal=vertex)"
    assert _canon("tinted(uv=texture_transform)", lib) == "tinted(normal=vertex,uv=texture_transform)"


@pytest.mark.parametrize("slot, words", [
    ('"uv": {"kind": "uv", "optional": True, "default": "texture_transform"}', "or \"optional\": True and none"),
    ('"uv": {"kind": "uv"}', "needs a default filler"),
    ('"uv": {"kind": "uv", "optional": False}', "BRICK['slots']['uv']['optional']"),
])
def test_an_optional_slot_has_no_default_and_a_slot_without_one_is_optional(tmp_path, slot, words):
    from generator.library.bricks import load_library
    with pytest.raises(SourceError) as e:
        load_library((_brick(tmp_path, slot),))
    assert str(e.value).startswith("bricks/tinted.py:"), str(e.value)  # at the brick, as every metadata error
    assert words in str(e.value) and " — " in str(e.value)


def test_the_uv_kind_contract(lib):
    from generator.library.kinds import KINDS
    from generator.lang.types import VEC2
    k = KINDS["uv"]
    assert [e.name for e in k.entries] == ["map_uv"] and k.entries[0].ret == VEC2 and k.reads == "surface"
    assert [b.id for b in lib.of_kind("uv")] == ["texture_transform"]
    b = lib.get("uv", "texture_transform")
    assert {n: (str(p.ty), p.default, p.range) for n, p in b.params.items()} == {
        "uv_offset": ("vec2", [0.0, 0.0], None), "uv_scale": ("vec2", [1.0, 1.0], None),
        "uv_rotation": ("float", 0.0, None)}


def test_the_catalogue_shows_the_optional_slot():
    r = subprocess.run([sys.executable, "-m", "generator.cli", "bricks", "--json"], cwd=REPO, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    rows = {(x["kind"], x["id"]): x for x in json.loads(r.stdout)}
    slot = rows[("packing", "albedo_texture")]["slots"]["uv"]
    assert slot == {"kind": "uv", "default": None, "fillers": ["texture_transform"]}
    r = subprocess.run([sys.executable, "-m", "generator.cli", "bricks"], cwd=REPO, capture_output=True, text=True,
                       timeout=120)
    assert "slot uv (uv, optional, empty by default): texture_transform" in r.stdout
