"""`shadermatrix render`: the example scene drawn on lavapipe in three modes and three languages, agreeing per pixel.

The example is placed as a courtyard (scenes/example.placement.toml) and its sun casts shadows: a depth pass
renders its shadow map before the first frame, and both paths read the computed shadow matrix. Every render
here runs with the Khronos validation layer on (SHADERMATRIX_VALIDATION=1) and report.json lists what it said:
nothing.

Tolerance: 1 LSB of 8-bit output on at most 1 % of channels (the specialized and ubershader shaders agree to
2 float32 ulp in the compute proofs, which can cross an 8-bit rounding boundary). Measured with shadows on
(lavapipe, Mesa 25.0.7, 96 × 48, shadow map 512²): identical images (max difference 0) between the three modes,
between GLSL, HLSL and WGSL, and for the specialization-constant ubershader.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


def _render(out, mode, language="glsl", frames=2):
    env = {**os.environ, "SHADERMATRIX_VALIDATION": "1"}
    r = subprocess.run([sys.executable, "-m", "generator.cli", "render", str(EXAMPLE), "--mode", mode, "--frames",
                        str(frames), "--out", str(out), "--size", "96x48", "--language", language],
                       capture_output=True, text=True, timeout=300, cwd=REPO, env=env)
    assert r.returncode == 0, r.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["validation"] and report["validation_messages"] == [], report["validation_messages"]
    return r, report


def _image(path):
    from PIL import Image
    return np.asarray(Image.open(path).convert("RGBA"))


def _agree(a, b, what):
    d = np.abs(a.astype(np.int32) - b.astype(np.int32))
    assert d.max() <= 1 and (d > 0).mean() <= 0.01, f"{what}: max {d.max()}, {(d > 0).sum()} channels differ"


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    from tests.conftest import require
    from generator.runtime.probe import lavapipe_present

    require(lavapipe_present(), "no lavapipe Vulkan device")
    base = tmp_path_factory.mktemp("render")
    return {m: (base / m, *_render(base / m, m)) for m in ("specialized", "ubershader", "hybrid")}


def test_modes_draw_every_object_and_hybrid_converges_to_the_matrix(renders):
    objects = 6
    _, _, spec = renders["specialized"]
    _, _, uber = renders["ubershader"]
    hyb = renders["hybrid"][2]
    assert all(f["draws_specialized"] == objects and f["draws_ubershader"] == 0 for f in spec["frames"])
    assert all(f["draws_ubershader"] == objects and f["draws_specialized"] == 0 for f in uber["frames"])
    first = hyb["frames"][0]
    assert first["draws_ubershader"] + first["draws_specialized"] == objects  # no object missing in frame 0
    assert hyb["steady"]["draws_ubershader"] == 0 and hyb["steady"]["draws_specialized"] == objects
    assert spec["pipelines_created"] == 5 and uber["pipelines_created"] == 1 and hyb["pipelines_created"] == 6
    assert all(f["gpu_ms"] > 0 and f["cpu_ms"] > 0 for r in (spec, uber, hyb) for f in r["frames"])
    assert len(hyb["pipeline_create_ms"]) == 6 and hyb["time_to_first_frame_ms"] > 0


def test_the_example_is_the_courtyard_with_the_sun_s_shadow_map_from_a_depth_pass(renders):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from generator.runtime.placement import load_placement

    for _, _, rep in renders.values():
        assert rep["placement"].endswith("example.placement.toml")
        assert list(rep["shadow_maps"]) == ["sun"]  # the one light whose filter samples a texture
        sm = rep["shadow_maps"]["sun"]
        assert sm["size"] == [512, 512] and sm["sampled"] in ("depth", "r32_copy")
    m = np.array(renders["specialized"][2]["shadow_maps"]["sun"]["shadow_matrix"]).reshape(4, 4).T
    pl = load_placement(load_scene(EXAMPLE, load_library()))
    p = np.c_[pl.points(), np.ones(len(pl.points()))] @ m.T
    assert (np.abs(p[:, :2]) <= 1).all() and (0 <= p[:, 2]).all() and (p[:, 2] <= 1).all(), "covers the courtyard"


def test_the_three_modes_render_the_same_image(renders):
    images = {m: _image(d / "frame_0001.png") for m, (d, _, _) in renders.items()}
    _agree(images["ubershader"], images["specialized"], "ubershader vs specialized")
    _agree(images["hybrid"], images["specialized"], "hybrid vs specialized")
    lit = images["specialized"][..., :3].astype(int).sum(-1)
    assert (lit > 60).sum() > 1000  # the courtyard is there and lit
    # hybrid's first frame mixes the two paths (the ubershader for what has no pipeline yet): same image
    _agree(_image(renders["hybrid"][0] / "frame_0000.png"), _image(renders["specialized"][0] / "frame_0000.png"),
           "hybrid frame 0 vs specialized")


def test_a_brick_texture_without_a_test_image_renders_with_a_grey_stand_in(tmp_path):
    scene = tmp_path / "lut.toml"
    scene.write_text('[scene]\nname = "lut"\n[materials.m]\nbrdf = "lut_diffuse"\n[lights.sun]\ntype = "directional"\n'
                     'params = { color = 2.0 }\n[light_sets]\nall = ["sun"]\n[[objects]]\nname = "o"\nmaterial = "m"\n'
                     'lights = "all"\n')
    for mode in ("specialized", "ubershader"):
        r = subprocess.run([sys.executable, "-m", "generator.cli", "render", str(scene), "--bricks",
                            str(REPO / "tests" / "bricks" / "link"), "--mode", mode, "--frames", "1", "--out",
                            str(tmp_path / mode), "--size", "48x32"], capture_output=True, text=True, timeout=300,
                           cwd=REPO)
        assert r.returncode == 0, r.stderr
    _agree(_image(tmp_path / "ubershader" / "frame_0000.png"), _image(tmp_path / "specialized" / "frame_0000.png"),
           "lut: ubershader vs specialized (a scalar light colour splats on both paths)")


def test_the_three_languages_render_the_same_image(renders, tmp_path):
    ref = _image(renders["specialized"][0] / "frame_0000.png")
    for lang in ("hlsl", "wgsl"):
        _render(tmp_path / lang, "specialized", lang, frames=1)
        _agree(_image(tmp_path / lang / "frame_0000.png"), ref, f"{lang} vs glsl")
    _render(tmp_path / "uber-wgsl", "ubershader", "wgsl", frames=1)
    _agree(_image(tmp_path / "uber-wgsl" / "frame_0000.png"), ref, "wgsl ubershader vs glsl specialized")


def test_a_corrupt_pipeline_cache_is_reported_in_one_line_ignored_and_replaced(renders, tmp_path):
    out = tmp_path / "again"
    r, rep = _render(out, "specialized", frames=1)
    assert rep["cache_problem"] == "" and "warning" not in r.stderr
    cache = out / "pipeline_cache.glsl.bin"
    good = cache.read_bytes()
    cache.write_bytes(good[:10])
    r, rep = _render(out, "specialized", frames=1)
    warnings = [line for line in r.stderr.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 1 and "truncated" in warnings[0] and "ignored" in warnings[0]
    assert cache.read_bytes() == good  # replaced by what this device writes


def test_a_second_run_hits_the_persisted_shader_cache_and_a_damaged_one_only_misses(tmp_path):
    """lavapipe's VkPipelineCache holds nothing (its data is the header, creation feedback reports no hit);
    what it does keep is Mesa's shader disk cache, which the renderer puts in out/shader_cache. The counts
    are the driver's own (MESA_SHADER_CACHE_SHOW_STATS), read from what Mesa prints at tear-down."""
    from tests.conftest import require
    from generator.runtime.probe import lavapipe_present

    require(lavapipe_present(), "no lavapipe Vulkan device")
    out = tmp_path / "cached"
    r, cold = _render(out, "specialized", frames=1)
    assert "disk shader cache" not in r.stdout  # Mesa's line is taken into the report, not printed
    assert cold["shader_cache_misses"] > 0, cold  # an empty cache: the shaders are compiled
    assert cold["pipeline_cache_hits"] == 0  # lavapipe: no VkPipelineCache hits, ever
    image = _image(out / "frame_0000.png")
    _, warm = _render(out, "specialized", frames=1)
    assert warm["shader_cache_misses"] == 0 and warm["shader_cache_hits"] >= cold["shader_cache_misses"], warm
    assert (_image(out / "frame_0000.png") == image).all()
    damaged = 0
    for f in sorted((out / "shader_cache").rglob("*")):
        if f.is_file() and f.stat().st_size > 64:
            data = bytearray(f.read_bytes())
            data[len(data) // 2:] = bytes(len(data) - len(data) // 2)  # zero the second half
            f.write_bytes(bytes(data))
            damaged += 1
    assert damaged
    _, again = _render(out, "specialized", frames=1)
    assert again["shader_cache_misses"] > 0, again  # damaged entries are misses, recompiled, never trusted
    assert (_image(out / "frame_0000.png") == image).all()


def test_bad_arguments_are_one_line_errors(tmp_path):
    for args, what in [(["--size", "12"], "is not WxH"), (["--frames", "0"], "at least one frame")]:
        r = subprocess.run([sys.executable, "-m", "generator.cli", "render", str(EXAMPLE), "--out", str(tmp_path / "x"),
                            *args], capture_output=True, text=True, timeout=120, cwd=REPO)
        assert r.returncode == 2 and what in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_the_specialization_constant_ubershader_renders_the_same_image(renders, tmp_path, monkeypatch):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from generator.runtime.renderer import render_scene
    from generator.assemble.render_inputs import scene_textures

    lib = load_library()
    ref = _image(renders["specialized"][0] / "frame_0000.png")
    monkeypatch.setenv("SHADERMATRIX_VALIDATION", "1")  # the renderer's own device, validated
    for lang in ("glsl", "wgsl"):
        scene = load_scene(EXAMPLE, lib)
        rep = render_scene(scene, lib, "ubershader", 1, tmp_path / lang, (96, 48), lang, uber_ids="specialization",
                           build=scene_textures(scene, tmp_path / lang))
        assert rep.pipelines_created == 5  # one ubershader pipeline per material variant
        said = rep.validation_messages
        if lang == "wgsl":  # naga resolves the override, spirv-opt drops the constants variant's dead v_tangent
            # and v_uv (locations 2, 3) from its fragment shader: a performance warning (see test_graphics)
            said = [m for m in said if not ("Shader-OutputNotConsumed" in m and
                                            any(f"output location {x}.0 which is not consumed" in m for x in (2, 3)))]
        assert rep.validation and said == [], said
        _agree(_image(tmp_path / lang / "frame_0000.png"), ref, f"{lang} specialization-constant ubershader")
