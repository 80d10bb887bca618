"""Shadows of perspective lights fall where a float64 ray test of the scene's geometry says, and only the objects
of a light's sets cast them.

tests/scenes/spot_shadow.toml: a Lambert floor (8 × 8, y = 0), a box (side 1) above it under one spot light with
pcf (one tap), and an "outsider" box in a light set without the spot. The spot is the only light the floor has, so
a floor pixel is black exactly where it is shadowed. For every camera pixel that sees the floor (the camera ray
hits no box first) the test intersects, in NumPy float64, the segment from the floor point to the light with the
casters' boxes (axis-aligned: their placed bounds), and compares with the render: lit (a channel above 2) or
shadowed. Pixels within two shadow-map texels of the analytic shadow edge are left out: a floor point is far from
the edge when every point of the floor whose map position lies 1 or 2 texels from its own (16 directions) has its
shadow state. Of the rest at least 99 % must agree, for the spot (within its full-intensity cone), and for the same
scene with a point light (six 90° faces in the layers of one array) or an uberlight (within its inner superellipse) in
its place. The outsider's would-be shadow stays lit; the frame export lists the light's casters; a spot's and an
uberlight's cone rims map just inside their maps. A spot whose direction has no length is refused at its scene
line (path:line:col); a spot whose cone is wider than its map (±75°) is a warning located at the light, and a
point light among its casters' bounds is none (its six faces hold every direction).

Measured on lavapipe (Mesa 25), 160 × 112, map 256²: the spot 100.00 % of 4,050 judged pixels agree (432 of them
shadowed), the point light 100.00 % of 10,915 (368), the uberlight 100.00 % of 2,000 (365); the outsider's
would-be shadow (665, 1,009, 473 seen pixels) all lit — with every object casting (as before casters were per
light set) none of the spot's is, and 83 % agree. ~8 s.
Rendered in-process on the validated `device` (tests/lavapipe.py).
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)
from tests.runtime.test_shadows import camera_rays  # a pixel's camera ray, as the shadow test builds it

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "tests" / "scenes" / "spot_shadow.toml"
W, H = 160, 112
SHADOW = 256
AGREE = 0.99
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _copy(tmp_path: Path, name: str, edit) -> Path:
    """The test scene, its light's line edited by `edit`, with its placement beside it."""
    d = tmp_path / name
    d.mkdir()
    text = SCENE.read_text()
    line = next(x for x in text.splitlines() if x.startswith("params = { position"))
    (d / SCENE.name).write_text(text.replace(line, edit(line)))
    shutil.copy(SCENE.with_name("spot_shadow.placement.toml"), d / "spot_shadow.placement.toml")
    return d / SCENE.name


def _as_point(line: str) -> str:
    return ('params = { position = [0.4, 4.0, 0.3], color = [16.0, 16.0, 16.0], shadow_bias = 0.002, '
            'pcf_taps = 1.0 }')


UBER = {"width": 0.55, "height": 0.4, "width_edge": 0.1, "height_edge": 0.1, "roundness": 0.5, "up": [0.3, 0.0, 1.0]}


def _as_uberlight(line: str) -> str:
    shape = ", ".join(f"{k} = {v}" for k, v in UBER.items())
    return (f"params = {{ position = [0.4, 4.0, 0.3], direction = [-0.1, -1.0, -0.05], color = [16.0, 16.0, 16.0], "
            f"radius = 100.0, {shape}, shadow_bias = 0.002, pcf_taps = 1.0 }}")


def _full_intensity(kind: str, params: dict, g) -> np.ndarray:
    """Where the light shines on floor points g at full intensity (0.01 clear of where it starts to fade): a spot's
    inner cone, an uberlight's inner superellipse (the bricks' own shapes, bricks/light), everywhere for a point."""
    if kind == "point":
        return np.ones(g.shape[:-1], bool)
    axis = np.array(params["direction"], np.float64)
    axis /= np.linalg.norm(axis)
    v = g - np.array(params["position"], np.float64)
    z = v @ axis
    if kind == "spot":
        return z / np.linalg.norm(v, axis=-1) > np.cos(params["inner_angle"] - 0.01)
    x_axis = np.cross(np.array(params["up"], np.float64), axis)
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(axis, x_axis)
    e = 2.0 / params["roundness"]
    rho = ((np.abs(v @ x_axis) / params["width"]) ** e + (np.abs(v @ y_axis) / params["height"]) ** e) ** (1.0 / e)
    return (z > 0) & (rho < 0.97 * z)


def _boxes(pl) -> dict:
    """{object name: (lo, hi)} of the placed boxes: the bounds the renderer places them by (no rotation here)."""
    return {o.name: (o.corners().min(0), o.corners().max(0)) for o in pl.objects if o.mesh == "box"}


def _hits(origin, direction, box, t_max):
    """Whether the rays origin + t·direction, 1e-6 < t < t_max, meet the axis-aligned box (lo, hi): slabs, float64."""
    lo, hi = box
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (lo - origin) / direction, (hi - origin) / direction
    near = np.nanmax(np.minimum(a, b), axis=-1)
    far = np.nanmin(np.maximum(a, b), axis=-1)
    return (near <= far) & (far > 1e-6) & (near < t_max)


