"""The GLSL, HLSL and WGSL emitters: every construct compiles and validates with the real tools.

tests/bricks/lang/constructs.py holds one function per group of constructs. Each
target's output is wrapped in a tiny compute shader that calls every function
(and a fragment shader for the one that uses implicit-derivative sample()),
compiled with glslc (GLSL, HLSL) or naga (WGSL) and checked with spirv-val.
The toolchain module is deliberately not used: these tests pin the emitters
against the tools themselves.
"""
from __future__ import annotations

import dataclasses
import re
import subprocess
from pathlib import Path

import pytest

from generator.lang import ir, parse_module
from generator.lang.types import BOOL, FLOAT, INT, TEXTURE2D, VEC2, VEC3, Type, scalar
from generator.backends import TARGETS, get_target
from generator.backends.clike.walk import float_literal
from generator.backends.glsl.keywords import WORDS as GLSL_WORDS
from generator.backends.hlsl.keywords import WORDS as HLSL_WORDS
from generator.backends.wgsl.keywords import WORDS as WGSL_WORDS

ROOT = Path(__file__).resolve().parents[2]
BRICK = "tests/bricks/lang/constructs.py"
HARNESS = ir.Loc("tests/harness", 1, 1)
LANGS = ("glsl", "hlsl", "wgsl")


@pytest.fixture(scope="module")
def module() -> ir.Module:
    return parse_module((ROOT / BRICK).read_text(), BRICK)


def brick_line(text: str) -> int:
    """1-based line of the first brick line containing `text`."""
    for i, line in enumerate((ROOT / BRICK).read_text().splitlines(), 1):
        if text in line:
            return i
    raise AssertionError(f"{text!r} not in {BRICK}")


def emit(module: ir.Module, lang: str, extra: list[ir.Function] = ()):
    return get_target(lang).emit(list(module.structs.values()), list(module.functions.values()) + list(extra))


def mapped(line_map, line: int) -> tuple[str, int]:
    """The brick location of generated `line`: the closest entry at or above it."""
    best = None
    for gen, path, src in line_map:
        if gen <= line:
            best = (path, src)
    assert best is not None, f"line {line} has no mapping"
    return best


# ---------------------------------------------------------------- harness in IR

def _value(t: Type, x: ir.Expr) -> ir.Expr:
    """Some value of type t computed from the float x (so nothing folds away)."""
    if t == FLOAT:
        return x
    if t.kind == "scalar":
        if t == BOOL:
            return ir.Binary(BOOL, HARNESS, ">", x, ir.Const(FLOAT, HARNESS, 0.0))
        return ir.Construct(t, HARNESS, [x])
    if t.kind == "vector":
        return ir.Construct(t, HARNESS, [_value(scalar(t.scalar), x)])
    if t.kind == "matrix":
        col = _value(Type("vector", "float", t.size, f"vec{t.size}"), x)
        return ir.Construct(t, HARNESS, [col] * t.size)
    if t.kind == "struct":
        return ir.Construct(t, HARNESS, [_value(ft, x) for _, ft in t.fields])
    if t.kind == "texture":
        return ir.Var(TEXTURE2D, HARNESS, "tex", "global")
    raise AssertionError(t)


def _digest(e: ir.Expr) -> ir.Expr:
    """A float that depends on the value e."""
    t = e.ty
    if t == FLOAT:
        return e
    if t == BOOL:
        return ir.Select(FLOAT, HARNESS, e, ir.Const(FLOAT, HARNESS, 1.0), ir.Const(FLOAT, HARNESS, 0.0))
    if t.kind == "scalar":
        return ir.Construct(FLOAT, HARNESS, [e])
    if t.kind == "vector":
        return _digest(ir.Swizzle(scalar(t.scalar), HARNESS, e, "x"))
    if t.kind == "matrix":
        col = Type("vector", "float", t.size, f"vec{t.size}")
        return _digest(ir.Index(col, HARNESS, e, ir.Const(INT, HARNESS, 0)))
    if t.kind == "struct":
        name, ft = t.fields[0]
        return _digest(ir.Member(ft, HARNESS, e, name))
    raise AssertionError(t)


