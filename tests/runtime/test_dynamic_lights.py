"""Dynamic light sets drawn on lavapipe (validation layer on): a loop over storage buffers draws what the static
list of the same lights draws, past the 32 a static set holds, in all three languages and all three modes.

Tolerance: 1 LSB of 8-bit output on at most 1 % of channels. The loop adds the same terms in the same order as the
unrolled static list (light k of a pair is element k of its buffer, and a single-pair set keeps the scene's
order), so only the compilers' freedom over the loop (fused multiply-adds, reassociation across an unrolled body)
differs; measured here (lavapipe, Mesa, 64 x 40): identical images, maximum difference 0, at 16 and 32 lights.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from generator.lang import SourceError
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]
W, H = 64, 40


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _scene(n: int, dynamic: bool, model: str = "") -> str:
    """A floor and a ball under n point lights on a circle, as one light set (static list or dynamic table)."""
    out = ['[materials.grey]\nbrdf = "lambert"\nparams = { rho_d = [0.8, 0.8, 0.8] }\n',
           '[materials.shiny]\nbrdf = "lambert+blinn_phong_normalized"\nparams = { rho_d = [0.5, 0.3, 0.2] }\n']
    for i in range(n):
        a = 2 * math.pi * i / n
        c = [round(0.2 + 0.6 * abs(math.sin(a + k)), 3) * 8.0 / n for k in (0.0, 2.1, 4.2)]
        out.append(f'[lights.l{i}]\ntype = "point"\nparams = {{ position = [{2.5 * math.cos(a):.4f}, 0.8, '
                   f'{2.5 * math.sin(a):.4f}], color = [{c[0]:.4f}, {c[1]:.4f}, {c[2]:.4f}] }}\n')
    names = ", ".join(f'"l{i}"' for i in range(n))
    if dynamic:
        out.append(f'[light_sets.all]\ndynamic = true\nlights = [{names}]\nmax = 256\n{model}')
    else:
        out.append(f"[light_sets]\nall = [{names}]\n")
    out += ['[[objects]]\nname = "floor"\nmaterial = "grey"\nlights = "all"\n',
            '[[objects]]\nname = "ball"\nmaterial = "shiny"\nlights = "all"\n']
    return "\n".join(out)


PLACEMENT = ('[objects.floor]\nmesh = "plane"\nscale = [4.0, 1.0, 4.0]\n[objects.ball]\nmesh = "sphere"\n'
             'translate = [0.0, 0.7, 0.0]\nscale = 0.7\n[camera]\neye = [0.0, 6.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n')


def _render(lib, device, d, text, mode="specialized", language="glsl"):
    from PIL import Image

    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene
    d.mkdir(parents=True, exist_ok=True)
    (d / "s.toml").write_text(text)
    (d / "s.placement.toml").write_text(PLACEMENT)
    scene = load_scene(d / "s.toml", lib)
    rep = render_scene(scene, lib, mode, 1, d / "out", (W, H), language, device=device)
    return scene, np.asarray(Image.open(d / "out" / "frame_0000.png").convert("RGBA")).astype(int), rep


def _agree(a, b, what):
    diff = np.abs(a - b)
    assert diff.max() <= 1 and (diff > 0).mean() <= 0.01, f"{what}: max {diff.max()}, {(diff > 0).sum()} channels"


@pytest.mark.parametrize("n", [16, 32])
def test_dynamic_point_lights_draw_what_the_static_set_draws(lib, device, tmp_path, n):
    static_scene, static, _ = _render(lib, device, tmp_path / "static", _scene(n, False))
    dyn_scene, dyn, rep = _render(lib, device, tmp_path / "dynamic", _scene(n, True))
    assert all("lights=*point/none;" in p.canonical() for p in dyn_scene.permutations.values())
    assert not any("*" in p.canonical() for p in static_scene.permutations.values())
    assert static[..., :3].max() > 40  # the lights light something
    _agree(dyn, static, f"{n} dynamic against static point lights")
    assert rep.pipelines_created == 2  # one shader per material


def test_64_dynamic_lights_render_where_a_static_set_cannot_hold_them(lib, device, tmp_path):
    with pytest.raises(SourceError, match="more than the 32 a specialized shader takes"):
        _render(lib, device, tmp_path / "static", _scene(64, False))
    _, img64, _ = _render(lib, device, tmp_path / "d64", _scene(64, True))
    _, img4, _ = _render(lib, device, tmp_path / "d4", _scene(4, True))
    assert img64[..., :3].max() > 40
    # 64 lights on the circle light the floor more evenly than 4: the same shader, another count
    assert np.abs(img64 - img4).max() > 10


def test_the_three_languages_and_the_three_modes_agree(lib, device, tmp_path):
    text = _scene(16, True, 'model = ["point/none", "spot/none"]\n')  # a pair with no light: a count of 0
    _, ref, _ = _render(lib, device, tmp_path / "glsl", text)
    for language in ("hlsl", "wgsl"):
        _agree(_render(lib, device, tmp_path / language, text, language=language)[1], ref, language)
    for mode in ("ubershader", "hybrid"):
        _agree(_render(lib, device, tmp_path / mode, text, mode=mode)[1], ref, mode)


def test_a_light_outside_the_sets_model_is_refused_at_the_set(lib, device, tmp_path):
    text = _scene(3, True, 'model = ["spot/none"]\n')
    with pytest.raises(SourceError) as e:
        _render(lib, device, tmp_path / "bad", text)
    msg = str(e.value)
    line = text.splitlines().index("lights = [\"l0\", \"l1\", \"l2\"]") + 1
    assert msg.startswith(f"{tmp_path / 'bad' / 's.toml'}:{line}:"), msg
    assert "light 'l0' (point/none) is not in the model of dynamic light set 'all' (spot/none)" in msg


def test_a_gltf_scene_made_dynamic_by_its_lights_file_draws_as_its_static_import(lib, device, tmp_path):
    from PIL import Image

    from generator.assemble.render_inputs import scene_textures
    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene
    from tests.scene.test_gltf import sample_doc
    path = sample_doc(extra_lights=True).write_gltf(tmp_path / "model.gltf")
    images = {}
    for name, sidecar in (("static", None), ("dynamic", "[light_set]\ndynamic = true\nmax = 8\n")):
        if sidecar is not None:
            (tmp_path / "model.lights.toml").write_text(sidecar)
        scene = load_scene(path, lib)
        assert bool(scene.dynamic_sets) == (sidecar is not None)
        out = tmp_path / name
        render_scene(scene, lib, "specialized", 1, out, (W, H), device=device, build=scene_textures(scene, out))
        images[name] = np.asarray(Image.open(out / "frame_0000.png").convert("RGBA")).astype(int)
    # the model's loops run in the order of its sorted pairs (directional, point_range, spot): the import's order
    assert images["static"][..., :3].max() > 40
    _agree(images["dynamic"], images["static"], "glTF lights as a dynamic set")
