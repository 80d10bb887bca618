"""The depth passes drawn with the generated depth shaders (runtime/depth_passes.py, by the description
runtime/shadow_pass.py gives the build and the renderer alike), on the validated lavapipe device.

- The moments stage and the GPU blur against shadow_pass.moments_map, the CPU reference: the moments stage writes
  the depth pass's depth exactly and its square to float32 rounding, and the two blur passes give the 5 × 5 clamped
  box of moments_map within 2 float32 ulp of 1 (measured on lavapipe, Mesa 25.0.7, the shadow scene's 256² map:
  max |GPU − CPU| = 1.2e-7 in GLSL, HLSL and WGSL alike).
- A masked material's caster discards what its coverage cuts: a card masked by its albedo texture's alpha, with a
  transparent square in its middle, leaves the floor's depth in the map there, and only there (the opaque unit
  draws the card whole); its hole covers the transparent quarter of the card.
- Through the renderer: a masked ball whose coverage (base_alpha) is below its cutoff casts no shadow at all, one
  above it shadows its footprint like an opaque one.
"""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

REPO = Path(__file__).resolve().parents[2]
SHADOW_SCENE = REPO / "tests" / "scenes" / "shadow.toml"
MASK_SCENE = REPO / "tests" / "scenes" / "depth_mask.toml"
LANGS = ("glsl", "hlsl", "wgsl")
pytestmark = [pytest.mark.lavapipe, pytest.mark.toolchain]


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


class Passes:
    """The depth units of a scene compiled in one language, a DepthPasses drawing them, what it owns."""

    def __init__(self, device, lib, scene, language):
        from generator.compose.depth import compose_depth_units
        from generator.link import link_permutation
        from generator.runtime.depth_passes import DepthPasses
        from generator.runtime.shadow_pass import depth_plan, shadowed_lights
        from generator.spec.resolve import resolve
        from generator.toolchain import compile_many
        from generator.toolchain.jobs import source_jobs

        self.scene, self.lib, self.device = scene, lib, device
        resolved = {h: resolve(p, lib) for h, p in sorted(scene.permutations.items())}
        self.linked = {h: link_permutation(r, lib) for h, r in resolved.items()}
        self.shadowed = shadowed_lights(scene, resolved.values())
        self.plan = depth_plan(self.shadowed, self.linked)
        self.units = compose_depth_units(self.plan, lib, (language,))
        results = compile_many([j for n, c in self.units.items() for j in source_jobs(n, c.sources)])
        self.spirv = {(n, s.stage): results[f"{n}.{s.stage}.{language}"].spirv for n, c in self.units.items()
                      for s in c.sources}
        self.owned = []
        self.passes = DepthPasses(device, self.spirv, {n: c.interface for n, c in self.units.items()}, self.owned)

    def desc(self, light, size=256):
        from generator.runtime.shadow_pass import VULKAN_CONVENTIONS, MOMENTS, depth_pass, pass_units

        textures = self.shadowed[light]
        L = self.scene.lights[light]
        return depth_pass(L, textures, dict(L.params), pass_units(self.plan, MOMENTS in textures), [], size,
                          {"vulkan": VULKAN_CONVENTIONS})

    def buffer(self, data: bytes):
        b = self.device.buffer(len(data), self.device.vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT)
        b.write(np.frombuffer(data, np.uint8))
        self.owned.append(b)
        return b

    def mesh(self, kind):
        from generator.runtime.graphics import GpuMesh
        from generator.runtime.placement import make_mesh

        m = GpuMesh(self.device, make_mesh(kind))
        self.owned.append(m)
        return m

    def close(self):
        for x in reversed(self.owned):
            x.destroy()


def _model(translate=(0.0, 0.0, 0.0), scale=1.0):
    m = np.diag([scale, scale, scale, 1.0])
    m[:3, 3] = translate
    return m


