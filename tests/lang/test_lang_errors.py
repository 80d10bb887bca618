"""The brick language rejects everything outside its subset with path:line:col and a hint."""
import pytest

from generator.lang import SourceError, parse_module

HEAD = '"""A test brick."""\nBRICK = {"kind": "specular"}\n\n'


def brick(body: str) -> str:
    return HEAD + body


CASES = [
    # (source after the header, line, col, words the message must contain)
    ("def f(x: float) -> float:\n    return 2 * x\n", 5, 12, "no implicit conversions"),
    ("def f(x: float) -> float:\n    y = [x]\n    return x\n", 5, 9, "lists are not allowed"),
    ("def f(x: float) -> float:\n    while x > 0.0:\n        x -= 1.0\n    return x\n", 5, 5, "'While' is not allowed"),
    ("def f(x: float) -> float:\n    return x ** 2.0\n", 5, 12, "use pow"),
    ("def f(x: float) -> float:\n    return foo(x)\n", 5, 12, "unknown function 'foo'"),
    ("def f(x: float) -> float:\n    if x > 0.0:\n        return x\n", 4, 1, "can reach its end"),
    ("def f(x) -> float:\n    return 1.0\n", 4, 7, "has no type"),
    ("def f(x: float) -> vec3:\n    return x\n", 5, 12, "returns float"),
    ("import os\n", 4, 1, "imports are not allowed"),
    ("def f(x: float) -> float:\n    return f(x)\n", 4, 1, "recursion"),
    ("def f(v: vec3) -> vec3:\n    v.xy = vec2(1.0)\n    return v\n", 5, 5, "multi-component swizzle"),
    ("def f(v: vec3) -> float:\n    return v.q\n", 5, 12, "not a swizzle"),
    ("def f(v: vec3) -> float:\n    return v.w\n", 5, 12, "reads past"),
    ("def f(x: float) -> float:\n    for i in range(x):\n        x += 1.0\n    return x\n", 5, 20, "non-negative int constant"),
    ("def f(x: float) -> float:\n    return dot(x, x)\n", 5, 12, "dot(float, float) is not defined"),
    ("def f(x: float) -> float:\n    return x if x > 0 else 0.0\n", 5, 17, "cannot compare float with int"),
    ("def f(__x: float) -> float:\n    return 1.0\n", 4, 7, "reserved for the generator"),
    ("def f(x: float) -> float:\n    return clamp(x, 0.0)\n", 5, 12, "clamp takes 3 arguments"),
    ("def f(x: float) -> float:\n    x\n    return x\n", 5, 5, "does nothing"),
    ("x = 3\n", 4, 1, "not a constant"),
    ("def f(x: float) -> float:\n    return x +\n", 5, 15, "syntax error"),
    # identifiers: ASCII, at most 64 characters (a 1,023-character name failed in glslang, past its 1,024 with the prefix)
    ("class " + "S" * 1023 + ":\n    a: float\n", 4, 1, "is 1023 characters long, more than the 64 allowed"),
    ("def " + "f" * 65 + "(x: float) -> float:\n    return x\n", 4, 1, "is 65 characters long"),
    ("def f(" + "x" * 100 + ": float) -> float:\n    return 1.0\n", 4, 7, "is 100 characters long"),
    ("def f(x: float) -> float:\n    " + "y" * 200 + " = x\n    return x\n", 5, 5, "is 200 characters long"),
    ("class S:\n    " + "a" * 70 + ": float\n", 5, 5, "is 70 characters long"),
    ("def f(x: float) -> float:\n    \u00e9t\u00e9 = x\n    return x\n", 5, 5, "not an ASCII letter, digit or _"),
    # struct names: CamelCase (generated functions hold a '_'), none of the templates' blocks and structs
    ("class lobe_data:\n    a: float\n", 4, 1, "must start with a capital letter and hold no '_'"),
    ("class Material:\n    a: float\n", 4, 1, "is a block or struct name of the generated code"),
    ("class LightData0:\n    a: vec4\n", 4, 1, "is a block or struct name of the generated code"),
]


@pytest.mark.parametrize("body,line,col,words", CASES, ids=[c[3] for c in CASES])
def test_rejected_with_location_and_hint(body, line, col, words):
    with pytest.raises(SourceError) as e:
        parse_module(brick(body), "bricks/test.py")
    err = e.value
    assert (err.path, err.line, err.col) == ("bricks/test.py", line, col), str(err)
    assert words in str(err)
    assert err.hint, "every language error says what to do instead"
    assert str(err).startswith(f"bricks/test.py:{line}:{col}: ")


