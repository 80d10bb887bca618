"""A glTF permutation carries where it was asked for (scene/gltf.py, Origins): an error resolving or linking
it is located at the glTF object to edit — its material's line and column in a .gltf, with the JSON pointer —
not in the permutation key's text."""
from __future__ import annotations

import pytest

from generator.lang import SourceError
from generator.lang.errors import position
from tests.scene.test_gltf import sample_doc


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def _by_material(scene):
    return {o["material"]: scene.permutations[o["permutation"]] for o in scene.objects}


def _link_error(perm, lib) -> str:
    """A shade kernel binds no textures and reads no vertex colours: linking one for such a material fails."""
    from generator.link import link_permutation
    with pytest.raises(SourceError) as e:
        link_permutation(perm, lib, kernel=True)
    return str(e.value)


def test_a_link_error_points_at_the_gltf_material(tmp_path, lib):
    from generator.scene.load import load_scene
    path = sample_doc().write_gltf(tmp_path / "scene.gltf")
    text = path.read_text()
    scene = load_scene(path, lib)
    perms = _by_material(scene)
    materials = text.index('"materials"')  # nodes may share a material's name

    line, col = position(text, text.rindex("{", 0, text.index('"name": "textured_metal"', materials)))
    assert _link_error(perms["textured_metal"], lib).startswith(
        f"{path}:{line}:{col}: /materials/0: a shade kernel binds no textures, and brdf=")
    line, col = position(text, text.rindex("{", 0, text.index('"name": "leaf"', materials)))
    assert _link_error(perms["leaf"], lib).startswith(f"{path}:{line}:{col}: /materials/1: a shade kernel")
    # the vertex colours were asked for by the primitive that has COLOR_0
    colors = text.index('"COLOR_0"')
    line, col = position(text, text.index(":", colors) + 2)
    assert _link_error(perms["cloth+COLOR_0"], lib).startswith(
        f"{path}:{line}:{col}: /meshes/2/primitives/0/attributes/COLOR_0: a shade kernel has no vertex colours")
    # lights: at their KHR_lights_punctual definitions
    origin = perms["bumpy"].origin
    torch = text.rindex("{", 0, text.index('"name": "torch"'))
    assert (origin.at("light2").line, origin.at("light2").col) == position(text, torch)
    assert origin.at("light2").pointer == "/extensions/KHR_lights_punctual/lights/2"


def test_a_glb_names_the_pointer_and_the_byte(tmp_path, lib):
    from generator.scene.load import load_scene
    path = sample_doc().write_glb(tmp_path / "scene.glb")
    data = path.read_bytes()
    message = _link_error(_by_material(load_scene(path, lib))["bumpy"], lib)
    head = f"{path}:1:1: /materials/3 (byte "
    assert message.startswith(head), message
    byte = int(message[len(head):].split(")")[0])
    assert data[byte:byte + 1] == b"{" and data.index(b'"name": "bumpy"', byte) == byte + 1


def test_the_default_material_is_asked_for_by_its_primitive(tmp_path, lib):
    from generator.scene.load import load_scene
    g = sample_doc(extra_lights=False)
    g.node(name="plain", mesh=g.quad_mesh("plain_mesh", None))
    scene = load_scene(g.write_gltf(tmp_path / "scene.gltf"), lib)
    where = _by_material(scene)["default"].origin.at("brdf")
    assert where.pointer == "/meshes/4/primitives/0" and where.line > 1
