"""Filtered shadows: `pcf` (k × k depth compares, averaged) and `vsm` (variance shadow map).

The scene is tests/scenes/shadow.toml (a Lambert floor, a ball above it, one directional light, nothing else:
a lit floor pixel has one colour, a shadowed one is black) with the sun's shadow swapped for the brick under
test. Each brick loads, the scene builds in GLSL, HLSL and WGSL with the real compilers (the render compiles
every permutation and the ubershader, and validates the SPIR-V) and draws on the validated lavapipe device.
Softness is counted on the floor pixels of the analytic footprint's edge band (0.85 r .. 1.15 r from the
shadow ray's closest approach, tests/runtime/test_shadows.py): pixels strictly between black and the lit colour.

Measured on lavapipe (Mesa 25.0.7), 96 × 64, shadow map 256²: the edge band (0.85 r .. 1.15 r) holds 98
floor pixels; shadow_map and pcf with k = 1 (the same image) leave 0 of them intermediate, pcf 3 × 3
(pcf_texel = 1/256) 38, pcf 5 × 5 71. vsm (the defaults: 5 × 5 moments box, vsm_bleed 0.2) widens the
penumbra past 1.15 r (3 pixels), so it is counted in 0.85 r .. 1.3 r: 79 of 153 intermediate, the same in both
paths. A NaN shadow term would reach the 8-bit frame as black: every floor pixel outside the penumbra is
asserted lit, one colour; the brick's denominators are bounded away from 0 by its parameter ranges.
"""
from __future__ import annotations

import itertools
import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)
from tests.runtime.test_shadows import camera_rays  # a pixel's camera ray

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "tests" / "scenes" / "shadow.toml"
W, H = 96, 64
SHADOW = 256
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


_SERIAL = itertools.count()


def _scene(lib, tmp_path, shadow, params=""):
    """A copy of the shadow test scene whose sun casts `shadow`, with extra light `params` ("k = v, ...")."""
    from generator.scene.load import load_scene

    d = tmp_path / f"scene-{shadow}-{next(_SERIAL)}"
    d.mkdir()
    text = SCENE.read_text().replace('shadow = "shadow_map"', f'shadow = "{shadow}"')
    if params:
        text = text.replace("shadow_bias = 0.003 }", f"shadow_bias = 0.003, {params} }}")
    (d / "shadow.toml").write_text(text)
    shutil.copy(SCENE.with_name("shadow.placement.toml"), d / "shadow.placement.toml")
    return load_scene(d / "shadow.toml", lib)


def _render(scene, lib, device, out, mode="specialized", language="glsl"):
    from PIL import Image

    from generator.runtime.renderer import render_scene

    rep = render_scene(scene, lib, mode, 1, out, (W, H), language=language, device=device, shadow_size=SHADOW)
    return np.asarray(Image.open(out / "frame_0000.png").convert("RGB")).astype(int), rep


def _regions(scene, outer=1.15):
    """(inside, outside, band): floor pixels well inside (< 0.85 r) / well outside (> outer · r) the ball's
    footprint, and between."""
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
    oc = eye - c
    b = np.einsum("hwk,k->hw", d, oc)
    near_ball = b * b - (oc @ oc - (1.1 * r) ** 2) >= 0
    light = np.asarray(scene.lights["sun"].params["direction"], np.float64)
    light = light / np.linalg.norm(light)
    cg = c - g
    along = cg @ light
    dist = np.linalg.norm(cg - along[..., None] * light, axis=-1)
    seen = on_floor & ~near_ball & (along > 0)
    return seen & (dist < 0.85 * r), seen & (dist > outer * r), seen & (dist >= 0.85 * r) & (dist <= outer * r)


def _intermediate(img, lit, band):
    v = img[band].sum(-1)
    return int(((v > 0) & (v < lit.sum())).sum())


FIGURES = {}
VSM_OUTER = 1.3  # vsm's penumbra reaches further out (the moments' box filter)


@pytest.mark.parametrize("brick", ["pcf", "vsm"])
def test_the_filtered_shadow_bricks_load(lib, brick):
    b = lib.get("shadow", brick)
    assert b.kind == "shadow" and "shadow_matrix" in b.params and "shadow_bias" in b.params
    assert list(b.textures) == (["shadow_map"] if brick == "pcf" else ["shadow_moments"])