def test_identifiers_of_64_characters_are_allowed():
    f, x, y, field = "f" * 64, "x" * 64, "y" * 64, "a" * 64
    m = parse_module(brick(f"class {'S' * 64}:\n    {field}: float\n\n\n"
                           f"def {f}({x}: float) -> float:\n    {y} = {x}\n    return {y}\n"), "b.py")
    assert f in m.functions and "S" * 64 in m.structs


def test_metadata_must_be_literal():
    with pytest.raises(SourceError, match="BRICK must be a literal dict"):
        parse_module('"""d"""\nBRICK = dict(kind="x")\n', "b.py")


def test_brick_is_never_executed(tmp_path):
    # A brick whose top level would have side effects if executed: it must be rejected, not run.
    marker = tmp_path / "ran"
    src = f'"""d"""\nBRICK = {{"kind": "diffuse"}}\nopen({str(marker)!r}, "w")\n'
    with pytest.raises(SourceError):
        parse_module(src, "evil.py")
    assert not marker.exists()


def test_valid_constructs_type_check():
    m = parse_module(brick(
        "K = 3\n"
        "class S:\n    a: float\n    b: vec3\n"
        "def g(x: float) -> float:\n    return x * 2.0\n"
        "def f(x: float, v: vec3) -> vec3:\n"
        "    acc = 0.0\n"
        "    for i in range(K):\n        acc += float(i)\n"
        "    s = S(g(x), v)\n"
        "    w = clamp(v, 0.0, 1.0)\n"
        "    return s.b * acc + w.zyx * (x if x > 0.0 else 1.0)\n"), "b.py")
    f = m.functions["f"]
    assert f.calls == ["g"]
    assert str(f.ret) == "vec3"


def test_a_long_call_chain_is_one_error_and_recursion_still_is_named():
    """A 3,000-deep chain of helpers overflowed Python's stack in the recursion check (a traceback); chains are
    limited to MAX_CALL_DEPTH, checked without recursion, and recursion is still named with its cycle. (A brick
    holds at most MAX_STATEMENTS statements now, two per helper here: the longest chain it can hold is tried.)"""
    from generator.lang.parse import MAX_CALL_DEPTH, MAX_STATEMENTS

    def chain(n: int) -> str:
        src = 'BRICK = {"kind": "test"}\n'
        for i in range(n):
            src += f"def f{i}(x: float) -> float:\n    return {f'f{i + 1}(x)' if i < n - 1 else 'x'}\n"
        return src
    parse_module(chain(MAX_CALL_DEPTH), "ok.py")
    with pytest.raises(SourceError, match=rf"long\.py:\d+:1: function 'f\d+' starts a chain of {MAX_CALL_DEPTH + 1} "
                                          rf"nested calls, more than the {MAX_CALL_DEPTH} allowed — "):
        parse_module(chain(MAX_STATEMENTS // 2 - 1), "long.py")
    cyc = 'BRICK = {"kind": "test"}\ndef a(x: float) -> float:\n    return b(x)\n' \
          'def b(x: float) -> float:\n    return a(x)\n'
    with pytest.raises(SourceError, match=r"recursion: a -> b -> a — "):
        parse_module(cyc, "cyc.py")


def test_two_bricks_declaring_one_struct_differently_is_one_error(tmp_path):
    """Both structs reached the shader (a redefinition to every compiler); now it is an error naming both."""
    from generator.compose import compose_eval
    from generator.library.bricks import load_library

    (tmp_path / "dl.py").write_text('"""D."""\nBRICK = {"kind": "diffuse", "cite": "x"}\n\n\nclass Lobe:\n'
                                    '    k: float\n\n\ndef diffuse(NdotL: float) -> vec3:\n'
                                    '    lo = Lobe(NdotL)\n    return vec3(lo.k)\n')
    (tmp_path / "sl.py").write_text('"""S."""\nBRICK = {"kind": "specular", "cite": "x"}\n\n\nclass Lobe:\n'
                                    '    c: vec3\n\n\ndef specular(NdotH: float) -> vec3:\n'
                                    '    lo = Lobe(vec3(NdotH))\n    return lo.c\n')
    lib = load_library([tmp_path])
    compose_eval("dl", lib)  # each alone is fine
    with pytest.raises(SourceError, match=r"sl\.py:5:1: struct 'Lobe' is also declared, differently, by "
                                          r"\S*dl\.py:5, and both bricks are linked into one shader — rename"):
        compose_eval("dl+sl", lib)
