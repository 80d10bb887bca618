"""The shadow depth pass: every shadowed light's depth rendered from the light, sampled as its shadow map.

tests/scenes/shadow.toml: a Lambert floor (8 × 8, y = 0) and a ball (r = 0.6) above it, one directional light with
shadow_map and nothing else, so a lit floor pixel has one uniform colour and a shadowed one is black. The ball's
shadow footprint is computed analytically from the light direction: a floor point G is in shadow when the ray
G + t·d (t > 0, d toward the light) passes within r of the ball's centre. Pixels well inside the footprint
(< 0.85 r) must be black and pixels well outside it (> 1.15 r) lit, in the specialized and the ubershader paths
(both get the computed shadow matrix); with shadow = "none" the footprint pixels are lit like the rest; a point
light variant (a perspective shadow matrix) shadows its own footprint (rays toward the light's position). Rendered
in-process on the validated `device` (tests/lavapipe.py): no validation messages.

Measured on lavapipe (Mesa 25.0.7, LLVM 15.0.6), 96 × 64, shadow map 256² (sampled as the D32 depth image
itself; Mesa 22.3.6 sampled its R32_SFLOAT copy and gave the same images): inside pixels exactly 0, outside pixels
one colour (124 in every channel); specialized and ubershader images identical.
"""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "tests" / "scenes" / "shadow.toml"
W, H = 96, 64
SHADOW = 256
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


POINT = [2.0, 4.0, -0.8]  # the point-light variant's position


def _scene(lib, tmp_path, shadow="shadow_map", light="directional"):
    """The test scene, or a copy (with its placement beside it) whose sun casts `shadow` / is a point light."""
    from generator.scene.load import load_scene

    if shadow == "shadow_map" and light == "directional":
        return load_scene(SCENE, lib)
    d = tmp_path / f"scene-{shadow}-{light}"
    d.mkdir()
    text = SCENE.read_text().replace('shadow = "shadow_map"', f'shadow = "{shadow}"')
    if shadow != "shadow_map":
        text = text.replace(", shadow_bias = 0.003", "")  # a parameter of shadow_map only
    if light == "point":
        text = text.replace('type = "directional"', 'type = "point"').replace(
            "direction = [1.0, 0.8, -0.3], color = [1.0, 1.0, 1.0]", f"position = {POINT}, color = [12.0, 12.0, 12.0]")
    (d / "shadow.toml").write_text(text)
    shutil.copy(SCENE.with_name("shadow.placement.toml"), d / "shadow.placement.toml")
    return load_scene(d / "shadow.toml", lib)


def _render(scene, lib, device, out, mode):
    from PIL import Image

    from generator.runtime.renderer import render_scene

    rep = render_scene(scene, lib, mode, 1, out, (W, H), device=device, shadow_size=SHADOW)
    return np.asarray(Image.open(out / "frame_0000.png").convert("RGB")).astype(int), rep


def camera_rays(pl, width: int, height: int):
    """(eye, d): the placement's camera position and, per pixel of a width × height image, the direction from it
    through the pixel's centre to the far plane ((height, width, 3), not normalized; row 0: clip y = −1, the image's
    top row)."""
    eye, vp = pl.camera(width, height)
    inv = np.linalg.inv(vp)
    x = 2.0 * (np.arange(width) + 0.5) / width - 1.0
    y = 2.0 * (np.arange(height) + 0.5) / height - 1.0
    nx, ny = np.meshgrid(x, y)
    far = np.stack([nx, ny, np.ones_like(nx), np.ones_like(nx)], -1) @ inv.T
    return eye, far[..., :3] / far[..., 3:] - eye