@pytest.mark.parametrize("language", ["glsl", "hlsl", "wgsl"])
@pytest.mark.parametrize("brick", ["pcf", "vsm"])
def test_a_scene_with_the_brick_builds_and_shadows_its_footprint_in_every_language(device, lib, tmp_path,
                                                                                    brick, language):
    scene = _scene(lib, tmp_path, brick, "pcf_texel = 0.00390625" if brick == "pcf" else "")
    # vsm's 5 × 5-texel prefilter (plus the bilinear tap) widens the penumbra past 1.15 r: 3 pixels measured
    inside, outside, band = _regions(scene, 1.15 if brick == "pcf" else VSM_OUTER)
    img, rep = _render(scene, lib, device, tmp_path / language, "specialized", language)
    assert rep.shadow_maps["sun"]["size"] == [SHADOW, SHADOW]
    lit = img[outside]
    assert lit.min() > 40 and np.ptp(lit, axis=0).max() <= 1, "the floor outside the footprint is lit, one colour"
    assert img[inside].max() == 0, f"{brick}/{language}: the footprint's inside is in shadow"


def test_pcf_softens_the_shadow_edge_where_shadow_map_has_none(device, lib, tmp_path):
    counts, images_map = {}, None
    for name, shadow, params in [("shadow_map", "shadow_map", ""),
                                 ("pcf1", "pcf", "pcf_taps = 1.0, pcf_texel = 0.00390625"),
                                 ("pcf3", "pcf", "pcf_taps = 3.0, pcf_texel = 0.00390625"),
                                 ("pcf5", "pcf", "pcf_taps = 5.0, pcf_texel = 0.00390625")]:
        scene = _scene(lib, tmp_path, shadow, params)
        inside, outside, band = _regions(scene)
        img, _ = _render(scene, lib, device, tmp_path / name)
        lit = img[outside][0]
        counts[name] = _intermediate(img, lit, band)
        if name == "pcf1":  # one tap is shadow_map's test
            assert np.array_equal(img, images_map), "pcf with k = 1 is shadow_map"
        if name == "shadow_map":
            images_map = img
    FIGURES.update(band=int(band.sum()), **counts)
    print("edge band pixels", int(band.sum()), "intermediate:", counts)
    assert counts["shadow_map"] == 0, "one compare per pixel: lit or black"
    assert counts["pcf3"] >= 10 and counts["pcf5"] > counts["pcf3"], counts


def test_pcf_is_the_same_in_both_paths(device, lib, tmp_path):
    scene = _scene(lib, tmp_path, "pcf", "pcf_texel = 0.00390625")
    a, _ = _render(scene, lib, device, tmp_path / "s", "specialized")
    b, _ = _render(scene, lib, device, tmp_path / "u", "ubershader")
    assert np.array_equal(a, b)


def test_vsm_renders_soft_edges_without_nan_in_both_paths(device, lib, tmp_path):
    from generator.runtime.renderer import moments_map

    scene = _scene(lib, tmp_path, "vsm")
    inside, outside, band = _regions(scene, VSM_OUTER)
    images = {}
    for mode in ("specialized", "ubershader"):
        img, rep = _render(scene, lib, device, tmp_path / mode, mode)
        images[mode] = img
        lit = img[outside][0]
        assert img[inside].max() == 0 and img[outside].min() > 40
        FIGURES[f"vsm_{mode}"] = _intermediate(img, lit, band)
        assert FIGURES[f"vsm_{mode}"] >= 10, FIGURES
    print("vsm: edge band (0.85 r .. 1.3 r) pixels", int(band.sum()), "intermediate:", FIGURES)
    assert np.array_equal(images["specialized"], images["ubershader"])
    # the moments the depth pass writes: finite, E[d²] >= E[d]² up to float32 rounding
    m = moments_map(np.random.default_rng(1).random((32, 32)).astype(np.float32))
    assert np.isfinite(m).all() and (m[..., 1] - m[..., 0] ** 2 >= -1e-6).all()
    flat = moments_map(np.full((9, 9), 0.25, np.float32))
    assert np.allclose(flat[..., 0], 0.25) and np.allclose(flat[..., 1], 0.0625), "a box of one depth keeps it"


