"""A point light's shadow is six faces, each a 90° map in a layer of one 2D array, and it falls where a float64 ray
test of the scene's geometry says, on every face.

tests/scenes/point_ring.toml: a Lambert floor (8 × 8, y = 0), a point light 1.6 above it with pcf (one tap), four
boxes around it and a low one beneath it and aside; the light is the floor's only light, so a floor pixel is black
exactly where it is shadowed. For every camera pixel that sees the floor (no box first) the test intersects, in
NumPy float64, the segment from the floor point to the light with the boxes (their placed bounds) and compares
with the render. Pixels within two map texels of the analytic shadow edge, by the map of the face the point lies
in, are left out (test_shadow_projection's criterion, per face); of the rest at least 99 % must agree, in the
specialized path and the ubershader, and the shadowed pixels they judge lie in at least four faces' layers. The
depth pass draws six layers (the report and the manifest's description say so), the six matrices are the
projections of Vulkan's cube faces (a direction's face and uv are the cube lookup's), and the shader binds a
2d_array. No warning: six faces hold every direction. Rendered in-process on the validated `device`.

Measured on lavapipe (Mesa 25), 128 × 96, map 128²: 99.99 % of 7,367 judged pixels agree (657 of them shadowed,
in faces +X, -X, -Y, +Z and -Z), in both paths; with the face picked wrongly (+X and -X swapped) 95.98 %. ~8 s.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)
from tests.runtime.test_shadow_projection import _far_from_edge, _hits, _shadowed
from tests.runtime.test_shadows import camera_rays

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "tests" / "scenes" / "point_ring.toml"
W, H = 128, 96
SHADOW = 128
AGREE = 0.99
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _render(scene, lib, device, out, mode):
    from PIL import Image

    from generator.runtime.renderer import render_scene

    rep = render_scene(scene, lib, mode, 1, out, (W, H), device=device, shadow_size=SHADOW)
    return np.asarray(Image.open(out / "frame_0000.png").convert("RGB")).astype(int), rep


def _floor(pl):
    """(seen, g, boxes): pixels whose camera ray meets the floor before any box, where, and the boxes' bounds."""
    floor = next(o for o in pl.objects if o.name == "floor")
    boxes = [(o.corners().min(0), o.corners().max(0)) for o in pl.objects if o.mesh == "box"]
    eye, d = camera_rays(pl, W, H)
    t = (floor.translate[1] - eye[1]) / d[..., 1]
    g = eye + t[..., None] * d
    c = floor.corners()
    seen = (t > 0) & (np.abs(g[..., 0]) < c[:, 0].max() - 0.05) & (np.abs(g[..., 2]) < c[:, 2].max() - 0.05)
    for box in boxes:
        seen &= ~_hits(eye, d, box, t)
    return seen, g, boxes


def test_cube_faces_are_vulkan_s_cube_lookup():
    """Each face's matrix maps a direction in its face to the uv a Vulkan cube lookup reads there (no GPU)."""
    from generator.runtime.shadow_pass import cube_face, cube_face_matrices

    eye = np.array([0.3, 1.0, -0.2])
    corners = np.array([[x, y, z] for x in (-2.0, 2.0) for y in (-1.0, 2.0) for z in (-2.0, 2.0)])
    mats = cube_face_matrices(eye, corners)  # the light inside the one caster's box: near = far × 1e-3
    rng = np.random.default_rng(1)
    # Vulkan's cube map face selection table: (sc, tc, ma) per face
    table = {0: lambda r: (-r[2], -r[1], r[0]), 1: lambda r: (r[2], -r[1], -r[0]), 2: lambda r: (r[0], r[2], r[1]),
             3: lambda r: (r[0], -r[2], -r[1]), 4: lambda r: (r[0], -r[1], r[2]), 5: lambda r: (-r[0], -r[1], -r[2])}
    for r in rng.normal(size=(200, 3)):
        r *= rng.uniform(0.1, 2.0) / np.linalg.norm(r)
        k = cube_face(r)
        sc, tc, ma = table[k](r)
        assert ma > 0
        c = mats[k] @ np.append(eye + r, 1.0)
        assert np.allclose(c[:2] / c[3], [sc / ma, tc / ma]), (k, r)
        assert 0.0 < c[2] / c[3] < 1.0
    assert [cube_face(v) for v in ([1, 1, 1], [1, 1, 0], [-1, 0, 0])] == [4, 2, 1], "ties to z, then y"


@pytest.mark.parametrize("mode", ["specialized", "ubershader"])
def test_a_point_light_s_six_faces_shadow_where_the_ray_test_says(device, lib, tmp_path, mode):
    from generator.runtime.placement import load_placement
    from generator.runtime.shadow_pass import cube_face
    from generator.scene.load import load_scene

    scene = load_scene(SCENE, lib)
    img, rep = _render(scene, lib, device, tmp_path / mode, mode)
    sm = rep.shadow_maps["bulb"]
    assert sm["layers"] == 6 and sm["size"] == [SHADOW, SHADOW] and len(sm["shadow_matrix"]) == 6
    assert rep.shadow_warnings == []
    pl = load_placement(scene)
    seen, g, boxes = _floor(pl)
    light = np.array(scene.lights["bulb"].params["position"], np.float64)
    expected = np.zeros(seen.shape, bool)
    for box in boxes:
        expected |= _shadowed(g, light, box)
    judged = seen.copy()
    for box in boxes:  # far from every box's shadow edge, by the map of the point's face
        judged &= _far_from_edge(g, light, box, sm["shadow_matrix"], SHADOW)
    shadowed = img.max(-1) <= 2
    agree = (shadowed == expected)[judged].mean()
    faces = np.apply_along_axis(cube_face, -1, g - light)
    assert judged.sum() > 2000 and expected[judged].sum() > 300, (judged.sum(), expected[judged].sum())
    assert len(set(faces[judged & expected].tolist())) >= 4, "shadows in at least four faces"
    assert agree >= AGREE, f"{mode}: {agree:.2%} of {judged.sum()} floor pixels agree with the ray test"


def test_the_description_and_the_shader_say_six_layers_of_a_2d_array(lib):
    """The manifest's depth pass of a point light: six faces, their order and parameters; its permutation reads a
    2d_array, and the Lights block holds the six matrices (no GPU)."""
    from generator.link import link_permutation
    from generator.runtime.shadow_pass import depth_pass, pass_units, depth_plan
    from generator.scene.load import load_scene
    from generator.spec.resolve import resolve

    scene = load_scene(SCENE, lib)
    (h, perm), = scene.permutations.items()
    lp = link_permutation(resolve(perm, lib), lib)
    tex, = [t for t in lp.interface.textures if t.group == "light"]
    assert (tex.param, tex.dim) == ("shadow_map", "2d_array")
    names = [s.param for s in lp.lights[0] if s.param.startswith("shadow_matrix")]
    assert names == ["shadow_matrix"] + [f"shadow_matrix_{k}" for k in range(1, 6)]
    d = depth_pass(scene.lights["bulb"], {"shadow_map": False}, {}, pass_units(depth_plan({"bulb": {}}, {}), False), [])
    assert d["faces"] == {"layers": 6, "order": ["+X", "-X", "+Y", "-Y", "+Z", "-Z"], "select": "major_axis",
                          "passes": "per_layer"}
    assert d["matrix"]["parameters"] == names and d["matrix"]["fit"]["projection"] == "cube_faces"
