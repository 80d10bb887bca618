"""Tiled dynamic light sets (culling = "tiles") on lavapipe, validation layer on: each pair's loop reads its
fragment's tile's index list (link/tiles.py), which render fills by culling each light's bounds against 16-pixel
tiles (runtime/light_tiles.py). Conservative culling loses nothing, so the tiled set draws what the untiled one
draws (tolerance as tests/runtime/test_dynamic_lights.py; measured: identical, maximum difference 0); a list that
drops a light draws a visibly different image, so the lists are what the shader reads."""
from __future__ import annotations

import math

import numpy as np
import pytest

from generator.lang import SourceError
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

W, H = 128, 80
PLACEMENT = ('[objects.floor]\nmesh = "plane"\nscale = [4.0, 1.0, 4.0]\n[objects.ball]\nmesh = "sphere"\n'
             'translate = [0.0, 0.7, 0.0]\nscale = 0.7\n[camera]\neye = [0.0, 6.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n')


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _scene(n: int, table: str = 'culling = "tiles"\n') -> str:
    """A floor and a ball under n ranged point lights and one spot on a circle: each light reaches a few tiles."""
    out = ['[materials.grey]\nbrdf = "lambert"\nparams = { rho_d = [0.8, 0.8, 0.8] }\n',
           '[materials.shiny]\nbrdf = "lambert+blinn_phong_normalized"\nparams = { rho_d = [0.5, 0.3, 0.2] }\n']
    for i in range(n):
        a = 2 * math.pi * i / n
        out.append(f'[lights.l{i}]\ntype = "point_range"\nparams = {{ position = [{2.5 * math.cos(a):.4f}, 0.5, '
                   f'{2.5 * math.sin(a):.4f}], color = [1.0, {0.4 + 0.05 * i:.2f}, 0.5], radius = 1.6 }}\n')
    out.append('[lights.spot]\ntype = "spot"\nparams = { position = [0.0, 3.0, 0.0], direction = [0.0, -1.0, 0.0], '
               'color = [2.0, 2.0, 2.0], radius = 4.0 }\n')
    names = ", ".join([f'"l{i}"' for i in range(n)] + ['"spot"'])
    out.append(f'[light_sets.all]\ndynamic = true\nlights = [{names}]\nmax = 64\n{table}')
    out += ['[[objects]]\nname = "floor"\nmaterial = "grey"\nlights = "all"\n',
            '[[objects]]\nname = "ball"\nmaterial = "shiny"\nlights = "all"\n']
    return "\n".join(out)


def _render(lib, device, d, text, language="glsl", mode="specialized"):
    from PIL import Image

    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene
    d.mkdir(parents=True, exist_ok=True)
    (d / "s.toml").write_text(text)
    (d / "s.placement.toml").write_text(PLACEMENT)
    scene = load_scene(d / "s.toml", lib)
    render_scene(scene, lib, mode, 1, d / "out", (W, H), language, device=device)
    return scene, np.asarray(Image.open(d / "out" / "frame_0000.png").convert("RGBA")).astype(int)


def _agree(a, b, what):
    diff = np.abs(a - b)
    assert diff.max() <= 1 and (diff > 0).mean() <= 0.01, f"{what}: max {diff.max()}, {(diff > 0).sum()} channels"


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_tiled_set_draws_what_the_untiled_one_draws(lib, device, tmp_path, monkeypatch):
    from generator.runtime import light_tiles
    made = []
    cull = light_tiles.cull
    monkeypatch.setattr(light_tiles, "cull", lambda *a, **k: made.append(cull(*a, **k)) or made[-1])
    _, plain = _render(lib, device, tmp_path / "plain", _scene(8, ""))
    assert plain[..., :3].max() > 40
    for language in ("glsl", "hlsl", "wgsl"):
        scene, tiled = _render(lib, device, tmp_path / language, _scene(8), language)
        assert all("lights=*point_range/none@tiles,*spot/none@tiles;" in p.canonical()
                   for p in scene.permutations.values())
        _agree(tiled, plain, f"{language}: tiled against untiled")
    # the culling culls: no tile holds every point light, and some tile at most a quarter of them
    counts = [len(t[0]) for t in made[0]]
    assert len(counts) == 8 * 5 and max(counts) < 8 and min(counts) <= 2, counts
    for mode in ("ubershader", "hybrid"):  # the ubershader reads every light: the same image
        _agree(_render(lib, device, tmp_path / mode, _scene(8), mode=mode)[1], plain, mode)


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_list_that_drops_a_light_changes_the_image(lib, device, tmp_path, monkeypatch):
    from generator.runtime import light_tiles
    _, full = _render(lib, device, tmp_path / "full", _scene(8))
    cull = light_tiles.cull

    def drop_first(*a, **k):  # light l0 (element 0 of the point_range pair) out of every tile
        return [[[x for x in ks if (p, x) != (0, 0)] for p, ks in enumerate(tile)] for tile in cull(*a, **k)]
    monkeypatch.setattr(light_tiles, "cull", drop_first)
    _, dropped = _render(lib, device, tmp_path / "dropped", _scene(8))
    assert np.abs(full - dropped).max() > 20


