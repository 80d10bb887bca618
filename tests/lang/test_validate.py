"""The IR validator: every program the link stage builds keeps the emitters' invariants, and it catches breaks."""
from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

from generator.lang import ir
from generator.lang.types import FLOAT, INT, VEC3, VEC4, storage_buffer, struct
from generator.lang.validate import InternalError, check_program, validate_program
from generator.library.bricks import load_library
from generator.link import eval_program, link_permutation, switch_program
from generator.link.uber import link_ubershader
from generator.scene.load import load_scene
from generator.spec.permutation import LightKey, Permutation

REPO = Path(__file__).resolve().parents[2]
CASES = tomllib.loads((REPO / "tests" / "golden" / "cases.toml").read_text())
L0 = ir.Loc("t.py", 1, 1)


@pytest.fixture(scope="module")
def lib():
    return load_library()


@pytest.fixture(scope="module")
def link_lib():
    return load_library([REPO / CASES["link_bricks"]])


def _programs(lib, link_lib):
    """Every program the golden cases and the example scenes link: eval, switch, permutation, shade and
    ubershader glue (the link stage's IR builders all appear)."""
    for spec in CASES["eval"]:
        yield f"eval {spec}", eval_program(spec, lib).program
    for spec in CASES["link_eval"]:
        yield f"eval {spec}", eval_program(spec, link_lib).program
    for specs in CASES["link_switch"]:
        yield f"switch {specs}", switch_program(specs, link_lib).program
    for case in CASES["link_permutation"]:
        lights = tuple(LightKey(*k.lstrip("*").split("/"), dynamic=k.startswith("*")) for k in case["lights"])
        perm = Permutation(case["brdf"], lights, case["packing"], case["output"])
        yield f"permutation {perm.canonical()}", link_permutation(perm, link_lib).program
        if case.get("shade_kernel"):
            yield f"shade {perm.canonical()}", link_permutation(perm, link_lib, kernel=True).program
    for scene_path in CASES["scenes"]:
        scene = load_scene(REPO / scene_path, lib)
        perms = [p for _, p in sorted(scene.permutations.items())]
        for perm in perms:
            yield f"permutation {perm.canonical()}", link_permutation(perm, lib).program
        yield f"ubershader of {scene_path}", link_ubershader(perms, lib).program
        plain = [p for p in perms if not link_permutation(p, lib).interface.textures]  # kernels bind no textures
        yield f"ubershader kernel of {scene_path}", link_ubershader(plain, lib, kernel=True).program
        yield f"specialized ubershader of {scene_path}", link_ubershader(perms, lib, specialized=True).program


def test_every_linked_program_keeps_the_invariants(lib, link_lib):
    checked = 0
    for name, prog in _programs(lib, link_lib):
        found = validate_program(prog.functions, prog.globals)
        assert not found, f"{name}:\n" + "\n".join(map(str, found))
        checked += 1
    assert checked > 40  # the cases really ran


# ------------------------------------------------------------------ the validator catches what it claims

def _f(name, params, ret, body):
    return ir.Function(name, params, ret, body, L0)


def _one(fx) -> ir.Function:
    """f(x: float) -> float: return x * 2.0"""
    x = ir.Var(FLOAT, L0, "x", "param")
    return _f(fx, [ir.Param("x", FLOAT, L0)], FLOAT,
              [ir.Return(L0, ir.Binary(FLOAT, L0, "*", x, ir.Const(FLOAT, L0, 2.0)))])


def _caller(args, ty=FLOAT, callee="f"):
    return _f("g", [], FLOAT, [ir.Return(L0, ir.Call(ty, L0, callee, args))])


def _messages(functions, globals_=()):
    return [v.message for v in validate_program(functions, globals_)]


def test_a_clean_program_has_no_violation():
    assert _messages([_one("f"), _caller([ir.Const(FLOAT, L0, 1.0)])]) == []


