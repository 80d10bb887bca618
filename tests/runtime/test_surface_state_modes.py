"""The surface state drawn alike by the specialized pipelines, the ubershader and the hybrid, and blended objects
sorted back to front, on lavapipe with the Khronos validation layer on (and silent).

- tests/scenes/surface_state.toml: a leaf card masked by its albedo texture's alpha (stripes), two blended balls
  (the nearer one first in scene order) and a double-sided roof seen from below, the leaf emitting a constant and
  the roof its emissive map: every mode draws the same frame, within the mode comparison's tolerance of
  tests/runtime/test_render.py (1 LSB on at most 1 % of channels; measured: identical, max difference 0, in GLSL,
  HLSL and WGSL). On the ubershader that ignored the surface state the leaf had no holes, the ball was opaque and
  the roof black (255 max, 4.4 % of channels); without the emission it is off by up to 127.
- Two blended quads given in the wrong scene order (the near one first): the near one's colour is on top in
  every mode, and the frame export's draw_order is back to front.

The masked caster's holes in the shadow are tests/runtime/test_depth_passes.py's (a masked card and ball).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "tests" / "scenes" / "surface_state.toml"
SIZE = (96, 64)
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


@pytest.fixture(autouse=True)
def _validated(monkeypatch):
    from tests.conftest import require
    from generator.runtime.probe import lavapipe_present

    require(lavapipe_present(), "no lavapipe Vulkan device")
    monkeypatch.setenv("SHADERMATRIX_VALIDATION", "1")


def _draw(scene, out: Path, mode: str, language: str = "glsl", export=None, **kw) -> tuple[np.ndarray, object]:
    """(frame 0 as RGBA int, the report) of `scene` drawn in `mode`."""
    from PIL import Image

    from generator.assemble.render_inputs import scene_textures
    from generator.library.bricks import load_library
    from generator.runtime.renderer import render_scene
    report = render_scene(scene, load_library(), mode, 1, out, size=SIZE, language=language,
                          build=scene_textures(scene, out / "build"), export=export, **kw)
    assert report.validation and report.validation_messages == [], report.validation_messages
    return np.asarray(Image.open(out / "frame_0000.png").convert("RGBA")).astype(int), report


def _agree(a, b, what):
    d = np.abs(a - b)
    assert d.max() <= 1 and (d > 0).mean() <= 0.01, f"{what}: max {d.max()}, {(d > 0).sum()} channels differ"


def test_masked_blended_and_double_sided_objects_draw_alike_in_every_mode(tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    scene = load_scene(SCENE, load_library())
    surfaces = {o["name"]: scene.permutations[o["permutation"]].surface for o in scene.objects}
    assert (surfaces["leaf"].alpha, surfaces["glass"].alpha, surfaces["roof"].double_sided) == ("mask", "blend", True)
    spec, _ = _draw(scene, tmp_path / "specialized", "specialized")
    uber, report = _draw(scene, tmp_path / "ubershader", "ubershader")
    assert report.steady.draws_ubershader == 5
    # one ubershader pipeline per distinct render state: single-sided opaque / mask, blended, double-sided
    assert report.pipelines_created == 3, report.pipelines_created
    _agree(uber, spec, "ubershader vs specialized")
    hybrid, _ = _draw(scene, tmp_path / "hybrid", "hybrid")
    _agree(hybrid, spec, "hybrid frame 0 vs specialized")
    for language in ("hlsl", "wgsl"):
        _agree(_draw(scene, tmp_path / language, "ubershader", language)[0], spec, f"{language} ubershader")
    ids, _ = _draw(scene, tmp_path / "spec_ids", "ubershader", uber_ids="specialization")
    _agree(ids, spec, "specialization-constant ubershader")
    # what the comparison covers is drawn: the roof's underside lit (blue), not culled or black
    roof = (spec[..., 2] > spec[..., 0] + 40) & (spec[..., 2] > 80)
    assert roof.sum() > 20, roof.sum()


def test_the_ubershader_without_the_mask_would_differ(tmp_path):
    """The comparison can fail: the leaf drawn opaque (its alpha mode 0 in the ubershader's material entry, as
    before) covers its stripes' holes, which the specialized frame shows through to the floor."""
    from generator.library.bricks import load_library
    from generator.link import uber
    from generator.scene.load import load_scene
    scene = load_scene(SCENE, load_library())
    spec, _ = _draw(scene, tmp_path / "specialized", "specialized")
    saved = dict(uber.ALPHA_IDS)
    try:
        uber.ALPHA_IDS["mask"] = 0  # what the renderer writes into ids.y for a masked material
        opaque, _ = _draw(scene, tmp_path / "opaque", "ubershader")
    finally:
        uber.ALPHA_IDS.update(saved)
    d = np.abs(opaque - spec).max(-1)
    assert (d > 8).sum() > 20, (d > 8).sum()