def _shadowed(g, light, box):
    """Whether the segment from floor points g (…, 3) to the light meets the box."""
    return _hits(g, light - g, box, 1.0 - 1e-6)


def _floor_pixels(pl):
    """(seen, g): which pixels' camera rays reach the floor before any box, and where, (H, W) and (H, W, 3)."""
    floor = next(o for o in pl.objects if o.name == "floor")
    eye, d = camera_rays(pl, W, H)
    t = (floor.translate[1] - eye[1]) / d[..., 1]
    g = eye + t[..., None] * d
    c = floor.corners()
    inside = (t > 0) & (g[..., 0] > c[:, 0].min() + 0.05) & (g[..., 0] < c[:, 0].max() - 0.05) \
        & (g[..., 2] > c[:, 2].min() + 0.05) & (g[..., 2] < c[:, 2].max() - 0.05)
    hidden = np.zeros(inside.shape, bool)
    for box in _boxes(pl).values():
        hidden |= _hits(eye, d, box, t)
    return inside & ~hidden, g


def _far_from_edge(g, light, box, matrix, size):
    """Which floor points' shadow state (by `box`) is that of every floor point 1 and 2 map texels from theirs; a
    point light's six faces (a list of six matrices): each point by its face's map (shadow_pass.cube_face)."""
    if np.size(matrix) == 6 * 16:
        from generator.runtime.shadow_pass import cube_face

        faces = np.apply_along_axis(cube_face, -1, g - light)
        out = np.zeros(faces.shape, bool)
        for k, m in enumerate(matrix):
            out |= (faces == k) & _far_from_edge(g, light, box, m, size)
        return out
    s = np.asarray(matrix, np.float64).reshape(4, 4).T  # column-major → row-major
    inv = np.linalg.inv(s)
    state = _shadowed(g, light, box)
    clip = np.concatenate([g, np.ones(g.shape[:-1] + (1,))], -1) @ s.T
    ndc = clip[..., :2] / clip[..., 3:]
    same = np.ones(state.shape, bool)
    for r in (1.0, 2.0):
        for a in np.linspace(0.0, 2.0 * np.pi, 16, endpoint=False):
            q = ndc + r * (2.0 / size) * np.array([np.cos(a), np.sin(a)])
            p = np.concatenate([q, np.full(q.shape[:-1] + (1,), 0.5), np.ones(q.shape[:-1] + (1,))], -1) @ inv.T
            p = p[..., :3] / p[..., 3:]
            k = (0.0 - light[1]) / (p[..., 1] - light[1])  # the light's ray through that texel, onto y = 0
            same &= _shadowed(light + k[..., None] * (p - light), light, box) == state
    return same


def _render(scene_path, lib, device, out, export=None):
    from PIL import Image

    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene

    scene = load_scene(scene_path, lib)
    rep = render_scene(scene, lib, "specialized", 1, out, (W, H), device=device, shadow_size=SHADOW, export=export)
    return scene, np.asarray(Image.open(out / "frame_0000.png").convert("RGB")).astype(int), rep


def _check(scene, img, rep, kind: str):
    """The ray test: (agreeing fraction, pixels compared, the outsider's would-be shadow's pixels and its lit part)."""
    from generator.runtime.placement import load_placement

    pl = load_placement(scene)
    boxes = _boxes(pl)
    L = scene.lights["spot"]
    light = np.array(L.params["position"], np.float64)
    seen, g = _floor_pixels(pl)
    seen &= _full_intensity(kind, L.params, g)
    matrix = rep.shadow_maps["spot"]["shadow_matrix"]
    expected = _shadowed(g, light, boxes["box"])
    judged = seen & _far_from_edge(g, light, boxes["box"], matrix, SHADOW)
    shadowed = img.max(-1) <= 2
    agree = (shadowed == expected)[judged].mean()
    would = seen & ~expected & _shadowed(g, light, boxes["outsider"])
    return agree, judged.sum(), expected[judged].sum(), would.sum(), (~shadowed[would]).mean() if would.any() else 0.0


@pytest.mark.parametrize("kind", ["spot", "point", "uberlight"])
def test_the_shadow_falls_where_the_ray_test_says_and_only_casters_cast(device, lib, tmp_path, kind):
    path = SCENE
    if kind != "spot":
        path = _copy(tmp_path, kind, _as_point if kind == "point" else _as_uberlight)
        path.write_text(path.read_text().replace('type = "spot"', f'type = "{kind}"', 1))
    scene, img, rep = _render(path, lib, device, tmp_path / kind, export=tmp_path / "export")
    agree, judged, in_shadow, would, lit = _check(scene, img, rep, kind)
    assert judged > 1500 and in_shadow > 100, (judged, in_shadow)
    assert agree >= AGREE, f"{kind}: {agree:.2%} of {judged} floor pixels agree with the ray test (≥ {AGREE:.0%} wanted)"
    assert would > 50, f"the outsider's would-be shadow covers {would} seen pixels: the check says little"
    assert lit == 1.0, f"{kind}: {1 - lit:.1%} of the outsider's would-be shadow is dark: it cast the light's shadow"
    assert rep.shadow_warnings == []
    frame = json.loads((tmp_path / "export" / "frame.json").read_text())
    assert frame["lights"]["spot"]["casters"] == [0, 1], "the export lists the floor and the box, not the outsider"


