"""The depth passes' shaders (compose/depth.py): composed in every language and platform dialect, compiled and
validated by the real tools (glslc / glslang / naga → spirv-opt → spirv-val; glslangValidator for GL and ES),
and reflected from their SPIR-V: each stage reads exactly the blocks, textures and vertex inputs its interface
says, at the material shaders' bindings.

The scene (tests/scenes/depth_mask.toml): a floor, a card whose material masks by its albedo texture's alpha,
and one whose material masks by COLOR_0's alpha; a shadow_map sun and a vsm moon, so every unit kind is
composed: depth (position; moments), blur, and per masked permutation mask and mask_moments.
"""
from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "tests" / "scenes" / "depth_mask.toml"
LANGS = ("glsl", "hlsl", "wgsl")
pytestmark = pytest.mark.toolchain


@pytest.fixture(scope="module")
def units():
    from generator.compose.depth import DepthPlan, compose_depth_units
    from generator.library.bricks import load_library
    from generator.link import link_permutation
    from generator.scene.load import load_scene
    from generator.spec.resolve import resolve
    from generator.toolchain import CompileJob, compile_many
    from generator.toolchain.jobs import job_key, source_jobs
    from generator.toolchain.platforms import validate_dialects

    lib = load_library()
    scene = load_scene(SCENE, lib)
    linked = {h: link_permutation(resolve(p, lib), lib) for h, p in sorted(scene.permutations.items())}
    masked = {h: lp for h, lp in linked.items() if lp.perm.surface.alpha == "mask"}
    composed = compose_depth_units(DepthPlan(True, True, masked), lib, LANGS, ("gl", "essl"))
    jobs = [j for n, c in composed.items() for j in source_jobs(n, c.sources)]
    results = compile_many(jobs, optimize=True, validate=True)
    dialect_jobs = [CompileJob(job_key(n, s.stage, s.language), s.language, s.stage, s.text,
                               line_map=tuple(s.line_map)) for n, c in composed.items() for s in c.dialects]
    return composed, results, validate_dialects(dialect_jobs), masked


def test_every_unit_kind_is_composed_for_the_scene(units):
    composed, _, _, masked = units
    assert len(masked) == 2
    assert sorted(composed) == sorted(["depth", "blur", *(f"{h}.{k}" for h in masked for k in ("mask", "mask_moments"))])
    for name, c in composed.items():
        assert sorted((s.language, s.stage) for s in c.sources) == sorted((lang, st) for lang in LANGS
                                                                         for st in ("vert", "frag")), name
        assert sorted((s.language, s.stage) for s in c.dialects) == sorted((d, st) for d in ("gl", "essl")
                                                                          for st in ("vert", "frag")), name


def test_every_stage_compiles_and_validates_in_every_language_and_dialect(units):
    composed, results, dialects, _ = units
    bad = {k: r.errors() for k, r in results.items() if not (r.ok and r.spirv)}
    assert not bad, bad
    assert len(results) == 2 * len(LANGS) * len(composed)
    assert len(dialects) == 2 * 2 * len(composed) and not any(dialects.values()), dialects


def _entry(results, name, stage, lang):
    from generator.analysis.reflect import reflect

    return reflect(results[f"{name}.{stage}.{lang}"].spirv).entry(stage)


@pytest.mark.parametrize("lang", LANGS)
def test_the_opaque_caster_reads_position_frame_and_object_and_writes_only_depth(units, lang):
    composed, results, _, _ = units
    vert = _entry(results, "depth", "vert", lang)
    assert [(v.location, v.type) for v in vert.inputs] == [(0, "vec3")]  # a_position, as the material's
    assert vert.outputs == []  # nothing but gl_Position: no interpolant the fragment stage could miss
    assert sorted((r.set, r.binding, r.kind) for r in vert.resources) == [(0, 0, "uniform_buffer"),
                                                                         (2, 0, "uniform_buffer")]
    frame = next(r for r in vert.resources if r.set == 0)
    assert frame.size == 80  # view_proj, camera_pos: the material shaders' Frame
    moments = _entry(results, "depth", "frag", lang)
    assert [(v.location, v.type) for v in moments.outputs] == [(0, "vec4")] and moments.resources == []
    assert any(b.builtin == "FragCoord" for b in moments.builtins)


