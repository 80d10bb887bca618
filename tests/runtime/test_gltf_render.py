"""The renderer draws a glTF scene's own meshes at their nodes' world matrices: a scene's meshes
are read for the renderer too."""
from __future__ import annotations

import json

import numpy as np
import pytest

from tests.scene.test_gltf import sample_doc


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_gltf_scene_renders_its_meshes_where_its_nodes_put_them(tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from generator.runtime.placement import load_placement
    from generator.runtime.renderer import render_scene
    from generator.assemble.render_inputs import scene_textures

    path = sample_doc().write_gltf(tmp_path / "s.gltf")
    scene = load_scene(path, load_library())
    placed = load_placement(scene)
    assert placed.source == path and len(placed.objects) == len(scene.objects)
    leaf = next(o for o in placed.objects if o.name.startswith("leaf"))
    assert np.allclose(leaf.model[:3, 3], [3, 0, 0])  # the node's translation
    corners = leaf.corners()
    assert np.allclose(corners.min(0), [2, 0, -1]) and np.allclose(corners.max(0), [4, 0, 1])  # the quad's box, moved
    report = render_scene(scene, load_library(), "specialized", 1, tmp_path / "out", size=(64, 48),
                          build=scene_textures(scene, tmp_path / "out"))
    assert report.placement == str(path)
    assert _drawn(tmp_path / "out") > 200, "the quads are drawn"
    assert json.loads((tmp_path / "out" / "report.json").read_text())["placement"] == str(path)


CLEAR = np.round(np.array([0.06, 0.07, 0.09]) * 255)  # the renderer's clear colour


def _drawn(out) -> int:
    """Pixels of the frame other than the clear colour."""
    from PIL import Image

    img = np.asarray(Image.open(out / "frame_0000.png").convert("RGB")).astype(int)
    return int((np.abs(img - CLEAR).max(-1) > 2).sum())


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_mirrored_single_sided_node_keeps_its_front_face(tmp_path):
    """glTF: a node whose world matrix has a negative determinant reverses its triangles' winding; the renderer
    culls the back faces of a single-sided material, so the mirrored quad must stay as visible as the plain one."""
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from generator.runtime.renderer import render_scene
    from generator.assemble.render_inputs import scene_textures
    from tests.scene.test_gltf import Doc

    lib, drawn = load_library(), {}
    for name, scale in (("plain", [1, 1, 1]), ("mirrored", [-1, 1, 1])):
        g = Doc()
        m = g.material(name="m", pbrMetallicRoughness={"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0})
        g.node(name="quad", mesh=g.quad_mesh("quad_mesh", m), scale=scale)  # faces +y, the camera looks down
        scene = load_scene(g.write_gltf(tmp_path / f"{name}.gltf"), lib)
        assert scene.permutations[scene.objects[0]["permutation"]].surface.double_sided is False
        render_scene(scene, lib, "specialized", 1, tmp_path / name, size=(64, 48),
                     build=scene_textures(scene, tmp_path / name))
        drawn[name] = _drawn(tmp_path / name)
    assert drawn["plain"] > 200 and drawn["mirrored"] == drawn["plain"], drawn
