"""Texture arrays: texture2d_array, texturecube_array and texture2d_array_shadow in every target.

tests/bricks/lang/ext_texture_arrays.py reads a layer of each in a compute kernel per language (GLSL
sampler2DArray / samplerCubeArray / sampler2DArrayShadow, HLSL Texture2DArray / TextureCubeArray with
SampleCmpLevelZero, WGSL texture_2d_array / texture_cube_array / texture_depth_2d_array); lavapipe's linear
clamp-to-edge samplers (the depth array's with compareOp LESS_OR_EQUAL) and the NumPy target read the same
texels, layers below 0 and past the last included: both clamp them to [0, L-1]. Each layer holds other
random texels, so a layer read wrongly (one off, not clamped, rounded another way) is off by ~0.5. The
implicit-LOD forms compile in a fragment shader; the GL 4.50 and ES 3.10 dialects validate with
glslangValidator, and ES 3.10, which has no samplerCubeArray, refuses a cube array at the brick's line.
"""
from __future__ import annotations

import numpy as np
import pytest

from generator.lang import SourceError, ir, parse_module
from generator.lang.sampling import sample_call, with_layer
from generator.lang.types import (FLOAT, INT, TEXTURE2D_ARRAY, TEXTURE2D_ARRAY_SHADOW, TEXTURE2D_SHADOW,
                                  TEXTURECUBE_ARRAY, VEC2, arrayed_texture, texture_type)
from generator.backends import get_target
from tests.lavapipe import device, no_validation_messages  # noqa: F401  (fixtures)
from tests.regen_goldens import REPO

BRICK = REPO / "tests" / "bricks" / "lang" / "ext_texture_arrays.py"
GLOBALS = [ir.Global("arr", TEXTURE2D_ARRAY, 0, 2), ir.Global("cube_maps", TEXTURECUBE_ARRAY, 0, 4),
           ir.Global("depth", TEXTURE2D_ARRAY_SHADOW, 0, 6)]
KERNEL = ["layered", "cubes", "shadowed"]
L = 3  # layers of each array

_BODY = {  # sample k: s[2k] = (uv, layer, ref), s[2k + 1] = (direction, cube layer); results r[3k .. 3k + 2]
    "glsl": "res.r[3u * i] = {layered}(arr, {s_arr}, smp.s[2u * i].xy, int(smp.s[2u * i].z));\n"
            "  res.r[3u * i + 1u] = {cubes}(cube_maps, {s_cube_maps}, smp.s[2u * i + 1u].xyz, uint(smp.s[2u * i + 1u].w));\n"
            "  res.r[3u * i + 2u] = vec4({shadowed}(depth, {s_depth}, smp.s[2u * i].xy, int(smp.s[2u * i].z), "
            "smp.s[2u * i].w));",
    "hlsl": "res[3u * i] = {layered}(arr, {s_arr}, smp[2u * i].xy, int(smp[2u * i].z));\n"
            "  res[3u * i + 1u] = {cubes}(cube_maps, {s_cube_maps}, smp[2u * i + 1u].xyz, uint(smp[2u * i + 1u].w));\n"
            "  res[3u * i + 2u] = {shadowed}(depth, {s_depth}, smp[2u * i].xy, int(smp[2u * i].z), "
            "smp[2u * i].w).xxxx;",
    "wgsl": "res[3u * i] = {layered}(arr, {s_arr}, smp[2u * i].xy, i32(smp[2u * i].z));\n"
            "  res[3u * i + 1u] = {cubes}(cube_maps, {s_cube_maps}, smp[2u * i + 1u].xyz, u32(smp[2u * i + 1u].w));\n"
            "  res[3u * i + 2u] = vec4<f32>({shadowed}(depth, {s_depth}, smp[2u * i].xy, i32(smp[2u * i].z), "
            "smp[2u * i].w));",
}
SHELL = {
    "glsl": "#version 450\n{header}\nlayout(local_size_x = 1) in;\n"
            "layout(std430, set = 0, binding = 0) readonly buffer S {{ vec4 s[]; }} smp;\n"
            "layout(std430, set = 0, binding = 1) buffer R {{ vec4 r[]; }} res;\n{functions}\n"
            "void main() {{ uint i = gl_GlobalInvocationID.x;\n  {body} }}\n",
    "hlsl": "[[vk::binding(0, 0)]] StructuredBuffer<float4> smp : register(t0, space0);\n"
            "[[vk::binding(1, 0)]] RWStructuredBuffer<float4> res : register(u1, space0);\n{functions}\n"
            "[numthreads(1, 1, 1)] void main(uint3 id : SV_DispatchThreadID) {{ uint i = id.x;\n  {body} }}\n",
    "wgsl": "@group(0) @binding(0) var<storage, read> smp: array<vec4<f32>>;\n"
            "@group(0) @binding(1) var<storage, read_write> res: array<vec4<f32>>;\n{functions}\n"
            "@compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{ let i = id.x;\n"
            "  {body} }}\n",
}