def _samples(module: ir.Module, name: str) -> bool:
    """Does `name` (or anything it calls) use implicit-derivative sample()?"""
    f = module.functions[name]
    return any(isinstance(n, ir.Intrinsic) and n.name == "sample" for n in ir.walk_body(f.body)) or any(
        _samples(module, c) for c in f.calls if c in module.functions)


def harness(module: ir.Module) -> list[ir.Function]:
    """`harness(x) -> float` calling every compute-safe function; `harness_frag(uv) -> vec4` sampling."""
    x = ir.Var(FLOAT, HARNESS, "x", "param")
    acc = ir.Var(FLOAT, HARNESS, "acc", "local")
    body: list[ir.Stmt] = [ir.Decl(HARNESS, "acc", FLOAT, ir.Const(FLOAT, HARNESS, 0.0))]
    for f in module.functions.values():
        if not _samples(module, f.name):
            call = ir.Call(f.ret, HARNESS, f.name, [_value(p.ty, x) for p in f.params])
            body.append(ir.Assign(HARNESS, acc, "+", _digest(call)))
    body.append(ir.Return(HARNESS, acc))
    comp = ir.Function("harness", [ir.Param("x", FLOAT, HARNESS)], FLOAT, body, HARNESS)
    uv = ir.Var(VEC2, HARNESS, "uv", "param")
    sampled = [f for f in module.functions.values() if _samples(module, f.name)]
    assert [f.name for f in sampled] == ["sample_albedo"]
    call = ir.Call(sampled[0].ret, HARNESS, "sample_albedo", [ir.Var(TEXTURE2D, HARNESS, "tex", "global"), uv])
    frag = ir.Function("harness_frag", [ir.Param("uv", VEC2, HARNESS)], sampled[0].ret,
                       [ir.Return(HARNESS, call)], HARNESS)
    return [comp, frag]


SHELLS = {
    ("glsl", "comp"): """#version 450
{header}
layout(local_size_x = 1) in;
{texture}
layout(std430, set = 0, binding = 2) buffer Data {{ float data[]; }} buf;
{functions}
{reset}
void main() {{ buf.data[0] = harness(buf.data[0]); }}
""",
    ("glsl", "frag"): """#version 450
{header}
{texture}
layout(location = 0) in vec2 v_uv;
layout(location = 0) out vec4 o_color;
{functions}
{reset}
void main() {{ o_color = harness_frag(v_uv); }}
""",
    ("hlsl", "comp"): """{header}
{texture}
[[vk::binding(2, 0)]] RWStructuredBuffer<float> buf : register(u2, space0);
{functions}
{reset}
[numthreads(1, 1, 1)] void main() {{ buf[0] = harness(buf[0]); }}
""",
    ("hlsl", "frag"): """{header}
{texture}
{functions}
{reset}
float4 main(float2 uv : TEXCOORD0) : SV_Target {{ return harness_frag(uv); }}
""",
    ("wgsl", "comp"): """{header}
{texture}
struct Data {{ data: array<f32> }}
@group(0) @binding(2) var<storage, read_write> buf: Data;
{functions}
{reset}
@compute @workgroup_size(1) fn main() {{ buf.data[0] = harness(buf.data[0]); }}
""",
    ("wgsl", "frag"): """{header}
{texture}
{functions}
{reset}
@fragment fn main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {{ return harness_frag(uv); }}
""",
}


def shader(module: ir.Module, lang: str, stage: str) -> tuple[str, object]:
    """A complete shader around the emitted brick functions, and the Emitted it holds."""
    target = get_target(lang)
    emitted = emit(module, lang, harness(module))
    head, tail = SHELLS[lang, stage].split("{functions}")
    head = head.format(header=target.header(), texture=target.declare_texture("tex", 0, 0))
    lines = (head + emitted.text + tail.format(reset="{reset}")).split("\n")
    i = lines.index("{reset}")
    lines[i] = target.line_reset(i + 2, f"shell.{stage}.{lang}")  # the next line is line i + 2
    text = "\n".join(lines)
    return text, emitted