def _footprint(scene, lib):
    """(inside, outside): floor pixels seen by the camera, well inside / well outside the ball's shadow."""
    from generator.runtime.placement import load_placement

    pl = load_placement(scene)
    floor, ball = pl.objects
    eye, d = camera_rays(pl, W, H)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    t = (floor.translate[1] - eye[1]) / d[..., 1]
    g = eye + t[..., None] * d
    half = np.array(floor.scale)[[0, 2]] - 0.2
    on_floor = (t > 0) & (np.abs(g[..., 0]) < half[0]) & (np.abs(g[..., 2]) < half[1])
    c, r = np.array(ball.translate), ball.scale[0]
    oc = eye - c  # camera rays that pass near the ball show the ball, not the floor
    b = np.einsum("hwk,k->hw", d, oc)
    near_ball = b * b - (oc @ oc - (1.1 * r) ** 2) >= 0
    sun = scene.lights["sun"]
    if sun.type == "directional":
        light = np.broadcast_to(np.array(sun.params["direction"], np.float64), g.shape)
        reach = np.full(g.shape[:2], np.inf)
    else:  # toward the point light, as far as the light
        light = np.array(sun.params["position"], np.float64) - g
        reach = np.linalg.norm(light, axis=-1)
    light = light / np.linalg.norm(light, axis=-1, keepdims=True)
    cg = c - g
    along = np.einsum("hwk,hwk->hw", cg, light)
    dist = np.linalg.norm(cg - along[..., None] * light, axis=-1)
    between = (along > 0) & (along < reach)
    seen = on_floor & ~near_ball
    return seen & between & (dist < 0.85 * r), seen & (~between | (dist > 1.15 * r))


def test_the_ball_shadows_its_analytic_footprint_on_the_floor_in_both_paths(device, lib, tmp_path):
    scene = _scene(lib, tmp_path)
    inside, outside = _footprint(scene, lib)
    assert inside.sum() > 100 and outside.sum() > 1000, (inside.sum(), outside.sum())
    images = {}
    for mode in ("specialized", "ubershader"):
        img, rep = _render(scene, lib, device, tmp_path / mode, mode)
        images[mode] = img
        sm = rep.shadow_maps["sun"]
        assert sm["size"] == [SHADOW, SHADOW] and sm["sampled"] in ("depth", "r32_copy")
        lit = img[outside]
        assert lit.min() > 40, "the floor outside the footprint is lit"
        assert np.ptp(lit, axis=0).max() <= 1, "a lit Lambert floor under a directional light is one colour"
        assert img[inside].max() == 0, f"{mode}: the floor inside the ball's footprint is in shadow"
        # the matrix maps every placed object's bounds into the light's clip volume
        from generator.runtime.placement import load_placement
        m = np.array(sm["shadow_matrix"]).reshape(4, 4).T
        p = np.c_[load_placement(scene).points(), np.ones(16)] @ m.T
        assert (np.abs(p[:, :2]) <= 1).all() and (p[:, 2] >= 0).all() and (p[:, 2] <= 1).all()
    assert np.array_equal(images["specialized"], images["ubershader"])
    darker = images["specialized"][inside].sum(-1).mean() < 0.2 * images["specialized"][outside].sum(-1).mean()
    assert darker


def test_with_shadow_none_the_footprint_is_lit_like_the_rest_of_the_floor(device, lib, tmp_path):
    scene = _scene(lib, tmp_path, "none")
    inside, outside = _footprint(scene, lib)
    img, rep = _render(scene, lib, device, tmp_path / "none", "specialized")
    assert rep.shadow_maps == {}, "no shadowed light: no depth pass"
    # Without a shadow map nothing of this permutation's fragment shader reads the world position (Lambert, a
    # directional light), but the vertex shader (backends/*/templates/vertex) still writes v_position at location 0:
    # valid Vulkan, a performance warning of the layer. Take exactly that warning, and only it.
    unread = [m for m in device.messages if m.id_name == "UNASSIGNED-CoreValidation-Shader-OutputNotConsumed"
              and "output location 0.0 which is not consumed" in m.text]
    assert unread, "the unread v_position warning went away: drop this drain"
    device.messages[:] = [m for m in device.messages if m not in unread]
    lit = img[outside][0]
    assert np.abs(img[inside] - lit).max() <= 1 and np.abs(img[outside] - lit).max() <= 1
    shadowed, _ = _render(_scene(lib, tmp_path), lib, device, tmp_path / "map", "specialized")
    assert np.array_equal(shadowed[outside], img[outside]), "outside the footprint the shadow changes nothing"


def test_a_point_light_shadows_its_footprint_too(device, lib, tmp_path):
    """A point light's shadow matrix is a perspective projection from its position (graphics.point_shadow_matrix)."""
    scene = _scene(lib, tmp_path, light="point")
    inside, outside = _footprint(scene, lib)
    assert inside.sum() > 100 and outside.sum() > 1000, (inside.sum(), outside.sum())
    img, rep = _render(scene, lib, device, tmp_path / "point", "ubershader")
    assert "sun" in rep.shadow_maps
    assert img[inside].max() == 0 and img[outside].min() > 10  # far corners: 1/d² dims them (≥ 19 measured)
