"""generator/lang/dump.py: every IR node spelled, no source lines, deterministic, no recursion limit."""
from __future__ import annotations

import pytest

from generator.lang import ir
from generator.lang.dump import dump_expr, dump_function, dump_program, dump_statements
from generator.lang.types import BOOL, FLOAT, INT, UINT, VEC3, storage_buffer, struct, vector
from generator.library.bricks import load_library
from generator.link import eval_program

AT = ir.Loc("bricks/x.py", 17, 5)


def _f(name: str) -> ir.Var:
    return ir.Var(FLOAT, AT, name, "param")


def test_every_statement_and_expression_node_is_spelled():
    light = struct("Light", (("position", vector("float", 4)),))
    buf = storage_buffer(light)
    x = _f("x")
    body = [
        ir.Decl(AT, "v", VEC3, ir.Construct(VEC3, AT, [x, ir.Const(FLOAT, AT, 2), ir.Unary(FLOAT, AT, "-", x)])),
        ir.Assign(AT, ir.Swizzle(FLOAT, AT, ir.Var(VEC3, AT, "v"), "y"), "+", ir.Intrinsic(FLOAT, AT, "sqrt", [x])),
        ir.If(AT, ir.Binary(BOOL, AT, "<", x, ir.Const(FLOAT, AT, 0.5)),
              [ir.Return(AT, ir.Const(FLOAT, AT, 0.0))], [ir.Assign(AT, x, None, ir.Const(FLOAT, AT, 1.0))]),
        ir.For(AT, "i", 4, [ir.Assign(AT, x, "*", ir.Call(FLOAT, AT, "lambert_f", [x]))]),
        ir.For(AT, "k", 0, [ir.Decl(AT, "p", vector("float", 4), ir.Member(
            vector("float", 4), AT, ir.Index(light, AT, ir.Var(buf, AT, "lights", "global"), ir.Var(UINT, AT, "k")),
            "position"))], bound=ir.Intrinsic(UINT, AT, "buffer_length", [ir.Var(buf, AT, "lights", "global")])),
        ir.Switch(AT, ir.Var(INT, AT, "id"), [((0, 2), [ir.Return(AT, x)])], [ir.Return(AT, None)]),
        ir.Return(AT, ir.Select(FLOAT, AT, ir.Const(BOOL, AT, True), x,
                                ir.Const(UINT, AT, 3))),
    ]
    f = ir.Function("brick_entry", [ir.Param("x", FLOAT, AT, assigned=True), ir.Param("id", INT, AT)], FLOAT,
                    body, AT, doc="a docstring, never printed")
    text = dump_program([f], [light], [ir.Global("lights", buf, 0, 3, AT), ir.Global("variant", UINT, -1, 0)])
    assert text == """\
// linked program: 1 structs, 2 globals, 1 functions

struct Light {
    position: vec4
}

global lights: storage_buffer[Light] (set 0, binding 3)
spec constant variant: uint (id 0)

fn brick_entry(mut x: float, id: int) -> float {  // bricks/x.py
    var v: vec3 = vec3(x, 2.0, (-x))
    v.y += sqrt(x)
    if (x < 0.5) {
        return 0.0
    } else {
        x = 1.0
    }
    for i in range(4) {
        x *= lambert_f(x)
    }
    for k: uint in range(buffer_length(lights)) {
        var p: vec4 = lights[k].position
    }
    switch id {
        case 0, 2: {
            return x
        }
        default: {
            return
        }
    }
    return (true ? x : 3u)
}
"""
    assert "17" not in text and "docstring" not in text


def test_nesting_far_past_the_recursion_limit_dumps():
    e: ir.Expr = _f("x")
    for _ in range(50_000):
        e = ir.Binary(FLOAT, AT, "+", e, ir.Const(FLOAT, AT, 1.0))
    assert dump_expr(e).count("+ 1.0") == 50_000
    body: list = [ir.Return(AT, _f("x"))]
    for _ in range(5_000):
        body = [ir.If(AT, _f("c"), body, [])]
    lines = dump_statements(body)
    assert len(lines) == 2 * 5_000 + 1 and lines[5_000].strip() == "return x"


def test_unknown_nodes_are_refused():
    class Odd(ir.Expr):
        pass

    with pytest.raises(TypeError, match="Odd"):
        dump_expr(Odd(FLOAT, AT))


def test_a_linked_program_dumps_the_same_twice_and_without_source_lines():
    lib = load_library()
    dumps = []
    for _ in range(2):
        p = eval_program("microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)", lib).program
        dumps.append(dump_program(p.functions, p.structs, p.globals))
    assert dumps[0] == dumps[1]
    assert "fn microfacet_" in dumps[0] and "// bricks/brdf/specular/microfacet.py" in dumps[0]
    assert ".py:" not in dumps[0] and "0x" not in dumps[0]
    assert dump_function(p.functions[0])[0].startswith("fn ggx_ndf(NdotH: float")
