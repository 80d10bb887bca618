"""Shaders around tests/bricks/lang/ext_constructs.py for the toolchain tests of tests/lang/test_lang_ext.py.

The harness functions are built directly as IR (no brick text), as the link stage builds
glue: they call every brick function and add a Switch and a runtime-bounded For of their
own. Buffers and the cube texture are declared through ir.Global and Target.emit(globals=).
"""
from __future__ import annotations

from pathlib import Path

from generator.lang import ir, parse_module
from generator.lang.types import FLOAT, INT, TEXTURECUBE, UINT, VEC3, VEC4, array

ROOT = Path(__file__).resolve().parent.parent
BRICK = "tests/bricks/lang/ext_constructs.py"
L = ir.Loc("tests/ext_harness", 1, 1)


def module() -> ir.Module:
    return parse_module((ROOT / BRICK).read_text(), BRICK)


def globals_for(m: ir.Module) -> list[ir.Global]:
    """The brick's buffers at set 0 (bindings 1, 2) and a global cube texture at set 1 (0, 1)."""
    out = []
    for binding, g in enumerate(m.globals.values(), start=1):
        out.append(ir.Global(g.name, g.ty, 0, binding, g.loc))
    out.append(ir.Global("env", TEXTURECUBE, 1, 0))
    return out


def _c(v):
    return ir.Const(FLOAT if isinstance(v, float) else INT, L, v)


def _call(m, name, args):
    f = m.functions[name]
    return ir.Call(f.ret, L, name, args)


def harness(m: ir.Module) -> list[ir.Function]:
    x = ir.Var(FLOAT, L, "x", "param")
    acc = ir.Var(FLOAT, L, "acc", "local")
    i, u = ir.Var(INT, L, "i", "local"), ir.Var(UINT, L, "u", "local")
    lobe_t = m.structs["Lobe"]
    lobes_t = array(lobe_t, 4)
    lobe = ir.Construct(lobe_t, L, [ir.Construct(VEC4, L, [x]), ir.Construct(VEC4, L, [x])])
    lobes = ir.Var(lobes_t, L, "lobes", "local")
    env = ir.Var(TEXTURECUBE, L, "env", "global")
    v3 = ir.Construct(VEC3, L, [x])

    def add(e):
        if e.ty != FLOAT:
            e = ir.Swizzle(FLOAT, L, e, "x")
        return ir.Assign(L, acc, "+", e)

    body = [
        ir.Decl(L, "acc", FLOAT, _c(0.0)),
        ir.Decl(L, "i", INT, ir.Construct(INT, L, [x])),
        ir.Decl(L, "u", UINT, ir.Construct(UINT, L, [x])),
        ir.Decl(L, "lobes", lobes_t, ir.Construct(lobes_t, L, [lobe] * 4)),
        add(_call(m, "classify", [i, x])),
        add(_call(m, "pick", [u])),
        add(_call(m, "no_default", [i])),
        add(_call(m, "sum_lobes", [lobes, i, x])),
        add(_call(m, "weights", [u, x])),
        add(_call(m, "shade_lights", [v3])),
        add(_call(m, "read_table", [i])),
        add(_call(m, "env_light", [env, v3, _c(0.0)])),
        # glue-style constructs built as IR
        ir.Switch(L, i, [((5,), [ir.Assign(L, acc, "+", _c(1.0))]),
                         ((6, 7), [ir.Return(L, acc)])],
                  [ir.Assign(L, acc, "*", _c(2.0))]),
        ir.For(L, "k", 0, [ir.Assign(L, acc, "+", ir.Construct(FLOAT, L, [ir.Var(UINT, L, "k", "local")]))],
               bound=u),
        ir.Return(L, acc),
    ]
    comp = ir.Function("harness", [ir.Param("x", FLOAT, L)], FLOAT, body, L)
    d = ir.Var(VEC3, L, "d", "param")
    frag = ir.Function("harness_frag", [ir.Param("d", VEC3, L)], VEC4,
                       [ir.Return(L, _call(m, "env_sample", [env, d]))], L)
    return [comp, frag]


SHELLS = {
    ("glsl", "comp"): "#version 450\n{header}\nlayout(local_size_x = 1) in;\n"
                      "layout(std430, set = 0, binding = 0) buffer Data {{ float data[]; }} buf;\n{functions}\n"
                      "void main() {{ buf.data[0] = harness(buf.data[0]); }}\n",
    ("glsl", "frag"): "#version 450\n{header}\nlayout(location = 0) in vec3 v_d;\n"
                      "layout(location = 0) out vec4 o_color;\n{functions}\n"
                      "void main() {{ o_color = harness_frag(v_d); }}\n",
    ("hlsl", "comp"): "[[vk::binding(0, 0)]] RWStructuredBuffer<float> buf : register(u0, space0);\n{functions}\n"
                      "[numthreads(1, 1, 1)] void main() {{ buf[0] = harness(buf[0]); }}\n",
    ("hlsl", "frag"): "{functions}\nfloat4 main(float3 d : TEXCOORD0) : SV_Target {{ return harness_frag(d); }}\n",
    ("wgsl", "comp"): "@group(0) @binding(0) var<storage, read_write> buf: array<f32>;\n{functions}\n"
                      "@compute @workgroup_size(1) fn main() {{ buf[0] = harness(buf[0]); }}\n",
    ("wgsl", "frag"): "{functions}\n@fragment fn main(@location(0) d: vec3<f32>) -> @location(0) vec4<f32> "
                      "{{ return harness_frag(d); }}\n",
}


def shader(m: ir.Module, lang: str, stage: str):
    """(complete shader text, Emitted) for one language and stage."""
    from generator.backends import get_target

    t = get_target(lang)
    emitted = t.emit(list(m.structs.values()), list(m.functions.values()) + harness(m), globals_for(m))
    return SHELLS[lang, stage].format(header=t.header(), functions=emitted.text), emitted