def compile_spirv(require_tool, lang: str, stage: str, text: str, tmp_path: Path) -> subprocess.CompletedProcess:
    """Front end (glslc or naga) then spirv-val; the first failing step's result."""
    src = tmp_path / f"shader.{stage}.{lang}"
    spv = tmp_path / f"shader.{stage}.spv"
    src.write_text(text)
    if lang == "wgsl":
        cmd = [require_tool("naga"), str(src), str(spv)]
    else:
        cmd = [require_tool("glslc"), "--target-env=vulkan1.1", f"-fshader-stage={stage}"]
        if lang == "hlsl":
            cmd += ["-x", "hlsl", "-fentry-point=main"]
        cmd += [str(src), "-o", str(spv)]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    if r.returncode != 0:
        return r
    return subprocess.run([require_tool("spirv-val"), "--target-env", "vulkan1.1", str(spv)],
                          capture_output=True, text=True)


# ---------------------------------------------------------------- toolchain tests

@pytest.mark.toolchain
@pytest.mark.parametrize("stage", ["comp", "frag"])
@pytest.mark.parametrize("lang", LANGS)
def test_every_construct_compiles_and_validates(module, lang, stage, tmp_path, require_tool):
    text, _ = shader(module, lang, stage)
    r = compile_spirv(require_tool, lang, stage, text, tmp_path)
    numbered = "\n".join(f"{i:4} {line}" for i, line in enumerate(text.splitlines(), 1))
    assert r.returncode == 0, f"{r.stdout}{r.stderr}\n--- {lang} {stage} source:\n{numbered}"


@pytest.mark.toolchain
@pytest.mark.parametrize("lang", ["glsl", "hlsl"])
def test_compiler_errors_point_at_the_brick_line(module, lang, tmp_path, require_tool):
    # A line in the middle of a straight run of statements: reached by counting from a
    # previous #line, not by its own directive, so the counting is checked too.
    want = brick_line("on = (flag and")
    text, emitted = shader(module, lang, "comp")
    lines = text.splitlines()
    offset = text[:text.index(emitted.text)].count("\n")
    hits = [gen for gen, _, src in emitted.line_map if src == want]
    assert len(hits) == 1
    i = offset + hits[0] - 1
    assert "on" in lines[i] and not lines[i - 1].startswith("#line")
    lines[i] = "    bool on = undefined_name_here;"
    r = compile_spirv(require_tool, lang, "comp", "\n".join(lines) + "\n", tmp_path)
    assert r.returncode != 0
    assert f"{BRICK}:{want}: error" in r.stderr, r.stderr


@pytest.mark.toolchain
def test_wgsl_line_map_maps_naga_errors_back_to_the_brick(module, tmp_path, require_tool):
    want = brick_line("on = (flag and")
    text, emitted = shader(module, "wgsl", "comp")
    offset = text[:text.index(emitted.text)].count("\n")
    lines = text.splitlines()
    i = next(n for n, line in enumerate(lines) if "var on: bool" in line)
    lines[i] = "    var on: bool = undefined_name_here;"
    r = compile_spirv(require_tool, "wgsl", "comp", "\n".join(lines) + "\n", tmp_path)
    assert r.returncode != 0
    m = re.search(r"shader\.comp\.wgsl:(\d+):\d+", r.stdout + r.stderr)
    assert m, r.stdout + r.stderr
    assert mapped(emitted.line_map, int(m.group(1)) - offset) == (BRICK, want)


# ---------------------------------------------------------------- emitter unit tests

def test_wgsl_line_map_covers_functions_and_statements(module):
    emitted = emit(module, "wgsl")
    lines = emitted.text.splitlines()
    for f in module.functions.values():
        n = next(i for i, line in enumerate(lines, 1) if line.startswith(f"fn {f.name}("))
        assert mapped(emitted.line_map, n) == (BRICK, f.loc.line)
    for needle, brick_text in [("var k: i32", "k = i * 2"), ("acc /= 2.0f", "acc /= 2.0"),
                               ("} else if (x < 2.0f)", "elif x < 2.0"), ("m3[i].y", "e = m3[1][2]")]:
        n = next(i for i, line in enumerate(lines, 1) if needle in line)
        assert mapped(emitted.line_map, n) == (BRICK, brick_line(brick_text)), needle
    assert [gen for gen, _, _ in emitted.line_map] == sorted(gen for gen, _, _ in emitted.line_map)


