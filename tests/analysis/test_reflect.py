"""Reflection from SPIR-V (generator.analysis.reflect) against the real toolchain, no mocks.

Two halves: the example scene built by the real build (facts read off the generated
GLSL sources must hold for the SPIR-V of every language, and the three languages must
agree), and tiny hand-written shaders that pin one layout or descriptor rule each.
"""
from __future__ import annotations

import json
import re
import struct
import subprocess
from pathlib import Path

import pytest

from tests.conftest import require_tool
from generator.analysis.reflect import Reflection, SpirvError, flatten_layout, reflect

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenes" / "example.toml"
LANGS = ("glsl", "hlsl", "wgsl")


@pytest.fixture(scope="module")
def tools():
    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)


def compile_one(source: str, language: str = "glsl", stage: str = "frag", optimize: bool = True):
    """One job through the project's toolchain: (optimized or validated SPIR-V, front-end SPIR-V)."""
    from generator.toolchain import CompileJob, compile_many

    r = compile_many([CompileJob(f"t.{stage}.{language}", language, stage, source)], optimize=optimize)
    res = next(iter(r.values()))
    assert res.ok, res.errors()
    return res.spirv, res.spirv_unopt


def by_binding(resources) -> dict:
    return {(r.set, r.binding): r for r in resources}


# ------------------------------------------------------------------ the example scene

@pytest.fixture(scope="module")
def example(tmp_path_factory, tools):
    """{(hash, stage): {lang: Reflection}} and {hash: GLSL sources by stage} of the built example scene."""
    from generator.assemble import BuildContext, build
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    lib = load_library()
    out = tmp_path_factory.mktemp("reflect")
    res = build(load_scene(EXAMPLE, lib), out, BuildContext(lib))
    assert res.ok, res.failures
    refl, glsl = {}, {}
    for perm in res.manifest["permutations"]:
        for lang, stages in perm["languages"].items():
            for stage, item in stages.items():
                refl.setdefault((perm["hash"], stage), {})[lang] = reflect((out / item["spirv"]).read_bytes())
                if lang == "glsl":
                    glsl.setdefault(perm["hash"], {})[stage] = (out / item["source"]).read_text()
    assert len(glsl) == 5 and all(set(v) == set(LANGS) for v in refl.values())
    return refl, glsl


_DECL = re.compile(r"^layout\(set = (\d+), binding = (\d+)\) uniform (\w+)(?: (\w+);| \{ ([^}]*) \} (\w+);)$", re.M)
_IO = re.compile(r"^layout\(location = (\d+)\) (in|out) (\w+) (\w+);$", re.M)
_STD140 = {"float": (4, 4), "vec2": (8, 8), "vec3": (12, 16), "vec4": (16, 16), "uvec4": (16, 16),
           "ivec4": (16, 16), "mat4": (64, 16)}  # (size, base alignment)


