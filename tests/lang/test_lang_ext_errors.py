"""Misuse of switches, runtime loops, arrays, buffers and cube textures: path:line:col, what, what to do."""
import pytest

from generator.lang import SourceError, parse_module

HEAD = '"""A test brick."""\nBRICK = {"kind": "specular"}\n\n'
LIGHT = "class Light:\n    color: vec4\n"  # lines 4-5
BUF = LIGHT + "lights: storage_buffer[Light]\n"  # line 6

CASES = [
    # (source after the header, line, col, words the message must contain)
    ("def f(x: float) -> float:\n    match x:\n        case 1:\n            return 1.0\n    return x\n",
     5, 11, "match selects on an int or uint, not float"),
    ("def f(k: int) -> float:\n    match k:\n        case 1:\n            return 1.0\n        case 2 | 1:\n"
     "            return 2.0\n    return 0.0\n", 8, 18, "case value 1 appears twice (first on line 6)"),
    ("def f(k: int) -> float:\n    match k:\n        case 1 if k > 0:\n            return 1.0\n    return 0.0\n",
     6, 19, "case guards"),
    ("def f(k: int) -> float:\n    match k:\n        case 1.5:\n            return 1.0\n    return 0.0\n",
     6, 14, "'1.5' is not a case value"),
    ("POINT = 1\ndef f(k: int) -> float:\n    match k:\n        case POINT:\n            return 1.0\n    return 0.0\n",
     7, 14, "would bind a new name"),
    ("def f(k: uint) -> float:\n    match k:\n        case -1:\n            return 1.0\n    return 0.0\n",
     6, 14, "case value -1 is outside the range of uint"),
    ("def f(k: int) -> float:\n    match k:\n        case 1 | _:\n            return 1.0\n    return 0.0\n",
     6, 18, "`_` inside an alternative"),
    ("def f(k: int) -> float:\n    match k:\n        case 1:\n            return 1.0\n", 4, 1, "can reach its end"),
    ("def f(a: array[float, n]) -> float:\n    return a[0]\n", 4, 23, "array size 'n' is not a constant"),
    ("def f(a: array[float, 0]) -> float:\n    return 1.0\n", 4, 23, "array size 0 is not positive"),
    ("def f(a: array[array[float, 2], 2]) -> float:\n    return 1.0\n", 4, 16, "arrays of array[float, 2]"),
    ("def f(a: array[float]) -> float:\n    return 1.0\n", 4, 10, "array takes 2 arguments"),
    ("def f(x: float) -> array[float, 2]:\n    return x\n", 4, 20, "returns an array"),
    ("def f(x: float) -> float:\n    a: array[float, 3] = [x, x]\n    return a[0]\n", 5, 26, "needs 3 elements, got 2"),
    ("def f(x: float) -> float:\n    a: array[float, 2] = [x, 1]\n    return a[0]\n", 5, 30,
     "element is int, the array holds float"),
    ("def f(x: float) -> float:\n    a: array[float, 2] = [x, x]\n    a = [x, 1.0]\n    return a[0]\n", 6, 9,
     "an array literal only initializes a declaration"),
    ("def f(a: array[float, 3]) -> float:\n    return a[3]\n", 5, 14, "index 3 is out of range for array[float, 3]"),
    ("def f(a: array[float, 3], x: float) -> float:\n    return a[x]\n", 5, 14, "index must be int or uint, got float"),
    ("def f(n: int) -> float:\n    acc = 0.0\n    for i in range(n):\n        n -= 1\n    return acc\n", 6, 20,
     "the loop body assigns 'n', which the bound reads"),
    ("def f(x: bool) -> float:\n    acc = 0.0\n    for i in range(x):\n        acc += 1.0\n    return acc\n", 6, 20,
     "the loop bound is bool"),
    ("def f(n: int) -> float:\n    acc = 0.0\n    for i in range(n):\n        i = 2\n    return acc\n", 7, 9,
     "cannot assign to loopvar 'i'"),
    (BUF + "def f(x: float) -> float:\n    lights[0].color = vec4(x)\n    return x\n", 8, 5,
     "buffer 'lights' is read-only"),
    (BUF + "def f(x: float) -> float:\n    b = lights\n    return x\n", 8, 5, "buffers cannot be stored in locals"),
    (BUF + "def f(x: float) -> float:\n    return lights.color.x\n", 8, 12, "has no attribute 'color'"),
    (BUF + "def lights(x: float) -> float:\n    return x\n", 7, 1, "has the name of a buffer"),
    (BUF + "def f(lights: float) -> float:\n    return lights\n", 7, 7, "shadows a function, type, intrinsic, constant or buffer"),
    (LIGHT + "def f(b: storage_buffer[Light]) -> float:\n    return 1.0\n", 6, 10,
     "a storage_buffer is a global resource"),
    (LIGHT + "class S:\n    b: uniform_buffer[Light, 2]\n", 7, 8, "a uniform_buffer is a global resource"),
    ("class Bad:\n    color: vec4\n    k: float\nlights: storage_buffer[Bad]\n", 7, 24,
     "buffer member Bad.k is float, not one of vec4, ivec4, uvec4"),
    ("lights: storage_buffer[vec4]\n", 4, 24, "a buffer holds structs, not vec4"),
    (LIGHT + "table: uniform_buffer[Light, K]\n", 6, 30, "uniform_buffer size 'K' is not a constant"),
    ("t: texture2d\n", 4, 1, "declares nothing"),
    ("def f(x: float) -> uint:\n    return buffer_length(x)\n", 5, 12, "buffer_length(float) is not defined"),
    ("def f(t: texturecube, uv: vec2) -> vec4:\n    return sample(t, uv)\n", 5, 12,
     "sample(texturecube, vec2) is not defined"),
    ("def f(t: texture2d, d: vec3) -> vec4:\n    return sample_level(t, d, 0.0)\n", 5, 12,
     "sample_level(texture2d, vec3, float) is not defined"),
]


@pytest.mark.parametrize("body,line,col,words", CASES, ids=[c[3] for c in CASES])
def test_rejected_with_location_and_hint(body, line, col, words):
    with pytest.raises(SourceError) as e:
        parse_module(HEAD + body, "bricks/test.py")
    err = e.value
    assert (err.path, err.line, err.col) == ("bricks/test.py", line, col), str(err)
    assert words in str(err)
    assert err.hint, "every language error says what to do instead"
    assert str(err).startswith(f"bricks/test.py:{line}:{col}: ")
    assert " — " in str(err)


def test_valid_new_constructs_type_check():
    m = parse_module(HEAD + BUF + "N = 2\nclass Pair:\n    a: array[vec4, N]\n"
                     "table: uniform_buffer[Pair, 3]\n"
                     "def f(k: uint, x: float) -> vec4:\n"
                     "    acc = vec4(0.0)\n"
                     "    for i in range(buffer_length(lights)):\n"
                     "        acc += lights[i].color\n"
                     "    match k:\n        case 0 | 4294967295:\n            acc += table[k].a[1]\n"
                     "        case _:\n            pass\n"
                     "    return acc * x\n", "b.py")
    assert set(m.globals) == {"lights", "table"}
    assert m.structs["Pair"].field("a").size == 2