def test_the_buffer_layout_header_records_and_lists():
    from generator.runtime.light_tiles import tile_words
    lists = [[[0, 2], []], [[1], [0]]]  # two tiles (32 x 16 at 16 pixels), two pairs
    w = tile_words(lists, (32, 16))
    assert list(w[:4]) == [2, 1, 16, 2]
    records = w[4:12].reshape(2, 2, 2)  # (tile, pair, (offset, count))
    assert [list(w[o:o + c]) for o, c in records.reshape(-1, 2)] == [[0, 2], [], [1], [0]]
    assert len(w) % 4 == 0 and w.dtype == np.uint32


def test_bounds_cover_the_tiles_a_light_reaches():
    from generator.runtime import graphics as gx
    from generator.runtime.light_tiles import covered
    vp = gx.perspective(40.0, W / H, 0.1, 100.0) @ gx.look_at(np.array([0.0, 0.0, 5.0]), (0.0, 0.0, 0.0))
    assert covered(vp, None, (W, H), 16) is None  # no range: every tile
    assert covered(vp, (np.array([0.0, 0.0, 5.5]), 1.0), (W, H), 16) is None  # the camera inside its bounds
    x0, y0, x1, y1 = covered(vp, (np.zeros(3), 0.1), (W, H), 16)
    # a small light at the centre (pixel (64, 40): on the border of tile columns 3 and 4, inside row 2)
    assert (x0, x1, y0, y1) == (3, 4, 2, 2)
    x0, _, x1, _ = covered(vp, (np.array([100.0, 0.0, 0.0]), 0.1), (W, H), 16)
    assert x1 < x0  # off screen: no tile


# ---------------------------------------------------------------- the scene keys

def _load(tmp_path, text, name="s.toml"):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    path = tmp_path / name
    path.write_text(text)
    return load_scene(path, load_library())


@pytest.mark.parametrize("table, key, words", [
    ('culling = "tile"\n', "culling", ["culling is 'tile', not one of none, tiles", 'did you mean culling = "tiles"?']),
    ('culling = "tiles"\nloop = "switch"\n', "culling", ["a switch loop has one loop for every pair",
                                                         'use loop = "types"']),
    ('culling = 1\n', "culling", ["'light_sets.all.culling' must be a string"]),
    ('culing = "tiles"\n', "culing", ["unknown key 'culing' in light set 'all'", "did you mean 'culling'?"]),
])
def test_a_wrong_culling_is_one_located_error(tmp_path, table, key, words):
    text = _scene(2, table)
    with pytest.raises(SourceError) as e:
        _load(tmp_path, text)
    msg = str(e.value)
    line = next(i for i, x in enumerate(text.splitlines(), 1) if x.startswith(key))
    assert msg.startswith(f"{tmp_path / 's.toml'}:{line}:") and " — " in msg, msg
    assert all(w in msg for w in words), msg


def test_a_gltf_lights_file_asks_for_tiles(tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    from tests.scene.test_gltf import sample_doc
    path = sample_doc(extra_lights=True).write_gltf(tmp_path / "model.gltf")
    (tmp_path / "model.lights.toml").write_text('[light_set]\ndynamic = true\nculling = "tiles"\n')
    scene = load_scene(path, load_library(()))
    keys = {p.canonical().split(";")[1] for p in scene.permutations.values()}
    assert keys == {"lights=*directional/none@tiles,*point_range/none@tiles,*spot/none@tiles"}
    (tmp_path / "model.lights.toml").write_text('[light_set]\nculling = "tiles"\n')  # a static set
    with pytest.raises(SourceError) as e:
        load_scene(path, load_library(()))
    assert str(e.value).startswith(f"{tmp_path / 'model.lights.toml'}:2:"), str(e.value)
    assert "'culling' is for a dynamic light set" in str(e.value)