def _module():
    return parse_module(BRICK.read_text(), str(BRICK.relative_to(REPO)))


def _fns(m, names):
    return [m.functions[n] for n in names]


def inputs(rng, n=300, h=5, w=7, c=6):
    """Layers of random texels; samples over the map and past its borders, layers -2 .. L + 1 (clamped), depth
    references on both sides of each layer's depths; cube directions a texel away from every face edge (where
    Vulkan filters across faces and NumPy clamps)."""
    arr = rng.uniform(-1, 1, (L, h, w, 4)).astype(np.float32)
    cubes = rng.uniform(-1, 1, (L, 6, c, c, 4)).astype(np.float32)
    depth = rng.uniform(0.2, 0.8, (L, h, w)).astype(np.float32)
    uv = rng.uniform(-0.2, 1.2, (n, 2))
    d = rng.normal(size=(n * 4, 3))
    a = np.abs(d)
    ma, mid = a.max(1), np.sort(a, 1)[:, 1]
    d = d[(mid / ma < 1 - 2.0 / c) & (ma - mid > 1e-3)][:n]
    samples = np.zeros((n, 2, 4), np.float32)
    samples[:, 0, :2], samples[:, 0, 2] = uv, rng.integers(-2, L + 2, n)
    samples[:, 0, 3] = rng.uniform(0.1, 0.9, n)
    samples[:, 1, :3], samples[:, 1, 3] = d, rng.integers(0, L + 3, n)
    return arr, cubes, depth, samples


def _kernels(m):
    from generator.toolchain import CompileJob

    jobs = {}
    for lang, shell in SHELL.items():
        t = get_target(lang)
        names = {k: t.ident(k) for k in KERNEL} | {f"s_{g.name}": t.sampler_name(g.name) for g in GLOBALS}
        text = t.emit([], _fns(m, KERNEL), GLOBALS).text
        jobs[lang] = CompileJob(f"arrays.{lang}", lang, "comp", shell.format(
            header=t.header(), functions=text, body=_BODY[lang].format(**names)))
    return jobs


def _compile(jobs):
    from generator.toolchain import compile_many

    compiled = compile_many(list(jobs.values()))
    for job in jobs.values():
        assert compiled[job.key].ok, "\n".join(compiled[job.key].errors())
    return {lang: compiled[job.key].spirv for lang, job in jobs.items()}


# ------------------------------------------------------------------ typing


@pytest.mark.parametrize("body, words", [
    ("def f(t: texture2d_array, uv: vec2) -> vec4:\n    return sample(t, uv, 1.0)\n",
     "the layer of a texture2d_array is an int or uint, not a float"),
    ("def f(t: texture2d_array, uv: vec2) -> vec4:\n    return sample(t, uv)\n",
     "sample(texture2d_array, vec2) is not defined"),
    ("def f(t: texturecube_array, uv: vec2) -> vec4:\n    return sample_level(t, uv, 0, 0.0)\n",
     "sample_level(texturecube_array, vec2, int, float) is not defined"),
    ("def f(t: texture2d_array_shadow, uv: vec2) -> vec4:\n    return sample(t, uv, 0)\n",
     "sample() cannot read a texture2d_array_shadow"),
    ("def f(t: texture2d_array_shadow, uv: vec2) -> float:\n    return sample_compare(t, uv, 0.5)\n",
     "sample_compare(texture2d_array_shadow, vec2, float) is not defined"),
    ("def f(t: texture2d_array, uv: vec2) -> float:\n    return sample_compare(t, uv, 0, 0.5)\n",
     "sample_compare(texture2d_array, vec2, int, float) is not defined"),
])
def test_a_texture_array_takes_an_integer_layer_after_its_coordinate(body, words):
    with pytest.raises(SourceError) as e:
        parse_module('"""A test brick."""\nBRICK = {"kind": "shadow"}\n\n' + body, "b.py")
    assert words in str(e.value) and "b.py:5:12" in str(e.value), str(e.value)


