"""The vulkan platform's conventions and the render state, as the manifest states them, hold for what the
renderer draws on lavapipe (it renders with the vulkan platform's conventions and reads the render state the
build writes: runtime/pipeline_state.py).

- clip space: world up is image up through a projection whose y points down (ndc_y `down`), and the image read
  back starts at its top row (framebuffer_origin `top-left`);
- front face: the meshes' counter-clockwise triangles are front faces under VK_FRONT_FACE_COUNTER_CLOCKWISE:
  culling the back faces of a single-sided sphere changes nothing, and a single-sided plane seen from behind
  is culled (a double-sided one is drawn), TOML objects as glTF ones;
- depth write: a blended surface writes no depth, so a blended surface drawn after it behind it still shows;
- colour attachments: a `linear` output into the `srgb` attachment stores what an `srgb` output stores into
  the `unorm` one (within one code), and the other two pairings are off by far more (not encoded, or twice).
"""
from __future__ import annotations


import numpy as np
import pytest

pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]
SIZE = (64, 48)
CLEAR = np.round(np.array([0.06, 0.07, 0.09]) * 255)  # the renderer's clear colour (UNORM)
LIGHT = """
[lights.sun]
type = "directional"
params = { direction = [0.2, 1.0, 0.6], color = [2.0, 2.0, 2.0] }

[light_sets]
sun = ["sun"]
"""


def _scene(tmp_path, name: str, materials: str, objects: dict[str, tuple[str, str]], camera: str,
           output: str = "linear") -> object:
    """A TOML scene of `materials`, lit by one sun, its objects {name: (material, placement lines)} placed as
    given, looked at by `camera` (placement lines)."""
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    d = tmp_path / name
    d.mkdir()
    objs = "".join(f'\n[[objects]]\nname = "{o}"\nmaterial = "{m}"\nlights = "sun"\n' for o, (m, _) in objects.items())
    (d / "s.toml").write_text(f'[scene]\nname = "{name}"\noutput = "{output}"\n\n{materials}\n{LIGHT}{objs}')
    (d / "s.placement.toml").write_text("".join(f"[objects.{o}]\n{p}\n" for o, (_, p) in objects.items())
                                        + f"[camera]\n{camera}\n")
    return load_scene(d / "s.toml", load_library())


def _render(scene, out, color_format: str | None = None) -> np.ndarray:
    """The frame the renderer draws of `scene` (specialized pipelines), RGB int; color_format: its colour
    attachment instead of the one the scene's output asks for (the manifest's output.attachment)."""
    from PIL import Image

    from generator.assemble.render_inputs import scene_textures
    from generator.library.bricks import load_library
    from generator.runtime import graphics as gx
    from generator.runtime.renderer import render_scene
    target = gx.OffscreenTarget
    try:
        if color_format is not None:
            gx.OffscreenTarget = lambda device, w, h, **_: target(device, w, h, color_format=color_format)
        render_scene(scene, load_library(), "specialized", 1, out, size=SIZE, build=scene_textures(scene, out))
    finally:
        gx.OffscreenTarget = target
    return np.asarray(Image.open(out / "frame_0000.png").convert("RGB")).astype(int)


def _drawn(img: np.ndarray, clear=CLEAR) -> np.ndarray:
    return np.abs(img - clear).max(-1) > 2


def _vulkan():
    from generator.assemble.platforms import PLATFORM_TABLE
    return PLATFORM_TABLE["vulkan"].conventions_section()


GREY = 'brdf = "lambert"\nparams = { rho_d = [0.7, 0.7, 0.7] }'