def test_emitters_keep_their_records_of_functions_not_the_ir(module):
    """A C-like emitter replays a function it emitted before (linked functions are shared by every program of
    a library) from the records its caller holds: the IR functions hold only their fields, the replay is the
    same text, and an emitter given no records (or other records) replays nothing of them."""
    from generator.backends.clike.records import FunctionRecords
    functions = list(module.functions.values())
    structs = list(module.structs.values())
    records = FunctionRecords()
    for lang in LANGS:
        first = get_target(lang).emit(structs, functions, records=records)
        again = get_target(lang).emit(structs, functions, records=records)
        assert (again.text, again.line_map) == (first.text, first.line_map) == dataclasses.astuple(emit(module, lang))
    fields = {f.name for f in dataclasses.fields(ir.Function)}
    for f in functions:
        assert set(vars(f)) == fields, sorted(set(vars(f)) - fields)
    assert all(records.of(f) for f in functions)  # each function was recorded, in the caller's store
    assert not any(FunctionRecords().of(f) for f in functions)  # another store has seen none of them
    copy = ir.clone(functions[0])
    assert not records.of(copy)  # a copy is another function: it has no record of its own yet


def test_reserved_words_are_renamed_identically_in_every_target(module):
    words = ["sampler", "texture", "input", "output", "half", "line", "filter", "fn", "let", "main", "gl_x"]
    for w in words:
        assert {TARGETS[t].ident(w) for t in LANGS} == {"_r_" + w}
    for w in ["albedo", "NdotH", "rough", "acc"]:
        assert {TARGETS[t].ident(w) for t in LANGS} == {w}
    for w in GLSL_WORDS | HLSL_WORDS | WGSL_WORDS:
        assert TARGETS["glsl"].ident(w) == TARGETS["hlsl"].ident(w) == TARGETS["wgsl"].ident(w) == "_r_" + w
    declared = [s.name for s in ir.walk_body(module.functions["surface_term"].body) if isinstance(s, ir.Decl)]
    for lang in LANGS:
        text = emit(module, lang).text
        body = text[text.index("surface_term("):]
        body = "\n".join(ln for ln in body[:body.index("\n}\n")].splitlines() if not ln.startswith("#line"))
        for name in declared + ["input"]:
            spelled = TARGETS[lang].ident(name)
            assert re.search(rf"\b{spelled}\b", body), (lang, spelled)
            if spelled != name:
                assert not re.search(rf"\b{name}\b", body), (lang, name)


def test_float_literals():
    assert [float_literal(v) for v in (1.0, 0.04, 1e-07, -2.5, 3e20, 2)] == ["1.0", "0.04", "1e-07", "-2.5", "3e+20", "2.0"]
    for bad in (float("inf"), float("-inf"), float("nan")):
        with pytest.raises(AssertionError):
            float_literal(bad)


def _expr(lang: str, e: ir.Expr) -> str:
    return TARGETS[lang].expr(e)