def test_the_link_stage_builds_an_arrayed_sample_as_the_checker_types_it():
    loc = ir.Loc("b.py", 1, 1)
    single = ir.Var(TEXTURE2D_SHADOW, loc, "shadow_depth", "param")
    uv, ref, layer = ir.Var(VEC2, loc, "uv", "param"), ir.Const(FLOAT, loc, 0.5), ir.Const(INT, loc, 2)
    call = sample_call("sample_compare", loc, single, uv, ref)
    arrayed = ir.Var(arrayed_texture(single.ty), loc, "shadow_depth", "param")
    got = with_layer(call, arrayed, layer)
    assert arrayed.ty == TEXTURE2D_ARRAY_SHADOW == texture_type("2d_array", compare=True)
    assert got.ty == FLOAT and [a for a in got.args] == [arrayed, uv, layer, ref]
    glsl = get_target("glsl").expr(got)
    assert glsl == ("textureGrad(sampler2DArrayShadow(shadow_depth, _smp_shadow_depth), vec4(uv, float(2), 0.5), "
                    "vec2(0.0), vec2(0.0))"), glsl
    with pytest.raises(ValueError, match="is not defined"):
        sample_call("sample_compare", loc, single, uv, ref, layer=layer)  # a single texture has no layer
    assert arrayed_texture(TEXTURECUBE_ARRAY) == TEXTURECUBE_ARRAY


# ------------------------------------------------------------------ every target


@pytest.mark.toolchain
def test_the_three_languages_declare_and_sample_each_array():
    m = _module()
    jobs = _kernels(m)
    want = {"glsl": ("uniform texture2DArray arr;", "uniform textureCubeArray cube_maps;", "uniform samplerShadow _smp_depth",
                     "sampler2DArray(", "samplerCubeArray(", "sampler2DArrayShadow("),
            "hlsl": ("Texture2DArray arr", "TextureCubeArray cube_maps", "SamplerComparisonState _smp_depth",
                     ".SampleCmpLevelZero(_smp_t, float3(uv, float(layer)), _r_ref)"),
            "wgsl": ("var arr: texture_2d_array<f32>;", "var cube_maps: texture_cube_array<f32>;",
                     "var depth: texture_depth_2d_array;", "textureSampleCompareLevel(t, _smp_t, uv, layer, _r_ref)")}
    for lang, job in jobs.items():
        for piece in want[lang]:
            assert piece in job.source, (lang, piece)
    # the implicit-LOD forms, in a fragment shader (derivatives)
    for lang in SHELL:
        t = get_target(lang)
        text = t.emit([], _fns(m, ["implicit", "implicit_cubes"]), GLOBALS[:2]).text
        jobs[f"{lang}.frag"] = _fragment_job(lang, t, text)
    _compile(jobs)  # glslc / naga, spirv-opt and spirv-val on each


def _fragment_job(lang, t, functions):
    from generator.toolchain import CompileJob

    a, c, sa, sc = t.ident("implicit"), t.ident("implicit_cubes"), t.sampler_name("arr"), t.sampler_name("cube_maps")
    src = {
        "glsl": f"#version 450\n{t.header()}\nlayout(location = 0) in vec3 d;\nlayout(location = 0) out vec4 o;\n"
                f"{functions}\nvoid main() {{ o = {a}(arr, {sa}, d.xy, 1) + {c}(cube_maps, {sc}, d, 2); }}\n",
        "hlsl": f"{functions}\nfloat4 main(float3 d : TEXCOORD0) : SV_Target {{ return {a}(arr, {sa}, d.xy, 1) + "
                f"{c}(cube_maps, {sc}, d, 2); }}\n",
        "wgsl": f"{functions}\n@fragment fn main(@location(0) d: vec3<f32>) -> @location(0) vec4<f32> {{ return "
                f"{a}(arr, {sa}, d.xy, 1i) + {c}(cube_maps, {sc}, d, 2i); }}\n",
    }[lang]
    return CompileJob(f"arrays.frag.{lang}", lang, "frag", src)


