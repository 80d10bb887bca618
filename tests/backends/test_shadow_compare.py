"""Hardware depth compare: texture2d_shadow and sample_compare, and the pcf_hardware brick.

tests/bricks/lang/ext_shadow_compare.py reads a depth texture through its comparison sampler in a compute
kernel per language (GLSL sampler2DShadow, HLSL SamplerComparisonState, WGSL texture_depth_2d +
sampler_comparison); lavapipe's linear comparison sampler (compareOp LESS_OR_EQUAL) and the NumPy target's
emulation (the bilinear weights of the 2 × 2 footprint applied to the four compares) are compared on a
shadow edge: a depth map with a step, sampled across it with references on both sides of the step and
between texels. A comparison result is a sum of bilinear weights, so one wrong compare moves it by that
texel's weight (random sub-texel positions: far above the tolerance), while lavapipe's float32 weights
agree to 1.5e-7 (measured, Mesa 25.0).

The scenes are tests/scenes/shadow.toml (tests/runtime/test_shadows_filtered.py) with the sun's shadow swapped for
pcf_hardware: it renders in the three languages and both paths, its manifest entry says depth format and
comparison sampler as the SPIR-V declares them, and an ubershader binds comparison and plain shadow slots
side by side (with lit stand-ins where a draw has fewer shadowed lights).
"""
from __future__ import annotations

import numpy as np
import pytest

from generator.lang import ir, parse_module
from generator.lang.types import TEXTURE2D_SHADOW
from generator.backends import get_target
from tests.lavapipe import device, no_validation_messages  # noqa: F401  (fixtures)
from tests.regen_goldens import REPO

BRICK = REPO / "tests" / "bricks" / "lang" / "ext_shadow_compare.py"
GLOBALS = [ir.Global("depth", TEXTURE2D_SHADOW, 0, 2)]

SHELL = {
    "glsl": "#version 450\n{header}\nlayout(local_size_x = 1) in;\n"
            "layout(std430, set = 0, binding = 0) readonly buffer S {{ vec4 s[]; }} smp;\n"
            "layout(std430, set = 0, binding = 1) buffer R {{ vec4 r[]; }} res;\n{functions}\n"
            "void main() {{ uint i = gl_GlobalInvocationID.x;\n"
            "  res.r[i] = vec4({fn}(depth, {s}, smp.s[i].xy, smp.s[i].z)); }}\n",
    "hlsl": "[[vk::binding(0, 0)]] StructuredBuffer<float4> smp : register(t0, space0);\n"
            "[[vk::binding(1, 0)]] RWStructuredBuffer<float4> res : register(u1, space0);\n{functions}\n"
            "[numthreads(1, 1, 1)] void main(uint3 id : SV_DispatchThreadID) {{ uint i = id.x;\n"
            "  res[i] = float4({fn}(depth, {s}, smp[i].xy, smp[i].z).xxxx); }}\n",
    "wgsl": "@group(0) @binding(0) var<storage, read> smp: array<vec4<f32>>;\n"
            "@group(0) @binding(1) var<storage, read_write> res: array<vec4<f32>>;\n{functions}\n"
            "@compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{ let i = id.x;\n"
            "  res[i] = vec4<f32>({fn}(depth, {s}, smp[i].xy, smp[i].z)); }}\n",
}