@pytest.mark.parametrize("language", LANGS)
def test_the_gpu_moments_and_blur_match_moments_map(device, lib, tmp_path, language):
    from generator.runtime.depth_passes import Caster
    from generator.runtime.graphics import object_bytes
    from generator.runtime.placement import load_placement
    from generator.runtime.shadow_pass import fit_shadow_matrix, moments_map
    from generator.scene.load import load_scene

    d = tmp_path / "vsm"
    d.mkdir()
    text = SHADOW_SCENE.read_text()
    text = text.replace("[light_sets]", '[lights.moon]\ntype = "directional"\nshadow = "vsm"\n'
                                        'params = { direction = [-0.6, 1.0, 0.2], color = [0.2, 0.2, 0.2] }\n\n'
                                        "[light_sets]").replace('sun = ["sun"]', 'sun = ["sun", "moon"]')
    (d / "shadow.toml").write_text(text)
    shutil.copy(SHADOW_SCENE.with_name("shadow.placement.toml"), d / "shadow.placement.toml")
    scene = load_scene(d / "shadow.toml", lib)
    p = Passes(device, lib, scene, language)
    try:
        placed = load_placement(scene)
        casters = [Caster(p.mesh(o.mesh), p.buffer(object_bytes(o.model))) for o in placed.objects]
        m = fit_shadow_matrix("directional", scene.lights["moon"].params, placed.points())
        eye = np.append(placed.points().mean(0), 1.0)
        depth_desc = {**p.desc("moon"), "kind": "depth"}  # the same light drawn as a depth map
        depth_desc["casters"] = p.desc("sun")["casters"]
        depth = p.passes.draw(depth_desc, m, eye, casters).depth.read()
        drawn = p.passes.draw(p.desc("moon"), m, eye, casters)
        assert drawn.depth is None and drawn.units == ["depth", "blur"]
        raw, blurred = drawn.unblurred.read(), drawn.blurred.read()
    finally:
        p.close()
    covered = depth < 1.0
    assert 0.2 < covered.mean() < 0.9, "the floor and the ball fill part of the map"
    assert np.array_equal(raw[..., 0], depth), "the moments stage writes the depth the depth pass stores"
    assert np.abs(raw[..., 1] - depth.astype(np.float64) ** 2).max() <= 6e-8  # d² to float32 rounding
    assert (raw[~covered] == [1.0, 1.0, 0.0, 1.0]).all(), "cleared to the far plane's moments"
    ref = moments_map(depth)
    err = np.abs(blurred.astype(np.float64) - ref).max()
    assert err <= 2.4e-7, err
    assert np.abs(blurred - raw).max() > 0.01, "the blur does blur (edges of the ball move by more than rounding)"