def test_world_up_is_the_top_of_the_image_read_back(tmp_path):
    """ndc_y `down` with the renderer's projection and framebuffer_origin `top-left`: an object above the
    camera's target lands in the image's first rows, one below it in its last."""
    assert _vulkan()["clip"] == {"depth_range": "0..1", "ndc_y": "down", "framebuffer_origin": "top-left"}
    mats = ('[materials.red]\nbrdf = "lambert"\nparams = { rho_d = [0.9, 0.0, 0.0] }\n\n'
            '[materials.green]\nbrdf = "lambert"\nparams = { rho_d = [0.0, 0.9, 0.0] }\n')
    scene = _scene(tmp_path, "updown", mats, {"high": ("red", 'mesh = "sphere"\ntranslate = [0.0, 1.4, 0.0]\n'
                                                      "scale = 0.6"),
                                              "low": ("green", 'mesh = "sphere"\ntranslate = [0.0, -1.4, 0.0]\n'
                                                      "scale = 0.6")},
                   "eye = [0.0, 0.0, 6.0]\ntarget = [0.0, 0.0, 0.0]")
    img = _render(scene, tmp_path / "updown" / "out")
    red = (img[..., 0] > img[..., 1] + 20) & _drawn(img)
    green = (img[..., 1] > img[..., 0] + 20) & _drawn(img)
    rows = np.arange(SIZE[1])[:, None]
    assert red.sum() > 50 and green.sum() > 50
    assert (rows * red).sum() / red.sum() < SIZE[1] / 2 < (rows * green).sum() / green.sum()


def test_counter_clockwise_front_faces_cull_as_the_render_state_says(tmp_path):
    """front_face `ccw` (VK_FRONT_FACE_COUNTER_CLOCKWISE): a single-sided TOML sphere (cull `back`) draws what the
    double-sided one (cull `none`) draws; a single-sided plane seen from below is culled, a double-sided one is
    drawn, and both are drawn seen from above."""
    vk = _vulkan()
    assert vk["front_face"] == {"winding": "ccw", "state": {"frontFace": "VK_FRONT_FACE_COUNTER_CLOCKWISE"}}
    mats = f'[materials.one]\n{GREY}\n\n[materials.two]\ndouble_sided = true\n{GREY}\n'
    from generator.runtime.pipeline_state import render_state
    img = {}
    for view, eye in (("below", "[0.0, -3.0, 2.0]"), ("above", "[0.0, 3.0, 2.0]")):
        for mat in ("one", "two"):
            for mesh in ("plane", "sphere"):
                name = f"{mesh}_{mat}_{view}"
                scene = _scene(tmp_path, name, mats, {"it": (mat, f'mesh = "{mesh}"\nscale = 0.8')},
                               f"eye = {eye}\ntarget = [0.0, 0.0, 0.0]")
                perm = scene.permutations[scene.objects[0]["permutation"]]
                assert render_state(perm.surface)["cull"] == ("back" if mat == "one" else "none")
                img[name] = _render(scene, tmp_path / name / "out")
    drawn = {k: int(_drawn(v).sum()) for k, v in img.items()}
    assert drawn["plane_one_below"] == 0, drawn  # seen from behind: culled
    assert drawn["plane_two_below"] > 300 and drawn["plane_one_above"] > 300 and drawn["plane_two_above"] > 300
    for view in ("below", "above"):  # a closed mesh: only front faces are ever seen
        assert drawn[f"sphere_one_{view}"] > 300
        assert np.array_equal(img[f"sphere_one_{view}"], img[f"sphere_two_{view}"]), view