@pytest.mark.parametrize("case, expected", [
    ("arity", "with 0 arguments; it takes 1"),
    ("arg type", "passes a int as 'x: float'"),
    ("result type", "is typed vec3; it returns float"),
    ("undefined callee", "not defined before it"),
    ("return type", "returns int from a function returning float"),
    ("undeclared local", "neither a parameter nor a local declared before"),
    ("unknown intrinsic", "unknown intrinsic 'frobnicate'"),
    ("duplicate case", "case value 1 appears twice"),
    ("float selector", "switch selector is float"),
    ("float index", "index is float"),
    ("assign to const", "assignment to the const 'PI'"),
    ("wide swizzle target", "only one component may be assigned"),
    ("unmarked param write", "parameter 'x' is assigned but not marked assigned"),
    ("buffer passed", "used other than indexed or by buffer_length"),
    ("twice", "defined twice"),
])
def test_each_invariant_is_checked(case, expected):
    one = lambda v: ir.Const(FLOAT, L0, v)  # noqa: E731
    i1 = ir.Const(INT, L0, 1)
    fns = [_one("f")]
    if case == "arity":
        fns.append(_caller([]))
    elif case == "arg type":
        fns.append(_caller([i1]))
    elif case == "result type":
        fns.append(_f("g", [], VEC3, [ir.Return(L0, ir.Call(VEC3, L0, "f", [one(1.0)]))]))
    elif case == "undefined callee":
        fns.append(_caller([one(1.0)], callee="h"))
    elif case == "return type":
        fns.append(_f("g", [], FLOAT, [ir.Return(L0, i1)]))
    elif case == "undeclared local":
        fns.append(_f("g", [], FLOAT, [ir.Return(L0, ir.Var(FLOAT, L0, "y"))]))
    elif case == "unknown intrinsic":
        fns.append(_f("g", [], FLOAT, [ir.Return(L0, ir.Intrinsic(FLOAT, L0, "frobnicate", [one(1.0)]))]))
    elif case == "duplicate case":
        fns.append(_f("g", [], FLOAT, [ir.Switch(L0, i1, [((1,), []), ((1,), [])]), ir.Return(L0, one(0.0))]))
    elif case == "float selector":
        fns.append(_f("g", [], FLOAT, [ir.Switch(L0, one(1.0), [((0,), [])]), ir.Return(L0, one(0.0))]))
    elif case == "float index":
        v = ir.Construct(VEC3, L0, [one(1.0)])
        fns.append(_f("g", [], FLOAT, [ir.Return(L0, ir.Index(FLOAT, L0, v, one(0.0)))]))
    elif case == "assign to const":
        fns.append(_f("g", [], FLOAT, [ir.Assign(L0, ir.Var(FLOAT, L0, "PI", "const"), None, one(3.0)),
                                       ir.Return(L0, one(0.0))]))
    elif case == "wide swizzle target":
        body = [ir.Decl(L0, "v", VEC3, ir.Construct(VEC3, L0, [one(0.0)])),
                ir.Assign(L0, ir.Swizzle(VEC3, L0, ir.Var(VEC3, L0, "v"), "xyz"), None,
                          ir.Construct(VEC3, L0, [one(1.0)])),
                ir.Return(L0, one(0.0))]
        fns.append(_f("g", [], FLOAT, body))
    elif case == "unmarked param write":
        f = _one("f")
        f.body.insert(0, ir.Assign(L0, ir.Var(FLOAT, L0, "x", "param"), None, one(1.0)))
        fns = [f]
    elif case == "buffer passed":
        light = struct("Light", (("a", VEC4),))
        buf = storage_buffer(light)
        g = ir.Global("lights", buf)
        fns.append(_f("g", [], FLOAT, [ir.Decl(L0, "b", buf, ir.Var(buf, L0, "lights", "global")),
                                       ir.Return(L0, one(0.0))]))
        assert any(expected in m for m in _messages(fns, [g]))
        return
    elif case == "twice":
        fns.append(_one("f"))
    found = _messages(fns)
    assert any(expected in m for m in found), found


def test_check_program_raises_naming_function_and_location():
    class Prog:
        functions = [_one("f"), _caller([])]
        globals = []
    with pytest.raises(InternalError) as e:
        check_program(Prog())
    assert "t.py:1:1: in g: calls 'f' with 0 arguments" in str(e.value)


def test_a_broken_linked_program_is_caught(lib):
    """A mistake in glue (a call losing an argument) is found before any emitter runs."""
    prog = copy.deepcopy(eval_program("lambert+blinn_phong_normalized", lib).program)
    calls = [e for f in prog.functions for e in ir.walk_body(f.body) if isinstance(e, ir.Call) and e.args]
    assert calls
    calls[-1].args.pop()
    assert any("arguments" in v.message for v in validate_program(prog.functions, prog.globals))


def test_the_validator_walks_deep_trees_without_recursion():
    e = ir.Const(FLOAT, L0, 1.0)
    for _ in range(20000):  # far past Python's recursion limit
        e = ir.Binary(FLOAT, L0, "+", e, ir.Const(FLOAT, L0, 1.0))
    assert validate_program([_f("g", [], FLOAT, [ir.Return(L0, e)])]) == []


@pytest.mark.toolchain
def test_build_validate_ir_passes_the_example_and_reports_a_violation(tmp_path, monkeypatch, capsys):
    """`build --validate-ir` checks the example's programs (clean: exit 0); a program breaking an invariant
    (one injected into the validator's input) is an internal error, exit 1, and nothing is written."""
    from generator.cli import main
    import generator.link.checked as checked

    scene = str(REPO / "scenes" / "example.toml")
    assert main(["build", scene, "--out", str(tmp_path / "a"), "--validate-ir", "--no-cache", "-q",
                 "--platform", "webgpu"]) == 0
    real = checked.validate_program

    def broken(functions, globals_=()):
        fns = copy.deepcopy(functions)
        fns.append(copy.deepcopy(fns[-1]))  # a function linked twice
        return real(fns, globals_)
    monkeypatch.setattr(checked, "validate_program", broken)
    assert main(["build", scene, "--out", str(tmp_path / "b"), "--validate-ir", "--no-cache", "-q"]) == 1
    err = capsys.readouterr().err
    assert "internal error:" in err and "defined twice" in err
    assert not (tmp_path / "b").exists()