def test_spellings_per_target():
    L = HARNESS
    x, y = ir.Var(FLOAT, L, "x", "param"), ir.Var(FLOAT, L, "y", "param")
    c = ir.Var(BOOL, L, "c", "param")
    v = ir.Var(VEC3, L, "v", "param")
    intr = lambda name, *args, ty=FLOAT: ir.Intrinsic(ty, L, name, list(args))  # noqa: E731
    cases = [
        (intr("rsqrt", x), ("inversesqrt(x)", "rsqrt(x)", "inverseSqrt(x)")),
        (intr("mix", x, y, x), ("mix(x, y, x)", "lerp(x, y, x)", "mix(x, y, x)")),
        (intr("fract", x), ("fract(x)", "frac(x)", "fract(x)")),
        (intr("saturate", v, ty=VEC3), ("clamp(v, 0.0, 1.0)", "saturate(v)", "saturate(v)")),
        (intr("atan2", y, x), ("atan(y, x)", "atan2(y, x)", "atan2(y, x)")),
        (intr("select", c, x, y), ("mix(y, x, c)", "(c ? x : y)", "select(y, x, c)")),
        (ir.Select(FLOAT, L, c, x, y), ("mix(y, x, c)", "(c ? x : y)", "select(y, x, c)")),
        (ir.Var(FLOAT, L, "PI", "const"), ("3.141592653589793",) * 2 + ("3.141592653589793f",)),
        (ir.Construct(VEC3, L, [x]), ("vec3(x)", "((float3)(x))", "vec3<f32>(x)")),
        (ir.Construct(FLOAT, L, [ir.Var(INT, L, "i", "local")]), ("float(i)", "float(i)", "f32(i)")),
        (ir.Const(INT, L, -3), ("(-3)", "(-3)", "(-3i)")),
        (ir.Unary(BOOL, L, "not", ir.Binary(BOOL, L, "and", c, c)), ("(!(c && c))",) * 3),
    ]
    for e, want in cases:
        assert tuple(_expr(lang, e) for lang in LANGS) == want


def test_texture_parameters_and_samples(module):
    f = module.functions["sample_albedo"]
    texts = {lang: emit(module, lang).text for lang in LANGS}
    assert "vec4 sample_albedo(texture2D albedo_map, sampler _smp_albedo_map, vec2 uv)" in texts["glsl"]
    assert "texture(sampler2D(albedo_map, _smp_albedo_map), uv)" in texts["glsl"]
    assert "textureLod(sampler2D(albedo_map, _smp_albedo_map), uv, lod)" in texts["glsl"]
    assert "float4 sample_albedo(Texture2D albedo_map, SamplerState _smp_albedo_map, float2 uv)" in texts["hlsl"]
    assert "albedo_map.Sample(_smp_albedo_map, uv)" in texts["hlsl"]
    assert "albedo_map.SampleLevel(_smp_albedo_map, uv, lod)" in texts["hlsl"]
    assert ("fn sample_albedo(albedo_map: texture_2d<f32>, _smp_albedo_map: sampler, uv: vec2<f32>) -> vec4<f32>"
            in texts["wgsl"])
    assert "textureSampleLevel(albedo_map, _smp_albedo_map, uv, lod)" in texts["wgsl"]
    assert "sample_lod(albedo_map, _smp_albedo_map, uv, 1.0f)" in texts["wgsl"]
    assert f.params[0].ty == TEXTURE2D
    assert TARGETS["glsl"].declare_texture("sampler", 1, 4).splitlines() == [
        "layout(set = 1, binding = 4) uniform texture2D _r_sampler;",
        "layout(set = 1, binding = 5) uniform sampler _smp_sampler;"]
    assert TARGETS["hlsl"].declare_texture("t", 1, 4).splitlines() == [
        "[[vk::binding(4, 1)]] Texture2D t : register(t4, space1);",
        "[[vk::binding(5, 1)]] SamplerState _smp_t : register(s5, space1);"]
    assert TARGETS["wgsl"].declare_texture("t", 1, 4).splitlines() == [
        "@group(1) @binding(4) var t: texture_2d<f32>;", "@group(1) @binding(5) var _smp_t: sampler;"]


def test_hlsl_matrices_keep_glsl_column_semantics(module):
    text = emit(module, "hlsl").text
    assert "float3 a = mul(m3, v);" in text and "float3 b = mul(v, m3);" in text
    assert "float3 col = transpose(m3)[i];" in text
    assert "float e = (m3[2][1] + m3[1][i]);" in text  # m3[1][2] is row 2 of column 1
    assert "w = mul(w, m4);" in text  # *= on matrices is a product, not component-wise
    assert "{ float4 _c = float4(col, e); w[0][3] = _c.x; w[1][3] = _c.y; w[2][3] = _c.z; w[3][3] = _c.w; }" in text
    assert "transpose(float4x4(float4(v, 1.0)," in text
    assert "_make_Surface(albedo, rough, 3, frame)" in text