def _mask_setup(p):
    """The floor and the textured masked card of tests/scenes/depth_mask.toml, the card's material resources:
    its Material block (base_alpha 1, alpha_cutoff 0.5) and a 16 × 16 albedo whose middle 8 × 8 is transparent."""
    from generator.link.interface import pack
    from generator.runtime.depth_passes import mask_interface, mask_resources

    h = next(h for h, lp in p.linked.items() if lp.perm.surface.alpha == "mask" and not lp.perm.surface.vertex_color)
    lp = p.linked[h]
    mb = lp.interface.block("Material")
    values = {s.name: s.spec.default for s in lp.material if s.spec is not None}
    values.update(m_base_alpha=1.0, m_alpha_cutoff=0.5)
    material = p.buffer(pack(lp.material, values, mb.size // 16))
    albedo = np.full((16, 16, 4), 200, np.uint8)
    albedo[4:12, 4:12, 3] = 0
    image = p.device.image(albedo, srgb=True)
    sampler = p.device.sampler()
    p.owned += [image, sampler]
    res = mask_resources(mask_interface(p.units, h), material, {"albedo_map": image}, sampler)
    return h, res


def test_a_masked_card_leaves_a_hole_where_its_texture_is_transparent(device, lib):
    from generator.runtime.depth_passes import Caster
    from generator.runtime.graphics import object_bytes
    from generator.runtime.shadow_pass import fit_shadow_matrix
    from generator.scene.load import load_scene

    p = Passes(device, lib, load_scene(MASK_SCENE, lib), "glsl")
    try:
        h, res = _mask_setup(p)
        plane = p.mesh("plane")
        floor = Caster(plane, p.buffer(object_bytes(_model(scale=2.0))))
        card = p.buffer(object_bytes(_model((0.0, 1.0, 0.0))))
        pts = np.array([[x, y, z] for x in (-2, 2) for y in (0, 1) for z in (-2, 2)], np.float64)
        m = fit_shadow_matrix("directional", {"direction": [0.0, 1.0, 0.0]}, pts)  # straight down
        desc = p.desc("sun", 128)
        maps = {}
        for kind, caster in (("masked", Caster(plane, card, h, res)), ("opaque", Caster(plane, card))):
            maps[kind] = p.passes.draw(desc, m, np.zeros(4), [floor, caster]).depth.read()
    finally:
        p.close()
    card_depth = maps["opaque"].min()
    on_card = np.isclose(maps["opaque"], card_depth, atol=1e-5)
    floor_depth = np.median(maps["opaque"][~on_card & (maps["opaque"] < 1)])
    hole = on_card & np.isclose(maps["masked"], floor_depth, atol=1e-5)
    kept = on_card & np.isclose(maps["masked"], card_depth, atol=1e-5)
    assert on_card.sum() > 500 and (hole | kept)[on_card].all(), "each card texel is the card or the floor"
    assert 0.2 < hole.sum() / on_card.sum() < 0.3, "the transparent quarter of the texture is cut out"
    rows, cols = np.nonzero(on_card)
    hr, hc = np.nonzero(hole)
    assert abs(hr.mean() - rows.mean()) < 1 and abs(hc.mean() - cols.mean()) < 1, "the hole is the card's middle"
    assert not (maps["masked"][~on_card] != maps["opaque"][~on_card]).any(), "the floor is the same elsewhere"


@pytest.mark.parametrize("base_alpha, shadowed", [(0.2, False), (1.0, True)])
def test_a_masked_ball_casts_a_shadow_only_where_its_coverage_passes_the_cutoff(device, lib, tmp_path, base_alpha,
                                                                                shadowed):
    from PIL import Image

    from generator.runtime.renderer import render_scene
    from generator.scene.load import load_scene
    from tests.runtime.test_shadows import H, W, _footprint

    d = tmp_path / "masked"
    d.mkdir()
    text = SHADOW_SCENE.read_text().replace(
        '[light_sets]', f'[materials.cutout]\nbrdf = "lambert"\nalpha = "mask"\n'
                        f'params = {{ rho_d = [0.8, 0.8, 0.8], base_alpha = {base_alpha} }}\n\n[light_sets]')
    text = text.replace('name = "ball"\nmaterial = "grey"', 'name = "ball"\nmaterial = "cutout"')
    (d / "shadow.toml").write_text(text)
    shutil.copy(SHADOW_SCENE.with_name("shadow.placement.toml"), d / "shadow.placement.toml")
    scene = load_scene(d / "shadow.toml", lib)
    rep = render_scene(scene, lib, "specialized", 1, d / "out", (W, H), device=device, shadow_size=256)
    assert any(u.endswith(".mask") for u in rep.shadow_maps["sun"]["depth_units"]), rep.shadow_maps
    img = np.asarray(Image.open(d / "out" / "frame_0000.png").convert("RGB")).astype(int)
    inside, outside = _footprint(scene, lib)
    lit = img[outside].min()
    assert lit > 40
    if shadowed:
        assert img[inside].max() == 0, "coverage 1 ≥ 0.5: the ball's depth is drawn and shadows its footprint"
    else:
        assert img[inside].min() >= lit - 1, "coverage 0.2 < 0.5: the ball is cut from the depth pass, no shadow"