def test_a_blended_surface_writes_no_depth(tmp_path):
    """render_state.depth.write is false for alpha blend: a blended plane drawn after a nearer blended one
    still shows through it (with depth written it would be hidden there)."""
    mats = ('[materials.near]\nbrdf = "lambert"\nalpha = "blend"\n'
            'params = { rho_d = [0.9, 0.1, 0.1], base_alpha = 0.5 }\n\n'
            '[materials.far]\nbrdf = "lambert"\nalpha = "blend"\n'
            'params = { rho_d = [0.1, 0.1, 0.9], base_alpha = 0.5 }\n')
    near = ("near", 'mesh = "plane"\ntranslate = [0.0, 0.5, 0.0]\nscale = 0.6')
    far = ("far", 'mesh = "plane"\nscale = 1.5')
    cam = "eye = [0.0, 4.0, 2.0]\ntarget = [0.0, 0.0, 0.0]"
    both = _scene(tmp_path, "both", mats, {"a": near, "b": far}, cam)  # scene order: the near plane first
    from generator.runtime.pipeline_state import render_state
    for o in both.objects:
        assert render_state(both.permutations[o["permutation"]].surface)["depth"] == \
            {"test": True, "write": False, "compare": "less"}
    alone = _scene(tmp_path, "alone", mats, {"a": near}, cam)
    a, b = _render(both, tmp_path / "both" / "out"), _render(alone, tmp_path / "alone" / "out")
    centre = a[SIZE[1] // 2, SIZE[0] // 2]
    assert _drawn(b)[SIZE[1] // 2, SIZE[0] // 2]  # the near plane covers the centre
    assert centre[2] > b[SIZE[1] // 2, SIZE[0] // 2][2] + 10, (centre, b[SIZE[1] // 2, SIZE[0] // 2])  # blue on top


def test_each_output_brick_s_attachment_stores_it_encoded_once(tmp_path):
    """output.attachment: `linear` into R8G8B8A8_SRGB stores what `srgb` stores into R8G8B8A8_UNORM (the
    hardware's encoding against the brick's, at most one code apart); `linear` into UNORM is not encoded (far
    darker) and `srgb` into SRGB is encoded twice (far brighter)."""
    from generator.library.bricks import load_library
    from generator.runtime.pipeline_state import COLOR_FORMATS, output_state
    lib = load_library()
    assert {b: output_state(lib.get("output", b))["attachment"] for b in ("linear", "srgb", "sqrt_gamma")} == \
        {"linear": "srgb", "srgb": "unorm", "sqrt_gamma": "unorm"}
    assert _vulkan()["attachments"]["color"] == {k: f"VK_FORMAT_{v}" for k, v in COLOR_FORMATS.items()}
    mats = '[materials.m]\nbrdf = "lambert"\nparams = { rho_d = [0.8, 0.5, 0.2] }\n'
    objects = {"ball": ("m", 'mesh = "sphere"')}
    cam = "eye = [0.0, 1.0, 3.5]\ntarget = [0.0, 0.0, 0.0]"
    img = {}
    for output in ("linear", "srgb"):
        scene = _scene(tmp_path, output, mats, objects, cam, output=output)
        for fmt in ("R8G8B8A8_UNORM", "R8G8B8A8_SRGB"):
            img[(output, fmt)] = _render(scene, tmp_path / output / fmt, color_format=fmt)
    ball = _drawn(img[("srgb", "R8G8B8A8_UNORM")]) & _drawn(img[("linear", "R8G8B8A8_UNORM")])
    assert ball.sum() > 500
    right = img[("linear", "R8G8B8A8_SRGB")][ball] - img[("srgb", "R8G8B8A8_UNORM")][ball]
    assert np.abs(right).max() <= 1, np.abs(right).max()
    dark = img[("srgb", "R8G8B8A8_UNORM")][ball] - img[("linear", "R8G8B8A8_UNORM")][ball]
    twice = img[("srgb", "R8G8B8A8_SRGB")][ball] - img[("srgb", "R8G8B8A8_UNORM")][ball]
    assert dark.max() > 40 and dark.min() >= 0 and twice.max() > 20 and twice.min() >= 0, (dark.max(), twice.max())


def test_the_renderer_draws_by_the_build_s_render_state(tmp_path):
    """Given a build, the renderer reads each permutation's render_state from its manifest: the single-sided plane
    seen from below is culled as built, and drawn when the manifest's entry says cull `none`."""
    import json
    import subprocess
    import sys

    from generator.runtime.material_textures import BuildOutputs
    from generator.runtime.renderer import render_scene
    from generator.library.bricks import load_library
    from PIL import Image
    scene = _scene(tmp_path, "built", f"[materials.one]\n{GREY}\n", {"it": ("one", 'mesh = "plane"\nscale = 0.8')},
                   "eye = [0.0, -3.0, 2.0]\ntarget = [0.0, 0.0, 0.0]")
    out = tmp_path / "built" / "build"
    r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(tmp_path / "built" / "s.toml"), "--out",
                        str(out), "-q"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    manifest = json.loads((out / "manifest.json").read_text())
    (entry,) = manifest["permutations"]
    assert entry["render_state"]["cull"] == "back"
    drawn = {}
    for cull in ("back", "none"):
        entry["render_state"]["cull"] = cull
        frames = tmp_path / "built" / cull
        render_scene(scene, load_library(), "specialized", 1, frames, size=SIZE,
                     build=BuildOutputs(json.loads(json.dumps(manifest)), out))
        drawn[cull] = int(_drawn(np.asarray(Image.open(frames / "frame_0000.png").convert("RGB")).astype(int)).sum())
    assert drawn["back"] == 0 and drawn["none"] > 300, drawn