def test_vsm_light_bleeding_figure_of_the_docstring():
    """Two occluders in one filter region (half at 0.2, half at 0.5), a receiver at 0.6: Chebyshev's bound lights
    a fully shadowed receiver by 0.265; the default vsm_bleed = 0.2 cuts it to 0.081 (bricks/shadow/vsm.py)."""
    from generator.runtime.renderer import moments_map

    m = moments_map(np.array([[0.2, 0.5]]), box=1)[0].astype(np.float64).mean(0)  # a tap halfway between them
    mean, var = m[0], m[1] - m[0] ** 2
    p_max = var / (var + (0.6 - mean) ** 2)
    assert abs(mean - 0.35) < 1e-6 and abs(var - 0.0225) < 1e-6
    assert abs(p_max - 0.2647) < 1e-3
    assert abs((p_max - 0.2) / 0.8 - 0.081) < 1e-3


def test_vsm_bleed_trades_umbra_light_against_penumbra_width(device, lib, tmp_path):
    """vsm_bleed = 0: the ball's own depth spread lights its umbra a little (Chebyshev's bound is not tight);
    the default 0.2 makes it black; 0.5 blackens more of the penumbra (figures in bricks/shadow/vsm.py)."""
    got = {}
    for bleed in (0.0, 0.2, 0.5):
        scene = _scene(lib, tmp_path, "vsm", f"vsm_bleed = {bleed}")
        inside, outside, band = _regions(scene, VSM_OUTER)
        img, _ = _render(scene, lib, device, tmp_path / f"b{bleed}")
        v, lit = img.sum(-1), img[outside][0].sum()
        assert v[outside].min() == lit, "nothing outside the penumbra is darkened (a NaN would be black)"
        got[bleed] = (int(v[inside].max()), int((v[band] == 0).sum()), _intermediate(img, img[outside][0], band))
    print("vsm_bleed: (umbra max, band black, band intermediate)", got)
    assert got[0.0][0] > 0 and got[0.2][0] == 0 and got[0.5][0] == 0, got
    assert got[0.0][1] < got[0.2][1] < got[0.5][1], got


def test_pcf_texel_left_unset_is_one_texel_of_the_rendered_map_in_both_paths(device, lib, tmp_path):
    """The renderer writes 1 / shadow_size into an unset pcf_texel (the brick's default is 1/512, the default map)."""
    explicit, _ = _render(_scene(lib, tmp_path, "pcf", "pcf_texel = 0.00390625"), lib, device, tmp_path / "e")
    unset = _scene(lib, tmp_path, "pcf")
    for mode in ("specialized", "ubershader"):
        img, _ = _render(unset, lib, device, tmp_path / f"u-{mode}", mode)
        assert np.array_equal(img, explicit), mode
    half, _ = _render(_scene(lib, tmp_path, "pcf", "pcf_texel = 0.001953125"), lib, device, tmp_path / "h")
    assert not np.array_equal(half, explicit), "the tap spacing changes the image"


def test_vsm_under_a_point_light_needs_a_stronger_bleed_cut(device, lib, tmp_path):
    """A point light's perspective depth: the default vsm_bleed leaves a few umbra pixels faintly lit (measured 9 of
    164, up to 9 of 255), vsm_bleed = 0.5 none (bricks/shadow/vsm.py); pcf shadows the footprint as shadow_map does."""
    from tests.runtime.test_shadows import _footprint, _scene as point_scene

    from generator.scene.load import load_scene

    for shadow, extra in [("pcf", ""), ("vsm", ", vsm_bleed = 0.5"), ("vsm", "")]:
        d = tmp_path / f"point-{next(_SERIAL)}"
        d.mkdir()
        path = point_scene(lib, d, shadow, light="point").path
        path.write_text(path.read_text().replace("color = [12.0, 12.0, 12.0]", "color = [12.0, 12.0, 12.0]" + extra))
        scene = load_scene(path, lib)
        inside, outside = _footprint(scene, lib)
        img, _ = _render(scene, lib, device, d / "out", "ubershader")
        v = img.sum(-1)
        assert v[outside].min() > 30, (shadow, extra)
        if extra or shadow == "pcf":
            assert v[inside].max() == 0, (shadow, extra)
        else:
            assert 0 < (v[inside] > 0).sum() < 0.1 * inside.sum(), "a few umbra pixels bleed"
