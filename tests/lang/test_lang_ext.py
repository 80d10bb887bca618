"""Switches, runtime loops, arrays, read-only buffers and cube textures in GLSL, HLSL and WGSL.

tests/bricks/lang/ext_constructs.py holds the constructs as brick text; tests/ext_harness.py wraps
them (plus a Switch and a For built directly as IR) in compute and fragment shaders, which
go through the project toolchain: glslc / naga, spirv-val, spirv-opt -O, spirv-val.
"""
from __future__ import annotations

import pytest

from generator.lang import ir, parse_module
from generator.lang.types import (FLOAT, INT, TEXTURECUBE, UINT, VEC4, array, buffer_layout_error, storage_buffer,
                                  struct, uniform_buffer)
from generator.backends import TARGETS, get_target
from tests.conftest import require_tool
from tests.ext_harness import globals_for, module, shader

LANGS = ("glsl", "hlsl", "wgsl")


@pytest.fixture(scope="module")
def mod() -> ir.Module:
    return module()


def texts(mod) -> dict[str, str]:
    return {lang: get_target(lang).emit(list(mod.structs.values()), list(mod.functions.values()),
                                        globals_for(mod)).text for lang in LANGS}


# ---------------------------------------------------------------- the real tools

@pytest.mark.toolchain
def test_every_new_construct_compiles_validates_and_optimizes(mod):
    from generator.toolchain import CompileJob, compile_many

    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    jobs = []
    for lang in LANGS:
        for stage in ("comp", "frag"):
            text, emitted = shader(mod, lang, stage)
            jobs.append(CompileJob(f"ext.{stage}.{lang}", lang, stage, text))
    results = compile_many(jobs)
    for job in jobs:
        r = results[job.key]
        numbered = "\n".join(f"{i:4} {line}" for i, line in enumerate(job.source.splitlines(), 1))
        assert r.ok, "\n".join(r.errors()) + f"\n--- {job.key}:\n{numbered}"


@pytest.mark.toolchain
def test_buffer_and_texture_bindings_reach_the_spirv(mod):
    """Every language puts lights at (0, 1), table at (0, 2), env at (1, 0) and its sampler at (1, 1)."""
    from generator.toolchain import CompileJob, compile_many

    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    jobs = [CompileJob(f"b.{lang}", lang, "comp", shader(mod, lang, "comp")[0]) for lang in LANGS]
    results = compile_many(jobs, optimize=False)
    for job in jobs:
        words = results[job.key].spirv
        assert words is not None, results[job.key].errors()
        bindings = _bindings(words)
        assert {(0, 0), (0, 1), (0, 2), (1, 0), (1, 1)} <= bindings, (job.language, bindings)


def _bindings(spirv: bytes) -> set[tuple[int, int]]:
    """(set, binding) pairs decorated in a SPIR-V module."""
    import struct as st

    words = st.unpack(f"<{len(spirv) // 4}I", spirv)
    sets, binds = {}, {}
    i = 5
    while i < len(words):
        count, op = words[i] >> 16, words[i] & 0xFFFF
        if op == 71 and count >= 4:  # OpDecorate target decoration literal
            target, deco, lit = words[i + 1], words[i + 2], words[i + 3]
            if deco == 34:
                sets[target] = lit
            elif deco == 33:
                binds[target] = lit
        i += max(count, 1)
    return {(sets[t], binds[t]) for t in binds if t in sets}


# ---------------------------------------------------------------- emitted text

def test_switch_spellings(mod):
    t = texts(mod)
    assert "    switch (k) {\n        case 0: {\n" in t["glsl"]
    assert "        case 1:\n        case 2: {\n" in t["glsl"] and "case 1:\n        case 2: {\n" in t["hlsl"]
    assert "        case -3: {\n" in t["glsl"] and "        case -3i: {\n" in t["wgsl"]
    assert "        case 7u:\n        case 9u: {\n" in t["glsl"] and "        case 7u, 9u: {\n" in t["wgsl"]
    assert "    switch k {\n        case 0i: {\n" in t["wgsl"] and "        case 1i, 2i: {\n" in t["wgsl"]
    for lang in ("glsl", "hlsl"):  # break unless the case returns
        assert "            return (x + 10.0);\n        }\n" in t[lang]
        assert "            y = (x * 2.0);\n            break;\n        }\n" in t[lang]
    assert "break;" not in t["wgsl"]
    # WGSL always has a default clause; GLSL/HLSL only when the brick has one
    body = t["wgsl"][t["wgsl"].index("fn no_default"):]
    assert "        default: {\n        }\n" in body[:body.index("\n}\n")]
    body = t["glsl"][t["glsl"].index("float no_default"):]
    assert "default:" not in body[:body.index("\n}\n")]