def test_wgsl_assigned_parameters_are_copied(module):
    text = emit(module, "wgsl").text
    assert "fn shade(_in_x: f32, _in_v: vec3<f32>, uv: vec2<f32>," in text
    assert "    var x: f32 = _in_x;\n    var v: vec3<f32> = _in_v;\n" in text
    assert "fn surface_term(_in_sfc: Surface, _in_input: f32)" in text
    clash = parse_module('BRICK = {}\ndef f(a: float) -> float:\n    a_in = 1.0\n    a = a_in\n    return a\n', "t.py")
    out = get_target("wgsl").emit([], list(clash.functions.values())).text
    assert "fn f(_in_a: f32) -> f32 {\n    var a: f32 = _in_a;\n    var a_in: f32 = 1.0f;" in out


def test_header_and_line_reset():
    assert TARGETS["glsl"].header() == "#extension GL_GOOGLE_cpp_style_line_directive : require"
    assert TARGETS["hlsl"].header() == TARGETS["wgsl"].header() == ""
    assert TARGETS["glsl"].line_reset(12, "fragment.glsl") == '#line 12 "fragment.glsl"'
    assert TARGETS["hlsl"].line_reset(3, "a\\b.hlsl") == '#line 3 "a/b.hlsl"'
    assert TARGETS["wgsl"].line_reset(12, "x") == ""


def test_registry():
    assert {name: get_target(name).name for name in LANGS} == {"glsl": "glsl", "hlsl": "hlsl", "wgsl": "wgsl"}
    assert {get_target(name).type_name(VEC3) for name in LANGS} == {"vec3", "float3", "vec3<f32>"}
    with pytest.raises(ValueError, match="unknown target 'msl'"):
        get_target("msl")


@pytest.mark.toolchain
def test_conditional_expressions_are_selects_not_branches_in_every_language(require_tool):
    """`a if c else b` must cost the same everywhere: OpSelect, no branch (GLSL's ?: would branch)."""
    from generator.library.bricks import load_library
    from generator.compose import compose_eval
    from generator.analysis import entry_cost
    from generator.toolchain import CompileJob, compile_many

    for t in ("glslc", "naga", "spirv-opt", "spirv-val"):
        require_tool(t)
    composed = compose_eval("microfacet(ndf=ggx)", load_library())  # the glue's NxH2 is a conditional expression
    jobs = [CompileJob(f"k.{s.language}", s.language, "comp", s.text) for s in composed.sources]
    results = compile_many(jobs)
    branches = {j.language: entry_cost(results[j.key].spirv).branches for j in jobs}
    selects = {j.language: entry_cost(results[j.key].spirv).opcodes.get("OpSelect", 0) for j in jobs}
    assert len(set(branches.values())) == 1, branches
    assert all(n >= 1 for n in selects.values()), selects


@pytest.mark.toolchain
def test_wgsl_vertex_keeps_the_vulkan_coordinate_space(require_tool):
    """naga flips gl_Position.y unless told not to; all languages must place vertices alike."""
    from generator.library.bricks import load_library
    from generator.compose import compose_permutation
    from generator.analysis import entry_cost
    from generator.spec.permutation import LightKey, Permutation
    from generator.toolchain import CompileJob, compile_many

    for t in ("glslc", "naga", "spirv-opt", "spirv-val"):
        require_tool(t)
    perm = Permutation("lambert", (LightKey("point", "none"),), "constants(normal=vertex)")
    sources = [s for s in compose_permutation(perm, load_library()).sources if s.stage == "vert"]
    results = compile_many([CompileJob(f"v.{s.language}", s.language, "vert", s.text) for s in sources])
    negates = {s.language: entry_cost(results[f"v.{s.language}"].spirv).opcodes.get("OpFNegate", 0) for s in sources}
    assert negates == {"glsl": 0, "hlsl": 0, "wgsl": 0}