def std140_layout(body: str) -> list[str]:
    """flatten_layout() leaves a GLSL std140 block body must give (the member types the templates use)."""
    leaves, off = [], 0
    for decl in filter(None, (d.strip() for d in body.split(";"))):
        m = re.fullmatch(r"(\w+) (\w+)(?:\[(\d+)\])?", decl)
        assert m and m[1] in _STD140, f"std140_layout() does not know {decl!r}: extend it"
        size, align = _STD140[m[1]]
        if m[3]:  # arrays: every element aligned to 16
            align = stride = max(16, align)
            off = -(-off // align) * align
            leaves.append(f"{off}:{m[1]}[{m[3]}] s{stride}" + (" m16" if m[1] == "mat4" else ""))
            off += stride * int(m[3])
        else:
            off = -(-off // align) * align
            leaves.append(f"{off}:{m[1]}" + (" m16" if m[1] == "mat4" else ""))
            off += size
    return leaves


_KIND = {"texture2D": ("sampled_image", "2d"), "textureCube": ("sampled_image", "cube"),
         "texture3D": ("sampled_image", "3d"), "sampler": ("sampler", None)}


def declared(source: str) -> dict:
    """(set, binding) -> (kind, dim, name, layout leaves) as the GLSL source declares them."""
    out = {}
    for s, b, ty, var, body, block_var in _DECL.findall(source):
        if body:
            out[int(s), int(b)] = ("uniform_buffer", None, block_var, std140_layout(body))
        else:
            assert ty in _KIND, f"declared() does not know 'uniform {ty}': extend it"
            out[int(s), int(b)] = (*_KIND[ty], var, [])
    return out


@pytest.mark.toolchain
def test_every_example_shader_has_one_main_entry_point_and_json_output(example):
    refl, _ = example
    for (h, stage), langs in refl.items():
        for lang, r in langs.items():
            assert isinstance(r, Reflection) and r.version == "1.3"
            e = r.entry()
            assert (e.name, e.stage) == ("main", stage)
            assert e.execution_model == {"vert": "Vertex", "frag": "Fragment"}[stage]
            assert e.resources == r.resources, "one entry point: it uses every resource the optimizer kept"
            d = json.loads(json.dumps(r.as_dict()))
            assert d["entry_points"][0]["resources"][0]["set"] == e.resources[0].set
            json.dumps(r.comparable())


@pytest.mark.toolchain
def test_resources_are_what_the_glsl_source_declares_in_every_language(example):
    """Set, binding, kind, dimension and std140 layout read off each GLSL source hold in all three SPIR-Vs."""
    refl, glsl = example
    for h, stages in glsl.items():
        for stage, source in stages.items():
            want = declared(source)
            assert want, f"{h}.{stage}: no declarations parsed"
            for lang, r in refl[h, stage].items():
                got = by_binding(r.entry().resources)
                assert set(got) == set(want), (h, stage, lang)
                for key, (kind, dim, _, leaves) in want.items():
                    res = got[key]
                    assert (res.kind, res.dim, res.count) == (kind, dim, 1), (h, stage, lang, key)
                    if kind == "uniform_buffer":
                        assert flatten_layout(res.members) == leaves, (h, stage, lang, key)
                        assert res.size == int(leaves[-1].split(":")[0]) + _block_tail(leaves[-1])
                    if kind == "sampled_image":
                        assert (res.arrayed, res.depth, res.multisampled, res.sampled_type) == (False, False, False, "float")


def _block_tail(leaf: str) -> int:
    ty = leaf.split(":")[1].split()[0]
    if m := re.fullmatch(r"(\w+)\[(\d+)\]", ty):
        return 16 * int(m[2]) * (4 if m[1] == "mat4" else 1)
    return _STD140[ty][0]


@pytest.mark.toolchain
def test_fragment_material_block_and_texture_pairs(example):
    refl, glsl = example
    seen_textures = 0
    for h, stages in glsl.items():
        n = int(re.search(r"uniform Material \{ vec4 data\[(\d+)\]; \} material;", stages["frag"])[1])
        for lang, r in refl[h, "frag"].items():
            res = by_binding(r.entry().resources)
            mat = res[1, 0]
            assert mat.kind == "uniform_buffer" and mat.size == 16 * n
            assert flatten_layout(mat.members) == [f"0:vec4[{n}] s16"]
            images = [k for k, v in res.items() if v.kind == "sampled_image"]
            for s, b in images:  # every texture: image at B, its sampler at B + 1
                assert res[s, b].dim == "2d" and res[s, b + 1].kind == "sampler", (h, lang, s, b)
            assert {k for k, v in res.items() if v.kind == "sampler"} == {(s, b + 1) for s, b in images}
            seen_textures += len(images)
        # GLSL names: the texture "t_x" and its sampler "_smp_t_x"
        for (s, b), v in by_binding(refl[h, "frag"]["glsl"].entry().resources).items():
            if v.kind == "sampled_image":
                assert by_binding(refl[h, "frag"]["glsl"].resources)[s, b + 1].name == "_smp_" + v.name
    assert seen_textures >= 3 * 4, "the example has albedo, normal and shadow maps"


@pytest.mark.toolchain
def test_stage_interfaces_match_the_sources_and_each_other(example):
    refl, glsl = example
    for h, stages in glsl.items():
        io = {(stage, d): sorted((int(loc), ty) for loc, dd, ty, _ in _IO.findall(src) if dd == d)
              for stage, src in stages.items() for d in ("in", "out")}
        # fixed attribute slots (position 0, normal 1, tangent 2, uv 3), unused ones left out
        assert io["vert", "in"][:2] == [(0, "vec3"), (1, "vec3")]
        assert {x for x in io["vert", "in"][2:]} <= {(2, "vec4"), (3, "vec2")}
        assert io["frag", "out"] == [(0, "vec4")]
        for lang in LANGS:
            v, f = refl[h, "vert"][lang].entry(), refl[h, "frag"][lang].entry()
            assert [(x.location, x.type) for x in v.inputs] == io["vert", "in"], (h, lang)
            assert [(x.location, x.type) for x in v.outputs] == io["vert", "out"], (h, lang)
            assert [(x.location, x.type) for x in f.inputs] == io["frag", "in"], (h, lang)
            assert [(x.location, x.type) for x in f.outputs] == [(0, "vec4")], (h, lang)
            # what the vertex stage writes, the fragment stage can read
            assert {(x.location, x.type) for x in f.inputs} <= {(x.location, x.type) for x in v.outputs}
            assert [(b.direction, b.builtin, b.type) for b in v.builtins] == [("output", "Position", "vec4")], lang
            assert f.builtins == [], lang
            assert f.execution_modes == ["OriginUpperLeft"]


@pytest.mark.toolchain
def test_glsl_hlsl_wgsl_of_one_permutation_agree(example):
    refl, _ = example
    for (h, stage), langs in refl.items():
        glsl = langs["glsl"].comparable()
        for lang in ("hlsl", "wgsl"):
            assert langs[lang].comparable() == glsl, (h, stage, lang)


@pytest.mark.toolchain
def test_names_nesting_and_matrix_layout_differ_as_documented(example):
    """What the module docstring says is not comparable, pinned (a tool update that changes it fails here)."""
    refl, _ = example
    h = next(h for (h, st), langs in refl.items() if st == "frag")
    g, x, w = (by_binding(refl[h, "frag"][lang].entry().resources) for lang in LANGS)
    assert (g[1, 0].name, g[1, 0].type_name, g[1, 0].members[0].name) == ("material", "Material", "data")
    assert (x[1, 0].name, x[1, 0].type_name, x[1, 0].members[0].name) == (None, "Material", "material_data")
    assert (w[1, 0].name, w[1, 0].type_name, w[1, 0].members[0].name) == (None, None, None)
    # naga wraps the declared struct in a one-member block: { Material @0 }
    assert w[1, 0].members[0].type == "struct" and w[1, 0].members[0].members[0].type.startswith("vec4[")
    assert g[1, 0].members[0].type == x[1, 0].members[0].type == w[1, 0].members[0].members[0].type
    frame = [[m.matrix_layout for m in (d[0, 0].members if lang != "wgsl" else d[0, 0].members[0].members)][:1]
             for lang, d in zip(LANGS, (g, x, w))]
    assert frame == [["column_major"], ["row_major"], ["column_major"]]  # Frame.view_proj
    vert = refl[h, "vert"]
    assert [v.name for v in vert["glsl"].entry().inputs][0] == "a_position"
    assert [v.name for v in vert["hlsl"].entry().inputs][0] == "i.a_position"
    assert {v.name for v in vert["wgsl"].entry().inputs} == {None}


# ------------------------------------------------------------------ hand-written shaders

STD140 = """#version 450
layout(set = 0, binding = 2, std140) uniform Params { mat4 m; vec3 a; float b; vec2 c; float arr[3]; mat3 n; } p;
layout(set = 0, binding = 3, std140, row_major) uniform Rows { mat4 r; } rows;
layout(location = 0) out vec4 o;
void main() { o = p.m * vec4(p.a, p.b) + vec4(p.c, p.arr[2], 0.0) + rows.r[1] + vec4(p.n[2], 0.0); }
"""


@pytest.mark.toolchain
def test_std140_block_offsets_sizes_and_strides(tools):
    spv, _ = compile_one(STD140)
    res = by_binding(reflect(spv).entry().resources)
    p = res[0, 2]
    assert (p.kind, p.name, p.type_name) == ("uniform_buffer", "p", "Params")
    got = [(m.name, m.offset, m.type, m.size, m.array_stride, m.matrix_stride, m.matrix_layout) for m in p.members]
    assert got == [("m", 0, "mat4", 64, None, 16, "column_major"),
                   ("a", 64, "vec3", 12, None, None, None),
                   ("b", 76, "float", 4, None, None, None),      # a float fills the vec3's last 4 bytes
                   ("c", 80, "vec2", 8, None, None, None),
                   ("arr", 96, "float[3]", 48, 16, None, None),  # std140: array elements on 16 bytes
                   ("n", 144, "mat3", 48, None, 16, "column_major")]
    assert p.size == 192
    assert res[0, 3].members[0].matrix_layout == "row_major"
    assert flatten_layout(p.members)[:2] == ["0:mat4 m16", "64:vec3"]


STORAGE = """#version 450
struct Light { vec3 pos; float range; vec4 color; };
layout(set = 0, binding = 0, std430) readonly buffer Lights { uint count; Light lights[]; } lb;
layout(set = 0, binding = 1, std430) writeonly buffer Out { float v[3]; vec4 tail[]; } outb;
layout(set = 0, binding = 5) uniform sampler2D never_read;
layout(local_size_x = 8, local_size_y = 4) in;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < lb.count) { outb.tail[i] = lb.lights[i].color * lb.lights[i].range + vec4(lb.lights[i].pos, 0.0); }
    outb.v[1] = 1.0;
}
"""


@pytest.mark.toolchain
def test_storage_buffer_of_structs_with_runtime_array(tools):
    spv, _ = compile_one(STORAGE, stage="comp")
    e = reflect(spv).entry("comp")
    res = by_binding(e.resources)
    lb, out = res[0, 0], res[0, 1]
    assert (lb.kind, lb.readonly, lb.writeonly, lb.type_name) == ("storage_buffer", True, False, "Lights")
    assert (out.kind, out.readonly, out.writeonly) == ("storage_buffer", False, True)
    count, lights = lb.members
    assert (count.offset, count.type, lights.offset, lights.type, lights.array_stride, lights.size) == \
        (0, "uint", 16, "Light[]", 32, 0)
    assert [(m.name, m.offset, m.type, m.size) for m in lights.members] == \
        [("pos", 0, "vec3", 12), ("range", 12, "float", 4), ("color", 16, "vec4", 16)]
    assert lb.size == 16, "the fixed part: a trailing runtime array counts from its offset"
    assert flatten_layout(lb.members) == ["0:uint", "16:{0:vec3,12:float,16:vec4}[] s32"]
    assert flatten_layout(out.members) == ["0:float[3] s4", "16:vec4[] s16"], "std430: float arrays packed"
    assert e.local_size == [8, 4, 1] and e.execution_modes == ["LocalSize"]
    assert [(b.direction, b.builtin, b.type) for b in e.builtins] == [("input", "GlobalInvocationId", "uvec3")]
    assert (0, 5) not in res


IMAGES = """#version 450
layout(set = 0, binding = 0) uniform samplerCube env;
layout(set = 0, binding = 1) uniform textureCube env_t;
layout(set = 0, binding = 2) uniform sampler smp;
layout(set = 0, binding = 3) uniform texture2D shadow;
layout(set = 0, binding = 4) uniform samplerShadow cmp;
layout(set = 0, binding = 5) uniform sampler2DArrayShadow cascades[4];
layout(set = 0, binding = 6) uniform sampler3D volume;
layout(set = 1, binding = 0, rgba8) uniform writeonly image2D img;
layout(set = 1, binding = 1, r32f) uniform readonly image2D heights;
layout(set = 1, binding = 2) uniform sampler2D unused_tex;
layout(push_constant) uniform PC { vec4 tint; uint mode; } pc;
layout(location = 0) in vec3 n;
layout(location = 1) flat in uint id;
layout(location = 2) noperspective in vec2 uv;
layout(location = 0) out vec4 o;
void main() {
    vec4 c = texture(env, n) + texture(samplerCube(env_t, smp), n) * pc.tint;
    c += texture(sampler2DShadow(shadow, cmp), vec3(uv, 0.5)) + texture(cascades[1], vec4(uv, 1.0, 0.5));
    c += texture(volume, n) + imageLoad(heights, ivec2(uv)).x;
    imageStore(img, ivec2(gl_FragCoord.xy), c);
    o = c + float(id + pc.mode);
}
"""


@pytest.mark.toolchain
def test_images_samplers_push_constants_and_stage_io(tools):
    spv, unopt = compile_one(IMAGES)
    r = reflect(spv)
    e = r.entry("main")
    res = by_binding(e.resources)
    facts = {k: (v.kind, v.count, v.dim, v.arrayed, v.depth) for k, v in res.items()}
    assert facts == {
        (0, 0): ("combined_image_sampler", 1, "cube", False, False),
        (0, 1): ("sampled_image", 1, "cube", False, False),
        (0, 2): ("sampler", 1, None, None, None),
        (0, 3): ("sampled_image", 1, "2d", False, True),  # used with a shadow sampler: a depth image
        (0, 4): ("sampler", 1, None, None, None),
        (0, 5): ("combined_image_sampler", 4, "2d", True, True),
        (0, 6): ("combined_image_sampler", 1, "3d", False, False),
        (1, 0): ("storage_image", 1, "2d", False, False),
        (1, 1): ("storage_image", 1, "2d", False, False),
    }
    assert (res[1, 0].format, res[1, 0].readonly, res[1, 0].writeonly) == ("rgba8", False, True)
    assert (res[1, 1].format, res[1, 1].readonly, res[1, 1].writeonly) == ("r32f", True, False)
    assert res[0, 0].name == "env" and res[0, 0].sampled_type == "float"
    [pc] = e.push_constants
    assert (pc.name, pc.type_name, pc.size) == ("pc", "PC", 20)
    assert [(m.name, m.offset, m.type) for m in pc.members] == [("tint", 0, "vec4"), ("mode", 16, "uint")]
    assert [(v.location, v.name, v.type, v.interpolation) for v in e.inputs] == \
        [(0, "n", "vec3", []), (1, "id", "uint", ["flat"]), (2, "uv", "vec2", ["noperspective"])]
    assert [(v.location, v.type) for v in e.outputs] == [(0, "vec4")]
    assert [(b.direction, b.builtin) for b in e.builtins] == [("input", "FragCoord")]
    # The optimizer removes the unused texture; before it, the module declares it but main does not use it.
    assert (1, 2) not in by_binding(r.resources)
    before = reflect(unopt)
    assert (1, 2) in by_binding(before.resources) and (1, 2) not in by_binding(before.entry().resources)
    assert by_binding(before.entry().resources).keys() == res.keys()


VERTEX = """#version 450
layout(location = 0) in vec3 pos;
layout(location = 1) in vec4 weights[2];
layout(location = 3) in mat2 m;
layout(location = 0) out Block { vec3 a; layout(location = 4, component = 1) vec2 b; } outs;
layout(location = 6) out Tail { mat3 c; dvec3 e; vec2 d; } tail;
void main() {
    gl_Position = vec4(pos, 1.0) + weights[1] + vec4(m[0], m[1]);
    outs.a = pos; outs.b = pos.xy; tail.c = mat3(1.0); tail.e = dvec3(pos); tail.d = pos.yz;
}
"""


@pytest.mark.toolchain
def test_vertex_io_arrays_blocks_and_per_vertex_builtins(tools):
    spv, _ = compile_one(VERTEX, stage="vert")
    e = reflect(spv).entry("vert")
    assert [(v.location, v.type) for v in e.inputs] == [(0, "vec3"), (1, "vec4[2]"), (3, "mat2")]
    assert [(v.location, v.component, v.name, v.type) for v in e.outputs] == \
        [(0, None, "a", "vec3"), (4, 1, "b", "vec2"),
         (6, None, "c", "mat3"), (9, None, "e", "dvec3"), (11, None, "d", "vec2")]  # on from the block's 6
    # gl_PerVertex declares PointSize, ClipDistance, CullDistance too; only Position is written
    assert [(b.direction, b.builtin, b.type) for b in e.builtins] == [("output", "Position", "vec4")]


HLSL = """struct Light { float3 pos; float range; float4 color; };
StructuredBuffer<Light> lights : register(t0, space0);
RWStructuredBuffer<float4> result : register(u1, space0);
cbuffer Params : register(b2, space0) { float4x4 m; float3 a; float b; uint count; };
[numthreads(64, 1, 1)]
void main(uint3 gid : SV_DispatchThreadID) {
    if (gid.x < count) { result[gid.x] = mul(m, lights[gid.x].color) * b + float4(a, lights[gid.x].range); }
}
"""
WGSL = """struct Light { pos: vec3<f32>, range: f32, color: vec4<f32> }
struct Params { m: mat4x4<f32>, a: vec3<f32>, b: f32, count: u32 }
@group(0) @binding(0) var<storage, read> lights: array<Light>;
@group(0) @binding(1) var<storage, read_write> result: array<vec4<f32>>;
@group(0) @binding(2) var<uniform> params: Params;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x < params.count) {
        result[gid.x] = params.m * lights[gid.x].color * params.b + vec4<f32>(params.a, lights[gid.x].range);
    }
}
"""
GLSL = """#version 450
layout(local_size_x = 64) in;
struct Light { vec3 pos; float range; vec4 color; };
layout(set = 0, binding = 0, std430) readonly buffer Lights { Light data[]; } lights;
layout(set = 0, binding = 1, std430) buffer Result { vec4 data[]; } result;
layout(set = 0, binding = 2) uniform Params { mat4 m; vec3 a; float b; uint count; } params;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < params.count) { result.data[i] = params.m * lights.data[i].color * params.b + vec4(params.a, lights.data[i].range); }
}
"""


@pytest.mark.toolchain
def test_one_compute_shader_in_three_languages_agrees(tools):
    refl = {lang: reflect(compile_one(src, lang, "comp")[0]) for lang, src in
            (("glsl", GLSL), ("hlsl", HLSL), ("wgsl", WGSL))}
    comparable = {lang: r.comparable() for lang, r in refl.items()}
    assert comparable["hlsl"] == comparable["glsl"] == comparable["wgsl"]
    [e] = comparable["glsl"]["entry_points"]
    assert [(r["set"], r["binding"], r["kind"], r["readonly"], r["size"], r["layout"]) for r in e["resources"]] == [
        (0, 0, "storage_buffer", True, 0, ["0:{0:vec3,12:float,16:vec4}[] s32"]),
        (0, 1, "storage_buffer", False, 0, ["0:vec4[] s16"]),
        (0, 2, "uniform_buffer", None, 84, ["0:mat4 m16", "64:vec3", "76:float", "80:uint"]),
    ]
    assert e["local_size"] == [64, 1, 1]
    # names: HLSL's StructuredBuffer is named after the variable, its member "@data"; naga names nothing
    h = by_binding(refl["hlsl"].entry().resources)
    assert (h[0, 0].type_name, h[0, 0].members[0].name, h[0, 2].name, h[0, 2].type_name) == \
        ("lights", "@data", None, "Params")
    w = by_binding(refl["wgsl"].entry().resources)
    assert w[0, 0].members[0].type == "struct[]" and w[0, 0].type_name is None


@pytest.mark.toolchain
def test_entry_points_of_one_module_each_get_the_resources_they_use(tools, tmp_path):
    naga = require_tool("naga")
    (tmp_path / "m.wgsl").write_text("""
@group(0) @binding(0) var<uniform> xf: mat4x4<f32>;
@group(0) @binding(1) var env: texture_cube<f32>;
@group(0) @binding(2) var smp: sampler;
@vertex fn vs(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> { return xf * vec4<f32>(p, 1.0); }
@fragment fn fs(@location(0) n: vec3<f32>) -> @location(0) vec4<f32> { return textureSample(env, smp, n); }
""")
    subprocess.run([naga, "--spirv-version", "1.3", "m.wgsl", "m.spv"], cwd=tmp_path, check=True,
                   capture_output=True)
    r = reflect((tmp_path / "m.spv").read_bytes())
    assert sorted((e.name, e.stage) for e in r.entry_points) == [("fs", "frag"), ("vs", "vert")]
    assert [(x.binding, x.kind) for x in r.entry("vs").resources] == [(0, "uniform_buffer")]
    assert [(x.binding, x.kind, x.dim) for x in r.entry("fs").resources] == \
        [(1, "sampled_image", "cube"), (2, "sampler", None)]
    assert len(r.resources) == 3
    # a bare matrix is wrapped by naga in a block of one member
    assert flatten_layout(r.entry("vs").resources[0].members) == ["0:mat4 m16"]
    with pytest.raises(KeyError):
        r.entry()


@pytest.mark.toolchain
def test_big_endian_module_reads_the_same(tools):
    spv, _ = compile_one(STD140)
    words = struct.unpack(f"<{len(spv) // 4}I", spv)
    assert reflect(struct.pack(f">{len(words)}I", *words)).as_dict() == reflect(spv).as_dict()


def test_not_spirv_is_an_error():
    with pytest.raises(SpirvError):
        reflect(b"\x00" * 24)
    with pytest.raises(SpirvError):
        reflect(b"abc")


DEPTH_GLSL = """#version 450
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform texture2D shadow;
layout(set = 0, binding = 1) uniform samplerShadow cmp;
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D img;
void main() {
    vec2 uv = vec2(gl_GlobalInvocationID.xy) / 64.0;
    imageStore(img, ivec2(gl_GlobalInvocationID.xy), vec4(textureLod(sampler2DShadow(shadow, cmp), vec3(uv, 0.5), 0.0)));
}
"""
DEPTH_HLSL = """Texture2D shadow : register(t0, space0);
SamplerComparisonState cmp : register(s1, space0);
{fmt}RWTexture2D<float4> img : register(u2, space0);
[numthreads(8, 8, 1)]
void main(uint3 id : SV_DispatchThreadID) {{
    img[id.xy] = (float4)shadow.SampleCmpLevelZero(cmp, float2(id.xy) / 64.0, 0.5);
}}
"""
DEPTH_WGSL = """@group(0) @binding(0) var shadow: texture_depth_2d;
@group(0) @binding(1) var cmp: sampler_comparison;
@group(0) @binding(2) var img: texture_storage_2d<rgba8unorm, write>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let d = textureSampleCompareLevel(shadow, cmp, vec2<f32>(id.xy) / 64.0, 0.5);
    textureStore(img, id.xy, vec4<f32>(d));
}
"""


@pytest.mark.toolchain
def test_depth_images_and_storage_image_formats_across_languages(tools):
    """The docstring's "equal only when the sources say the same thing": depth and format."""
    srcs = {"glsl": DEPTH_GLSL, "wgsl": DEPTH_WGSL, "hlsl": DEPTH_HLSL.format(fmt=""),
            "hlsl+format": DEPTH_HLSL.format(fmt="[[spv::format_rgba8]] ")}  # glslang's spelling (not DXC's)
    res = {k: by_binding(reflect(compile_one(src, k.split("+")[0], "comp")[0]).entry().resources)
           for k, src in srcs.items()}
    for k, r in res.items():
        assert (r[0, 0].kind, r[0, 0].dim, r[0, 0].depth) == ("sampled_image", "2d", True), k
        assert r[0, 1].kind == "sampler", k  # a comparison sampler is a plain OpTypeSampler
        assert r[0, 2].kind == "storage_image", k
    assert {k: r[0, 2].format for k, r in res.items()} == \
        {"glsl": "rgba8", "wgsl": "rgba8", "hlsl": "rgba32f", "hlsl+format": "rgba8"}
    assert {k: r[0, 2].writeonly for k, r in res.items()} == \
        {"glsl": True, "wgsl": True, "hlsl": False, "hlsl+format": False}