def test_loop_and_array_spellings(mod):
    t = texts(mod)
    assert "for (int i = 0; i < n; i++) {" in t["glsl"] and "for (int i = 0; i < n; i++) {" in t["hlsl"]
    assert "for (uint i = 0u; i < m; i++) {" in t["glsl"]
    assert "for (var i: i32 = 0i; i < n; i++) {" in t["wgsl"] and "for (var i: u32 = 0u; i < m; i++) {" in t["wgsl"]
    assert "vec3 sum_lobes(Lobe lobes[4], int n, float cos_t)" in t["glsl"]
    assert "float3 sum_lobes(Lobe lobes[4], int n, float cos_t)" in t["hlsl"]
    assert "fn sum_lobes(lobes: array<Lobe, 4>, n: i32, cos_t: f32) -> vec3<f32>" in t["wgsl"]
    assert "float w[3] = float[3](x, (2.0 * x), 0.5);" in t["glsl"]
    assert "float w[3] = {x, (2.0 * x), 0.5};" in t["hlsl"]
    assert "var w: array<f32, 3> = array<f32, 3>(x, (2.0f * x), 0.5f);" in t["wgsl"]
    assert "    vec4 taps[2];\n" in t["glsl"] and "    taps: array<vec4<f32>, 2>,\n" in t["wgsl"]
    assert "Table _make_Table(Lobe lobe, float4 taps[2])" in t["hlsl"]


def test_buffer_spellings(mod):
    t = texts(mod)
    assert ("layout(set = 0, binding = 1, std430) readonly buffer _blk_lights { Light data[]; } lights;"
            in t["glsl"])
    assert "layout(set = 0, binding = 2, std140) uniform _blk_table { Table data[8]; } table;" in t["glsl"]
    assert "Light light = lights.data[i];" in t["glsl"] and "i < uint(lights.data.length())" in t["glsl"]
    assert "[[vk::binding(1, 0)]] StructuredBuffer<Light> lights : register(t1, space0);" in t["hlsl"]
    assert "uint _len_lights() { uint n, stride; lights.GetDimensions(n, stride); return n; }" in t["hlsl"]
    assert "[[vk::binding(2, 0)]] cbuffer _blk_table : register(b2, space0) { Table table[8]; };" in t["hlsl"]
    assert "Light light = lights[i];" in t["hlsl"] and "i < _len_lights()" in t["hlsl"]
    assert "@group(0) @binding(1) var<storage, read> lights: array<Light>;" in t["wgsl"]
    assert "@group(0) @binding(2) var<uniform> table: array<Table, 8>;" in t["wgsl"]
    assert "i < arrayLength(&lights)" in t["wgsl"]
    # a uniform buffer's length is its capacity, a constant
    assert "float(8u)" in t["glsl"] and "f32(8u)" in t["wgsl"]


def test_cube_texture_spellings(mod):
    t = texts(mod)
    assert "vec4 env_light(textureCube env, sampler _smp_env, vec3 dir, float lod)" in t["glsl"]
    assert "textureLod(samplerCube(env, _smp_env), dir, lod)" in t["glsl"]
    assert "texture(samplerCube(env, _smp_env), dir)" in t["glsl"]
    assert "float4 env_light(TextureCube env, SamplerState _smp_env, float3 dir, float lod)" in t["hlsl"]
    assert "env.SampleLevel(_smp_env, dir, lod)" in t["hlsl"] and "env.Sample(_smp_env, dir)" in t["hlsl"]
    assert "fn env_light(env: texture_cube<f32>, _smp_env: sampler, dir: vec3<f32>, lod: f32)" in t["wgsl"]
    assert TARGETS["glsl"].declare_texture("env", 1, 2, "cube").splitlines() == [
        "layout(set = 1, binding = 2) uniform textureCube env;",
        "layout(set = 1, binding = 3) uniform sampler _smp_env;"]
    assert TARGETS["hlsl"].declare_texture("env", 1, 2, dim="cube").splitlines() == [
        "[[vk::binding(2, 1)]] TextureCube env : register(t2, space1);",
        "[[vk::binding(3, 1)]] SamplerState _smp_env : register(s3, space1);"]
    assert TARGETS["wgsl"].declare_texture("env", 1, 2, "cube").splitlines() == [
        "@group(1) @binding(2) var env: texture_cube<f32>;", "@group(1) @binding(3) var _smp_env: sampler;"]
    # the 2d default is unchanged
    assert TARGETS["glsl"].declare_texture("t", 0, 0) == TARGETS["glsl"].declare_texture("t", 0, 0, "2d")