def _dialect_job(dialect, names, globals_):
    from generator.backends.gl.emit import DIALECTS, gl_bindings
    from generator.toolchain import CompileJob

    t = DIALECTS[dialect](gl_bindings([], globals_))
    m = _module()
    text = t.emit([], _fns(m, names), globals_).text
    calls = {"layered": "layered(arr, d.xy, 1)", "implicit": "implicit(arr, d.xy, -1)",
             "shadowed": "vec4(shadowed(depth, d.xy, 4, d.z))", "cubes": "cubes(cube_maps, d, 1u)",
             "implicit_cubes": "implicit_cubes(cube_maps, d, 0)"}
    head = "\n".join([t.version_line(), *t.precision_lines("frag")])
    body = " + ".join(calls[n] for n in names)
    src = (f"{head}\nlayout(location = 0) in vec3 d;\nlayout(location = 0) out vec4 o;\n{text}\n"
           f"void main() {{ o = {body}; }}\n")
    return CompileJob(f"arrays.{dialect}", dialect, "frag", src), text


@pytest.mark.toolchain
def test_the_gl_dialects_validate_their_array_samplers():
    from generator.toolchain.platforms import validate_dialects

    all_names = ["layered", "shadowed", "implicit", "cubes", "implicit_cubes"]
    gl, gl_text = _dialect_job("gl", all_names, GLOBALS)
    es, es_text = _dialect_job("essl", ["layered", "shadowed", "implicit"], [GLOBALS[0], GLOBALS[2]])
    assert "uniform sampler2DArray arr;" in gl_text and "uniform samplerCubeArray cube_maps;" in gl_text
    assert "uniform highp sampler2DArrayShadow depth;" in es_text and "highp sampler2DArray t" in es_text
    errors = validate_dialects([gl, es])
    assert errors == {gl.key: [], es.key: []}, errors


def test_gl_es_refuses_a_cube_array_at_the_brick_line():
    from generator.backends.gl.emit import DIALECTS, gl_bindings

    m = _module()
    with pytest.raises(SourceError) as e:
        DIALECTS["essl"](gl_bindings([], [])).emit([], _fns(m, ["layered", "cubes"]))
    text = str(e.value)
    assert text.startswith("tests/bricks/lang/ext_texture_arrays.py:13:"), text
    assert "parameter 't' of 'cubes' is a texturecube_array, which GLSL ES 3.10 does not have" in text
    assert "take a texturecube per layer" in text
    DIALECTS["gl"](gl_bindings([], [])).emit([], _fns(m, ["cubes"]))  # desktop GL 4.50 has samplerCubeArray


# ------------------------------------------------------------------ lavapipe and NumPy


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_lavapipe_and_numpy_read_the_same_layers(device):
    from tests.ext_vulkan_images import Image, run_sampling_kernel

    m = _module()
    spirv = _compile(_kernels(m))
    arr, cubes, depth, samples = inputs(np.random.default_rng(29))
    nt = get_target("numpy")
    fns = nt.load(nt.emit([], _fns(m, KERNEL)), np.float32)
    s0, s1 = samples[:, 0], samples[:, 1]
    layer, cube_layer = s0[:, 2].astype(np.int32), s1[:, 3].astype(np.uint32)
    compares = fns["shadowed"](depth, s0[:, :2], layer, s0[:, 3])
    want = np.stack([fns["layered"](arr, s0[:, :2], layer), fns["cubes"](cubes, s1[:, :3], cube_layer),
                     np.repeat(compares[:, None], 4, 1)], 1).astype(np.float64)
    assert (layer < 0).sum() > 20 and (layer >= L).sum() > 20 and (cube_layer >= L).sum() > 20, "clamped layers"
    assert 0.2 < (compares == 1.0).mean() < 0.8 and ((compares > 0) & (compares < 1)).sum() > 50
    images = [Image(device, arr, view="2d_array"), Image(device, cubes, view="cube_array"),
              Image(device, depth, view="2d_array", depth=True)]
    try:
        for lang, code in spirv.items():
            got = run_sampling_kernel(device, code, samples, 3, images).astype(np.float64)
            # float32 filtering on lavapipe (measured ~1e-6); a wrong layer is off by ~0.5, a wrong compare by ≥ 1/35
            np.testing.assert_allclose(got, want, rtol=0, atol=4e-6,
                                       err_msg=f"{lang}: lavapipe and NumPy read different layers")
    finally:
        for i in images:
            i.destroy()