@pytest.mark.parametrize("lang", LANGS)
def test_a_mask_stage_reads_its_material_block_and_coverage_texture_at_the_colour_pass_bindings(units, lang):
    composed, results, _, masked = units
    for h, lp in masked.items():
        for kind in ("mask", "mask_moments"):
            name = f"{h}.{kind}"
            iface = composed[name].interface
            frag = _entry(results, name, "frag", lang)
            mb = lp.interface.block("Material")
            got = {(r.set, r.binding): r for r in frag.resources}
            assert got[(mb.set, mb.binding)].kind == "uniform_buffer" and got[(mb.set, mb.binding)].size == mb.size
            want_tex = {(t.set, t.binding) for t in lp.interface.textures if t.param == "albedo_map"}
            assert {(t.set, t.binding) for t in iface.textures} == want_tex, name
            for t in iface.textures:
                assert got[(t.set, t.binding)].kind == "sampled_image" and got[(t.set, t.binding + 1)].kind == "sampler"
            assert set(got) == {(mb.set, mb.binding), *want_tex, *((s, b + 1) for s, b in want_tex)}, name
            assert [v.location for v in frag.outputs] == ([0] if kind == "mask_moments" else []), name
            vert = _entry(results, name, "vert", lang)
            assert [v.location for v in vert.inputs] == [x.location for x in iface.vertex_inputs], name
            assert [v.location for v in frag.inputs] == [v.location for v in vert.outputs] == \
                [x.location for x in iface.interpolants], name
            assert "Kill" in _opcodes(results[f"{name}.frag.{lang}"].spirv) or \
                "DemoteToHelperInvocation" in _opcodes(results[f"{name}.frag.{lang}"].spirv), name


def test_the_textured_mask_samples_the_albedo_and_the_vertex_colour_mask_reads_color_0(units):
    composed, _, _, masked = units
    kinds = {}
    for h, lp in masked.items():
        iface = composed[f"{h}.mask"].interface
        kinds[lp.perm.surface.vertex_color] = (iface.surface, [t.param for t in iface.textures])
    assert kinds[False] == (["P", "uv"], ["albedo_map"])
    assert kinds[True] == (["P", "color"], [])


def test_the_textured_mask_reads_uv_through_the_packing_s_transform_as_the_colour_pass_does(units):
    composed, _, _, masked = units
    h, lp = next((h, lp) for h, lp in masked.items() if not lp.perm.surface.vertex_color)
    glsl = next(s.text for s in composed[f"{h}.mask"].sources if s.language == "glsl" and s.stage == "frag")
    colour = {s.name: s for s in lp.material}
    for name in ("m_uv_offset", "m_uv_scale", "m_uv_rotation", "m_base_alpha", "m_alpha_cutoff"):
        s = colour[name]  # read at the colour pass's slot of the same Material block
        assert f"material.data[{s.index}]{s.swizzle}" in glsl, name
    assert "texture_transform_map_uv(uv," in glsl and "uv_t).w" in glsl  # the coverage samples the transformed uv


@pytest.mark.parametrize("lang", LANGS)
def test_the_blur_reads_the_moments_texture_and_its_block_and_writes_moments(units, lang):
    _, results, _, _ = units
    frag = _entry(results, "blur", "frag", lang)
    got = {(r.set, r.binding): r for r in frag.resources}
    assert got[(0, 0)].kind == "sampled_image" and got[(0, 2)].kind == "uniform_buffer"
    from generator.analysis.reflect import flatten_layout

    assert flatten_layout(got[(0, 2)].members) == ["0:ivec4"] and got[(0, 2)].size == 16
    assert [(v.location, v.type) for v in frag.outputs] == [(0, "vec4")]
    vert = _entry(results, "blur", "vert", lang)
    assert [(v.location, v.type) for v in vert.inputs] == [(0, "vec3")] and vert.resources == []


def _opcodes(spirv: bytes) -> set[str]:
    """The names of the opcodes a module uses (OpKill 252, OpDemoteToHelperInvocation 5380)."""
    import struct

    words = struct.unpack(f"<{len(spirv) // 4}I", spirv)
    ops, i = set(), 5
    while i < len(words):
        n, op = words[i] >> 16, words[i] & 0xFFFF
        ops.add({252: "Kill", 5380: "DemoteToHelperInvocation"}.get(op, str(op)))
        i += max(n, 1)
    return ops