def edge_inputs(rng, n=512, h=6, w=8):
    """A depth map with a shadow edge (0.3 left of column 4, 0.7 from it, a little noise; the last row at the
    far plane, 1.0, where nothing was drawn) and samples across it: uv over the whole map and past its
    borders (clamp-to-edge), references below, between and above the depths, and past the far plane (1.05:
    a D32_SFLOAT reference is not clamped to [0, 1], so it is shadowed even against 1.0 — on lavapipe too)."""
    depth = np.where(np.arange(w)[None, :] < w // 2, 0.3, 0.7) + rng.uniform(-0.02, 0.02, (h, w))
    depth[-1] = 1.0
    uv = rng.uniform(-0.2, 1.2, (n, 2))
    ref = rng.choice([0.1, 0.29, 0.31, 0.5, 0.69, 0.71, 0.9, 1.05], n) + rng.uniform(-0.005, 0.005, n)
    samples = np.zeros((n, 4), np.float32)
    samples[:, :2], samples[:, 2] = uv, ref
    return depth.astype(np.float32), samples


def _compile(jobs_of):
    from generator.toolchain import compile_many

    jobs = list(jobs_of.values())
    compiled = compile_many(jobs)
    for job in jobs:
        assert compiled[job.key].ok, "\n".join(compiled[job.key].errors())
    return {lang: compiled[job.key].spirv for lang, job in jobs_of.items()}


def _kernels():
    from generator.toolchain import CompileJob

    m = parse_module(BRICK.read_text(), str(BRICK.relative_to(REPO)))
    jobs = {}
    for lang, shell in SHELL.items():
        t = get_target(lang)
        text = t.emit([], list(m.functions.values()), GLOBALS).text
        jobs[lang] = CompileJob(f"cmp.{lang}", lang, "comp", shell.format(
            header=t.header(), functions=text, fn=t.ident("compare"), s=t.sampler_name("depth")))
    return m, jobs


@pytest.mark.parametrize("body, words", [
    ("def f(t: texture2d_shadow, uv: vec2) -> vec4:\n    return sample_level(t, uv, 0.0)\n",
     "sample_level() cannot read a texture2d_shadow"),
    ("def f(t: texture2d, uv: vec2) -> float:\n    return sample_compare(t, uv, 0.5)\n",
     "sample_compare(texture2d, vec2, float) is not defined"),
    ("def f(t: texture2d_shadow, uv: vec2) -> float:\n    return sample_compare(t, uv, 1)\n",
     "sample_compare(texture2d_shadow, vec2, int) is not defined"),
])
def test_a_depth_texture_is_read_only_by_sample_compare_and_only_it(body, words):
    from generator.lang import SourceError

    with pytest.raises(SourceError) as e:
        parse_module('"""A test brick."""\nBRICK = {"kind": "shadow"}\n\n' + body, "b.py")
    assert words in str(e.value) and "b.py:5:12" in str(e.value), str(e.value)


@pytest.mark.toolchain
def test_the_three_languages_declare_a_depth_texture_and_a_comparison_sampler():
    m, jobs = _kernels()
    want = {"glsl": ("uniform texture2D depth;", "uniform samplerShadow _smp_depth;", "sampler2DShadow("),
            "hlsl": ("Texture2D depth", "SamplerComparisonState _smp_depth", ".SampleCmpLevelZero("),
            "wgsl": ("var depth: texture_depth_2d;", "var _smp_depth: sampler_comparison;",
                     "textureSampleCompareLevel(")}
    for lang, job in jobs.items():
        for piece in want[lang]:
            assert piece in job.source, (lang, piece)
    _compile(jobs)  # glslc / naga, spirv-opt and spirv-val on each


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_lavapipe_and_numpy_filter_the_same_compares_on_a_shadow_edge(device):
    from generator.runtime.compute import SAMPLED_IMAGE, SAMPLER, STORAGE, ComputePipeline
    from generator.runtime.depth_images import ComparisonSampler, DepthImage

    m, jobs = _kernels()
    spirv = _compile(jobs)
    depth, samples = edge_inputs(np.random.default_rng(13))
    nt = get_target("numpy")
    fns = nt.load(nt.emit([], list(m.functions.values())), np.float32)
    want = fns["compare"](depth, samples[:, :2], samples[:, 2]).astype(np.float64)
    assert 0.2 < (want == 1.0).mean() < 0.8 and ((want > 0) & (want < 1)).sum() > 50, "both sides and the edge"
    image, sampler = DepthImage(device, depth), ComparisonSampler(device)
    usage = device.vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT
    src, dst = device.buffer(samples.nbytes, usage), device.buffer(samples.nbytes, usage)
    try:
        src.write(samples)
        for lang, code in spirv.items():
            pipe = ComputePipeline(device, code, (STORAGE, STORAGE, SAMPLED_IMAGE, SAMPLER))
            try:
                pipe.bind([src, dst, image, sampler])
                pipe.dispatch(len(samples))
                got = dst.array(np.float32)[:samples.size].reshape(-1, 4)[:, 0].astype(np.float64)
            finally:
                pipe.destroy()
            # lavapipe weighs in float32 (measured: 1.5e-7); one wrong compare would move a result by ≥ 1/16
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-6,
                                       err_msg=f"{lang}: lavapipe and NumPy filter the compares differently")
    finally:
        for obj in (src, dst, image, sampler):
            obj.destroy()


