"""The renderer draws a glTF scene's own meshes at their nodes' world matrices (issue 12: "meshes are read
too, for the renderer")."""
from __future__ import annotations

import json

import numpy as np
import pytest

from tests.test_gltf import sample_doc


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_gltf_scene_renders_its_meshes_where_its_nodes_put_them(tmp_path):
    from PIL import Image

    from generator.library.bricks import load_library
    from generator.matrix.scene import load_scene
    from generator.runtime.placement import load_placement
    from generator.runtime.renderer import render_scene

    path = sample_doc().write_gltf(tmp_path / "s.gltf")
    scene = load_scene(path, load_library())
    placed = load_placement(scene)
    assert placed.source == path and len(placed.objects) == len(scene.objects)
    leaf = next(o for o in placed.objects if o.name.startswith("leaf"))
    assert np.allclose(leaf.model[:3, 3], [3, 0, 0])  # the node's translation
    corners = leaf.corners()
    assert np.allclose(corners.min(0), [2, 0, -1]) and np.allclose(corners.max(0), [4, 0, 1])  # the quad's box, moved
    report = render_scene(scene, load_library(), "specialized", 1, tmp_path / "out", size=(64, 48))
    assert report.placement == str(path)
    img = np.asarray(Image.open(tmp_path / "out" / "frame_0000.png"))[..., :3].astype(int)
    assert (img.sum(-1) > 30).sum() > 200, "the quads are drawn and lit"
    assert json.loads((tmp_path / "out" / "report.json").read_text())["placement"] == str(path)