QUADS = """[scene]
name = "quads"

[materials.near]
brdf = "lambert"
alpha = "blend"
params = { rho_d = [0.9, 0.05, 0.05], base_alpha = 0.6 }

[materials.far]
brdf = "lambert"
alpha = "blend"
params = { rho_d = [0.05, 0.05, 0.9], base_alpha = 0.6 }

# a point light: the fragment stages read the world position the vertex stage writes
[lights.sun]
type = "point"
params = { position = [0.0, 3.0, 1.0], color = [12.0, 12.0, 12.0] }

[light_sets]
sun = ["sun"]

# the near quad first: scene order is front to back, the wrong order for blending
[[objects]]
name = "a"
material = "near"
lights = "sun"

[[objects]]
name = "b"
material = "far"
lights = "sun"
"""
QUADS_PLACEMENT = """[objects.a]
mesh = "plane"
translate = [0.0, 0.5, 0.0]
scale = 0.6

[objects.b]
mesh = "plane"
scale = 1.5

[camera]
eye = [0.0, 4.0, 2.0]
target = [0.0, 0.0, 0.0]
"""


@pytest.mark.parametrize("mode", ["specialized", "ubershader"])
def test_blended_quads_in_the_wrong_scene_order_are_drawn_back_to_front(tmp_path, mode):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    (tmp_path / "s.toml").write_text(QUADS)
    (tmp_path / "s.placement.toml").write_text(QUADS_PLACEMENT)
    scene = load_scene(tmp_path / "s.toml", load_library())
    img, _ = _draw(scene, tmp_path / "out", mode, export=tmp_path / "export")
    r, g, b, _ = img[SIZE[1] // 2, SIZE[0] // 2]
    # source-over, far then near: 0.6 of the near quad's red over the far one's blue (drawn the other way round
    # the blue dominates)
    assert r > b + 30, (r, g, b)
    assert json.loads((tmp_path / "export" / "frame.json").read_text())["draw_order"] == [1, 0]


def test_the_draw_order_key_is_the_view_depth_of_the_bounds_centre_ties_in_scene_order():
    from generator.runtime import graphics as gx
    from generator.runtime.placement import Placed, Placement
    from generator.runtime.renderer import draw_order
    eye = np.array([0.0, 0.0, 10.0])
    vp = gx.perspective(40.0, 1.5, 0.1, 100.0) @ gx.look_at(eye, np.zeros(3))
    objs = [Placed("opaque", "sphere", (0.0, 0.0, 5.0)), Placed("near", "sphere", (3.0, 0.0, 4.0)),
            Placed("far", "plane", (-2.0, 0.0, -6.0), (3.0, 1.0, 3.0)), Placed("tie", "sphere", (3.0, 0.0, 4.0)),
            # off-axis but nearer along the forward than `far`: its distance from the eye is larger
            Placed("side", "sphere", (9.0, 0.0, -4.0))]
    order = draw_order(Placement(objs), vp, [False, True, True, True, True])
    assert [objs[i].name for i in order] == ["opaque", "far", "side", "near", "tie"]