# ------------------------------------------------------------------ the pcf_hardware brick in scenes

# The floor of tests/scenes/shadow.toml is tilted against the sun's map: a compare against a texel up to one
# texel away from P needs the bias to cover the depth slope over that distance (shadow_bias 0.003, enough for
# pcf's compares against the bilinearly interpolated depth, acnes the lit floor: measured on lavapipe, 256²
# map, k = 1 needs 0.006 and k = 3 0.01): the scenes here use 0.01. The taps' footprint is the bias's
# business, as in every PCF.
def _hw_scene(lib, tmp_path, shadow="pcf_hardware", taps=3):
    from tests.runtime.test_shadows_filtered import _scene

    scene = _scene(lib, tmp_path, shadow, f"pcf_taps = {float(taps)}, pcf_texel = 0.00390625")
    scene.path.write_text(scene.path.read_text().replace("shadow_bias = 0.003", "shadow_bias = 0.01"))
    from generator.scene.load import load_scene
    return load_scene(scene.path, lib)


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def test_pcf_hardware_samples_a_texture2d_shadow(lib):
    b = lib.get("shadow", "pcf_hardware")
    (f,) = [f for f in b.entries if f.name == "shadow"]
    assert {p.name: str(p.ty) for p in f.params}["shadow_depth"] == "texture2d_shadow"
    assert list(b.textures) == ["shadow_depth"] and "pcf_taps" in b.params and "pcf_texel" in b.params


@pytest.mark.toolchain
def test_the_manifest_reflects_a_depth_texture_and_its_comparison_sampler_as_the_spirv_declares(lib, tmp_path):
    import json

    from generator.analysis.reflect import reflect
    from generator.assemble import BuildContext, build
    from tests.assemble.test_manifest import _expected_resources, _reflected_resources

    res = build(_hw_scene(lib, tmp_path), tmp_path / "out", BuildContext(lib))
    assert res.ok, res.failures
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    (perm,) = manifest["permutations"]
    for iface, languages in [(perm["interface"], perm["languages"]),
                             (manifest["ubershader"]["interface"], manifest["ubershader"]["languages"])]:
        (tex,) = [t for t in iface["frag"]["textures"] if t["name"] == "shadow_depth"]
        assert tex["sampler"] == "comparison" and tex["format"] == "depth" and tex["compare_op"] == "less_or_equal"
        assert tex["dimension"] == "2d" and tex["sampler_binding"] == tex["binding"] + 1
        want = [r for r in _expected_resources(iface["frag"]) if r[2] in ("sampled_image", "sampler")]
        for lang, stages in languages.items():
            entry = reflect((tmp_path / "out" / stages["frag"]["spirv"]).read_bytes()).entry("frag")
            got = [r for r in _reflected_resources(entry) if r[2] in ("sampled_image", "sampler")]
            assert got == want, lang  # the image at B, the (comparison) sampler at B + 1, in every language