def test_a_spot_with_no_direction_is_refused_at_its_scene_line(device, lib, tmp_path):
    from generator.lang.errors import SourceError

    path = _copy(tmp_path, "nodir", lambda line: line.replace("[-0.1, -1.0, -0.05]", "[0.0, 0.0, 0.0]"))
    with pytest.raises(SourceError) as e:
        _render(path, lib, device, tmp_path / "out")
    lines = path.read_text().splitlines()
    row = next(i for i, x in enumerate(lines) if x.startswith("params = { position")) + 1
    col = lines[row - 1].index("direction") + 1
    assert str(e.value).startswith(f"{path}:{row}:{col}: light 'spot': direction [0.0, 0.0, 0.0] has no length"), e.value
    assert " — give the light a direction" in str(e.value)


def test_a_wide_spot_is_a_warning_at_its_line_and_a_point_light_among_its_casters_is_not(lib, tmp_path):
    """One ±75° map cannot hold a spot's cone of ±86°: a warning, located; a point light's six faces hold what lies
    beside and behind it: none (no GPU needed)."""
    from generator.runtime.placement import load_placement
    from generator.runtime.shadow_pass import casters, fit_lights
    from generator.scene.load import load_scene

    def point_at(name, position):
        path = _copy(tmp_path, name, lambda line: f"params = {{ position = {position}, color = [1.0, 1.0, 1.0] }}")
        path.write_text(path.read_text().replace('type = "spot"', 'type = "point"'))
        scene = load_scene(path, lib)
        values = {"spot": {"position": position, "color": [1.0, 1.0, 1.0]}}
        return path, fit_lights(scene, load_placement(scene), values, {"spot": casters(scene, "spot")})[1]

    assert point_at("among", [0.4, 0.8, 0.3])[1] == [], "six faces hold every direction"
    assert point_at("above", [0.4, 4.0, 0.3])[1] == []
    path = _copy(tmp_path, "wide", lambda line: line.replace("outer_angle = 0.65", "outer_angle = 1.5")
                 .replace("position = [0.4, 4.0, 0.3]", "position = [0.4, 1.0, 0.3]"))
    scene = load_scene(path, lib)
    values = {"spot": {**scene.lights["spot"].params}}
    warnings = fit_lights(scene, load_placement(scene), values, {"spot": casters(scene, "spot")})[1]
    row = next(i for i, x in enumerate(path.read_text().splitlines()) if x.startswith("params = { position")) + 1
    col = path.read_text().splitlines()[row - 1].index("direction") + 1
    assert len(warnings) == 1 and warnings[0].startswith(f"{path}:{row}:{col}: warning: light 'spot'"), warnings
    assert "'floor'" in warnings[0] and "'outsider'" not in warnings[0] and "±75°" in warnings[0]


@pytest.mark.parametrize("kind", ["spot", "uberlight"])
def test_a_cone_s_rim_lies_just_inside_its_map(kind):
    """The spot's cone (outer_angle) and the uberlight's outer superellipse's rectangle map to 1 / (1 + padding) of
    the map's half-side; a cone wider than ±75° is clamped there (no GPU needed)."""
    from generator.runtime.shadow_pass import FIT_PADDING, fit_shadow_matrix

    pos, axis = np.array([0.4, 4.0, 0.3]), np.array([0.0, -1.0, 0.0])
    casters = np.array([[-3.0, 0.0, -3.0], [3.0, 1.0, 3.0]])
    if kind == "spot":
        values = {"position": pos, "direction": axis, "outer_angle": 0.5}
        rim = [pos + axis + np.tan(0.5) * np.array([1.0, 0.0, 0.0])]
    else:
        values = {"position": pos, "direction": axis, **UBER}
        x = np.cross(UBER["up"], axis)
        x /= np.linalg.norm(x)
        y = np.cross(axis, x)
        rim = [pos + axis + (UBER["width"] + UBER["width_edge"]) * x, pos + axis + (UBER["height"] + UBER["height_edge"]) * y]
    m = fit_shadow_matrix(kind, values, casters)
    for p in rim:
        c = m @ np.append(p, 1.0)
        assert abs(np.abs(c[:2] / c[3]).max() - 1.0 / (1.0 + FIT_PADDING)) < 1e-9, c[:2] / c[3]
    z = np.c_[casters, np.ones(2)] @ m.T
    assert (z[:, 2] / z[:, 3] > 0).all() and (z[:, 2] / z[:, 3] < 1).all(), "near and far hold the casters"
    if kind == "spot":
        wide = fit_shadow_matrix(kind, {**values, "outer_angle": 1.5}, casters)
        edge = wide @ np.append(pos + axis + np.tan(np.radians(75.0)) * np.array([1.0, 0.0, 0.0]), 1.0)
        assert abs(abs(edge[0] / edge[3]) - 1.0) < 1e-9, "clamped at ±75°"