def test_declare_buffer_directly_and_its_checks():
    light = struct("Light", [("color", VEC4), ("dir", VEC4)])
    g = TARGETS["glsl"].declare_buffer("lights", light, 2, 5)
    assert g == "layout(set = 2, binding = 5, std430) readonly buffer _blk_lights { Light data[]; } lights;"
    assert TARGETS["wgsl"].declare_buffer("in", light, 0, 1, "uniform", 3) == \
        "@group(0) @binding(1) var<uniform> _r_in: array<Light, 3>;"  # names go through ident()
    bad = struct("Bad", [("color", VEC4), ("k", FLOAT)])
    assert "Bad.k is float" in buffer_layout_error(bad)
    for lang in LANGS:
        with pytest.raises(ValueError, match="Bad.k is float"):
            TARGETS[lang].declare_buffer("b", bad, 0, 0)
        with pytest.raises(ValueError, match="capacity"):
            TARGETS[lang].declare_buffer("b", light, 0, 0, "uniform", 0)
        with pytest.raises(ValueError, match="no set/binding"):
            TARGETS[lang].declare_global(ir.Global("b", storage_buffer(light)))
    with pytest.raises(ValueError):
        storage_buffer(bad)
    assert uniform_buffer(light, 4).components == 32 and storage_buffer(light).components == 0
    assert array(light, 3).components == 24 and str(array(light, 3)) == "array[Light, 3]"


def test_ir_nodes_are_walked_so_the_linker_can_rename_calls():
    loc = ir.Loc("glue", 1, 1)
    call = ir.Call(FLOAT, loc, "f", [])
    bound = ir.Call(INT, loc, "count", [])
    sw = ir.Switch(loc, ir.Var(INT, loc, "k", "param"), [((1, 2), [ir.Return(loc, call)])], [ir.Return(loc, call)])
    loop = ir.For(loc, "i", 0, [sw], bound=bound)
    calls = [n.func for n in ir.walk(loop) if isinstance(n, ir.Call)]
    assert calls == ["count", "f", "f"]
    assert loop.var_type == INT and ir.For(loc, "i", 0, [], ir.Var(UINT, loc, "n", "param")).var_type == UINT
    assert ir.For(loc, "i", 4, []).bound is None  # constant loops as before


def test_parsed_module_records_buffers_and_types(mod):
    assert {n: str(g.ty) for n, g in mod.globals.items()} == {
        "lights": "storage_buffer[Light]", "table": "uniform_buffer[Table, 8]"}
    assert mod.globals["lights"].set == -1  # the link stage assigns set and binding
    f = mod.functions["sum_lobes"]
    assert str(f.params[0].ty) == "array[Lobe, 4]" and f.params[0].ty.elem is mod.structs["Lobe"]
    assert mod.functions["env_light"].params[0].ty == TEXTURECUBE
    loops = [s for s in ir.walk_body(mod.functions["weights"].body) if isinstance(s, ir.For)]
    assert loops[0].var_type == UINT and loops[0].bound is not None
    sw = next(s for s in ir.walk_body(mod.functions["classify"].body) if isinstance(s, ir.Switch))
    assert [v for v, _ in sw.cases] == [(0,), (1, 2), (-3,)] and sw.default


def test_a_switch_whose_every_arm_returns_ends_a_function():
    """`pick` in the brick ends with such a switch (compiled above in every language); here the checker."""
    src = ('"""t"""\nBRICK = {"kind": "test"}\n\ndef f(k: int) -> float:\n    match k:\n        case 1:\n'
           '            return 1.0\n        case _:\n            return 2.0\n')
    f = parse_module(src, "t.py").functions["f"]
    assert isinstance(f.body[-1], ir.Switch)
    for lang in LANGS:  # nothing is appended after the switch
        text = get_target(lang).emit([], [f]).text
        assert text.count("return") == 2, text


def test_hlsl_builds_arrays_only_in_declarations():
    loc = ir.Loc("glue", 1, 1)
    arr = array(FLOAT, 2)
    x = ir.Var(FLOAT, loc, "x", "param")
    value = ir.Construct(arr, loc, [x, x])
    ok = ir.Function("f", [ir.Param("x", FLOAT, loc)], FLOAT,
                     [ir.Decl(loc, "a", arr, value), ir.Return(loc, ir.Index(FLOAT, loc, ir.Var(arr, loc, "a", "local"),
                                                                            ir.Const(INT, loc, 1)))], loc)
    assert "float a[2] = {x, x};" in get_target("hlsl").emit([], [ok]).text
    assert "float a[2] = float[2](x, x);" in get_target("glsl").emit([], [ok]).text
    g = ir.Function("g", [ir.Param("x", FLOAT, loc)], FLOAT,
                    [ir.Return(loc, ir.Index(FLOAT, loc, value, ir.Const(INT, loc, 0)))], loc)
    with pytest.raises(ValueError, match="HLSL has no array expression"):
        get_target("hlsl").emit([], [g])
    assert "return array<f32, 2>(x, x)[0i];" in get_target("wgsl").emit([], [g]).text