def _footprint_figures(scene, img):
    from tests.runtime.test_shadows_filtered import _intermediate, _regions

    inside, outside, band = _regions(scene)
    lit = img[outside]
    assert lit.min() > 40 and np.ptp(lit, axis=0).max() <= 1, "the floor outside the footprint is lit, one colour"
    assert img[inside].max() == 0, "the footprint's inside is in shadow"
    return _intermediate(img, lit[0], band), int(band.sum())


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", ["glsl", "hlsl", "wgsl"])
def test_a_scene_with_pcf_hardware_renders_its_soft_footprint_in_every_language(device, lib, tmp_path, language):
    from tests.runtime.test_shadows_filtered import SHADOW, _render

    scene = _hw_scene(lib, tmp_path)
    img, rep = _render(scene, lib, device, tmp_path / language, "specialized", language)
    assert rep.shadow_maps["sun"]["size"] == [SHADOW, SHADOW] and rep.shadow_maps["sun"]["sampled"] == "depth"
    soft, band = _footprint_figures(scene, img)
    assert soft >= 30, (soft, band)


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_pcf_hardware_filters_where_pcf_steps_and_is_the_same_in_both_paths(device, lib, tmp_path):
    """One tap of pcf_hardware already filters 2 × 2 compares (pcf with k = 1 is shadow_map: none
    intermediate); at k = 3 it leaves more of the edge band between black and lit than pcf does."""
    from tests.runtime.test_shadows_filtered import _render

    counts = {}
    for shadow, taps in [("pcf", 1), ("pcf_hardware", 1), ("pcf", 3), ("pcf_hardware", 3)]:
        scene = _hw_scene(lib, tmp_path, shadow, taps)
        img, _ = _render(scene, lib, device, tmp_path / f"{shadow}{taps}", "specialized")
        counts[f"{shadow}{taps}"] = _footprint_figures(scene, img)[0]
        if (shadow, taps) == ("pcf_hardware", 3):
            uber, _ = _render(scene, lib, device, tmp_path / "uber", "ubershader")
            assert np.array_equal(img, uber), "the ubershader binds the same depth image and comparison sampler"
    print("edge band intermediate pixels:", counts)
    assert counts["pcf1"] == 0 and counts["pcf_hardware1"] >= 10, counts
    assert counts["pcf_hardware3"] > counts["pcf3"], counts


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_an_ubershader_binds_depth_compares_beside_plain_shadow_maps_and_lit_stand_ins(device, lib, tmp_path):
    """The sun casts pcf_hardware, a second light shadow_map: the ubershader binds a comparison slot and a plain
    slot per shadowed light. The floor sees both lights; the ball only the second, so the ball's draws read
    the second light's depth through the comparison slot 0 and a lit 1×1 depth image in slot 1."""
    import shutil

    from generator.scene.load import load_scene
    from tests.runtime.test_shadows_filtered import SCENE, _render

    text = SCENE.read_text().replace('shadow = "shadow_map"', 'shadow = "pcf_hardware"')
    text = text.replace("shadow_bias = 0.003", "shadow_bias = 0.01").replace('[light_sets]\nsun = ["sun"]', """\
[lights.sky]
type = "directional"
shadow = "shadow_map"
params = { direction = [-0.5, 1.0, 0.2], color = [0.3, 0.3, 0.3], shadow_bias = 0.003 }

[light_sets]
sun = ["sun", "sky"]
sky = ["sky"]""").replace('name = "ball"\nmaterial = "grey"\nlights = "sun"', 'name = "ball"\nmaterial = "grey"\nlights = "sky"')
    (tmp_path / "shadow.toml").write_text(text)
    shutil.copy(SCENE.with_name("shadow.placement.toml"), tmp_path / "shadow.placement.toml")
    scene = load_scene(tmp_path / "shadow.toml", lib)
    assert {o["light_set"] for o in scene.objects} == {"sun", "sky"}
    spec, _ = _render(scene, lib, device, tmp_path / "s", "specialized")
    uber, rep = _render(scene, lib, device, tmp_path / "u", "ubershader")
    assert sorted(rep.shadow_maps) == ["sky", "sun"]
    assert np.array_equal(spec, uber)


def test_an_eval_kernel_refuses_a_brdf_that_reads_a_texture2d_shadow(tmp_path):
    """Eval kernels bind every BRDF texture with the bilinear colour sampler: a depth texture there is an error
    naming it, not an invalid descriptor on the GPU."""
    from generator.lang import SourceError
    from generator.library.bricks import load_library
    from generator.link import eval_program

    (tmp_path / "shadowed_lambert.py").write_text(
        '"""Lambert darkened by a depth compare (a test brick)."""\n'
        'BRICK = {"kind": "diffuse", "cite": "a test", "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], '
        '"default": [0.5, 0.5, 0.5]}}, "textures": {"occluder": {"srgb": False}}}\n\n\n'
        'def diffuse(rho_d: vec3, occluder: texture2d_shadow) -> vec3:\n'
        '    return rho_d * INV_PI * sample_compare(occluder, vec2(0.5), 0.5)\n')
    lib = load_library([tmp_path])
    with pytest.raises(SourceError, match="reads 'occluder' as a texture2d_shadow"):
        eval_program("shadowed_lambert", lib)
