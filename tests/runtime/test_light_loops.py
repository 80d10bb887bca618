"""A dynamic set's two light loops on lavapipe (validation layer on): `loop = "switch"` (one buffer, a switch on each
light's type) draws what `loop = "types"` (one loop per type) and the static list of the same lights draw.

Tolerance as tests/runtime/test_dynamic_lights.py's: 1 LSB of 8-bit output on at most 1 % of channels. The switch
loop adds the same terms as the types loop in the same order (its buffer holds the pairs one after another, each
pair's lights in the set's order) with one BRDF evaluation per light as both others; measured here (lavapipe,
Mesa, 64 x 40, 8 points and 8 spots): identical images, maximum difference 0, in GLSL and WGSL.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from generator.lang import SourceError
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)
from tests.runtime.test_dynamic_lights import PLACEMENT, _agree

pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]
W, H = 64, 40


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _scene(n: int, loop: str) -> str:
    """A floor and a ball under n lights on a circle, even ones point, odd ones spot; loop "" for a static set."""
    out = ['[materials.grey]\nbrdf = "lambert"\nparams = { rho_d = [0.8, 0.8, 0.8] }\n',
           '[materials.shiny]\nbrdf = "lambert+blinn_phong_normalized"\nparams = { rho_d = [0.5, 0.3, 0.2] }\n']
    for i in range(n):
        a = 2 * math.pi * i / n
        c = [round(0.2 + 0.6 * abs(math.sin(a + k)), 3) * 8.0 / n for k in (0.0, 2.1, 4.2)]
        kind, aim = ("point", "") if i % 2 == 0 else ("spot", ", direction = [0.0, -1.0, 0.0], outer_angle = 1.2")
        out.append(f'[lights.l{i}]\ntype = "{kind}"\nparams = {{ position = [{2.5 * math.cos(a):.4f}, 1.6, '
                   f'{2.5 * math.sin(a):.4f}], color = [{c[0]:.4f}, {c[1]:.4f}, {c[2]:.4f}]{aim} }}\n')
    names = ", ".join(f'"l{i}"' for i in range(n))
    if loop:
        out.append(f'[light_sets.all]\ndynamic = true\nlights = [{names}]\nloop = "{loop}"\n')
    else:
        out.append(f"[light_sets]\nall = [{names}]\n")
    out += ['[[objects]]\nname = "floor"\nmaterial = "grey"\nlights = "all"\n',
            '[[objects]]\nname = "ball"\nmaterial = "shiny"\nlights = "all"\n']
    return "\n".join(out)


def _render(lib, device, d, text, language="glsl"):
    from PIL import Image

    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene
    d.mkdir(parents=True, exist_ok=True)
    (d / "s.toml").write_text(text)
    (d / "s.placement.toml").write_text(PLACEMENT)
    scene = load_scene(d / "s.toml", lib)
    rep = render_scene(scene, lib, "specialized", 1, d / "out", (W, H), language, device=device)
    return scene, np.asarray(Image.open(d / "out" / "frame_0000.png").convert("RGBA")).astype(int), rep


@pytest.mark.parametrize("language", ["glsl", "wgsl"])
def test_the_switch_loop_draws_what_the_types_loop_and_the_static_list_draw(lib, device, tmp_path, language):
    _, static, _ = _render(lib, device, tmp_path / "static", _scene(16, ""), language)
    types_scene, types, _ = _render(lib, device, tmp_path / "types", _scene(16, "types"), language)
    switch_scene, switch, rep = _render(lib, device, tmp_path / "switch", _scene(16, "switch"), language)
    assert all("lights=*point/none,*spot/none;" in p.canonical() for p in types_scene.permutations.values())
    assert all("lights=**point/none,**spot/none;" in p.canonical() for p in switch_scene.permutations.values())
    assert rep.pipelines_created == 2  # one shader per material
    assert static[..., :3].max() > 40  # the lights light something
    # the spots alone light their own pools: a switch that read every light as a point would differ
    _agree(switch, types, f"{language}: switch against types")
    _agree(switch, static, f"{language}: switch against the static list")


def test_the_switch_buffer_holds_each_pair_after_the_other_with_its_id(lib, tmp_path):
    from generator.link import link_permutation
    from generator.link.values import light_buffer_of, light_buffers
    from generator.scene.load import load_scene
    (tmp_path / "s.toml").write_text(_scene(5, "switch"))
    scene = load_scene(tmp_path / "s.toml", lib)
    dyn = scene.dynamic_sets["all"]
    perm = next(iter(scene.permutations.values()))
    c = link_permutation(perm, lib)  # values read its .interface, as a Composed's
    block = light_buffer_of(c.interface, 1)
    assert block is light_buffer_of(c.interface, 0) and block.name == "LightBuffer0"
    stride = block.members[0]["array_stride"]
    data = light_buffers(scene, scene.light_sets["all"], dyn, c)[block.name]
    assert len(data) == 5 * stride
    ids = [int.from_bytes(data[k * stride:k * stride + 4], "little") for k in range(5)]
    assert ids == [0, 0, 0, 1, 1]  # l0, l2, l4 (points), then l1, l3 (spots)


def test_an_unknown_loop_is_a_located_error_with_the_closest_name(lib, tmp_path):
    from generator.scene.load import load_scene
    text = _scene(2, "swich")
    (tmp_path / "s.toml").write_text(text)
    with pytest.raises(SourceError) as e:
        load_scene(tmp_path / "s.toml", lib)
    msg = str(e.value)
    line = text.splitlines().index('loop = "swich"') + 1
    assert msg.startswith(f"{tmp_path / 's.toml'}:{line}:"), msg
    assert "loop is 'swich', not one of types, switch" in msg and 'did you mean loop = "switch"' in msg, msg


def test_a_rebuild_that_composes_nothing_keeps_the_switch_sets_fill(tmp_path):
    """The manifest's dynamic set entry of a build that composed none of its permutations (only the set's max
    changed) is the last build's with the scene's capacity: its fill stays the switch buffer's."""
    import json
    import subprocess
    import sys

    from generator.assemble.reflection import FILL_SWITCH
    from tests.assemble.test_manifest_schema import REPO
    scene, out = tmp_path / "s.toml", tmp_path / "out"

    def build():
        r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(out),
                            "--platform", "vulkan"], cwd=REPO, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, r.stderr[-3000:]
        return json.loads((out / "manifest.json").read_text())["dynamic_light_sets"]["all"], r.stdout

    scene.write_text(_scene(4, "switch"))
    first, _ = build()
    scene.write_text(_scene(4, "switch").replace('loop = "switch"\n', 'loop = "switch"\nmax = 8\n'))
    second, said = build()
    assert "(2 up to date" in said and " 0 shaders" in said, said
    assert first["fill"] == second["fill"] == FILL_SWITCH
    assert second["loop"] == "switch" and second["max"] == 8 != first["max"]
    assert [p["first"] for p in second["pairs"]] == [p["first"] for p in first["pairs"]] == [0, 2]
