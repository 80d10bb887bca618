"""Hostile bricks: text Python cannot parse, and bricks past the loader's bounds on nesting and size, are one
located error when the brick is loaded — on every Python the project supports (Debian 12's 3.11.2 raises
ValueError for a NUL where later 3.11 releases raise SyntaxError) — never a traceback from Python's parser,
the link stage or an emitter, and never a build that runs for minutes. Each case below was a traceback, a
compiler error or a hang before the bound it tests (found by fuzzing mutated bricks)."""
from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from generator.lang import SourceError, ir
from generator.lang.parse import MAX_BRICK_BYTES, MAX_DEPTH, MAX_NODES, MAX_STATEMENTS

REPO = Path(__file__).resolve().parents[2]
HEAD = '"""Hostile."""\nBRICK = {"kind": "diffuse", "cite": "x"}\n\n\n'
LAMBERT = HEAD + "def diffuse(NdotL: float) -> vec3:\n    return vec3(NdotL) * INV_PI\n"
SCENE = """[scene]
name = "hostile"
output = "linear"
precision = "fp32"

[materials.m]
brdf = "BRDF"

[lights.sun]
type = "directional"
params = { direction = [0.3, 0.9, 0.3], color = [3.0, 2.9, 2.7] }

[light_sets]
s = ["sun"]

[[objects]]
name = "o"
material = "m"
lights = "s"
"""


def _load(tmp_path, data, name="hz.py"):
    from generator.library.bricks import load_brick

    path = tmp_path / name
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    return load_brick(path, shown=name)


def _error(tmp_path, data, name="hz.py") -> SourceError:
    with pytest.raises(SourceError) as e:
        _load(tmp_path, data, name)
    assert e.value.hint, str(e.value)
    return e.value


def _cli(*args, timeout=120):
    return subprocess.run([sys.executable, "-m", "generator.cli", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout)


def _build_one_error(tmp_path, brick_text: str | bytes, brdf: str = "hz") -> str:
    """`build` of a scene whose material uses the engine brick hz.py: exit 1 with one located line."""
    engine = tmp_path / "engine"
    engine.mkdir()
    (engine / "hz.py").write_bytes(brick_text if isinstance(brick_text, bytes) else brick_text.encode())
    (tmp_path / "scene.toml").write_text(SCENE.replace("BRDF", brdf))
    r = _cli("build", tmp_path / "scene.toml", "--out", tmp_path / "out", "--bricks", engine, "-q")
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    lines = r.stderr.strip().splitlines()
    # named as the other brick messages name it, or (a file that cannot be read) by the path given
    assert len(lines) == 1 and re.match(r"error: (\S*/)?engine/hz\.py:\d+:\d+: ", lines[0]) and " — " in lines[0], \
        r.stderr
    return lines[0][len("error: "):].split("engine/", 1)[1]


# ---------------------------------------------------------------- text Python cannot parse

NUL_CASES = [  # (id, bytes, line, col): the NUL's own line and column (characters), whatever the line breaks
    ("in-code", LAMBERT.replace("* INV_PI", "*\x00 INV_PI"), 6, 25),
    ("in-docstring", LAMBERT.replace("Hostile.", "Host\x00ile."), 1, 8),
    ("in-comment", LAMBERT + "# a\x00b\n", 7, 4),
    ("first-byte", "\x00" + LAMBERT, 1, 1),
    ("CRLF-lines", LAMBERT.replace("\n", "\r\n").replace("* INV_PI", "*\x00 INV_PI"), 6, 25),
    ("CR-lines", LAMBERT.replace("\n", "\r").replace("* INV_PI", "*\x00 INV_PI"), 6, 25),
    ("after-form-feed", LAMBERT.replace("\n\n\ndef", "\n\f\x00\n\ndef"), 3, 2),
]


@pytest.mark.parametrize("case", NUL_CASES, ids=[c[0] for c in NUL_CASES])
def test_a_nul_is_one_error_at_its_line_and_column(case, tmp_path):
    """3.11.2's ast.parse raised ValueError (a traceback), 3.11.7's a SyntaxError at 1:1: either way not where
    the NUL is. It is found before Python's parser sees the text."""
    _, text, line, col = case
    e = _error(tmp_path, text)
    assert (e.line, e.col) == (line, col) and str(e).startswith(f"hz.py:{line}:{col}: a NUL character — "), str(e)


def test_utf16_text_without_a_byte_order_mark_is_named(tmp_path):
    e = _error(tmp_path, LAMBERT.encode("utf-16-le"))
    assert (e.line, e.col) == (1, 2) and "the file looks UTF-16" in str(e) and "save the brick as UTF-8" in str(e)


UNDECODABLE = [  # (id, bytes, line, col, words)
    ("invalid-byte", LAMBERT.encode().replace(b"* INV_PI", b"* \xc3( INV_PI"), 6, 26, "byte 0xc3 is not UTF-8"),
    ("lone-surrogate", LAMBERT.encode().replace(b"Hostile", b"Host\xed\xa0\x80ile"), 1, 8, "byte 0xed is not UTF-8"),
    # a column counts characters, as editors do: the two bytes of é are one column
    ("after-multibyte", LAMBERT.replace("* INV_PI", "é \udcff").encode("utf-8", "surrogateescape"), 6, 26,
     "byte 0xff is not UTF-8"),
    ("UTF-16-mark", b"\xff\xfe" + LAMBERT.encode("utf-16-le"), 1, 1, "the brick is UTF-16 text"),
    ("UTF-32-mark", b"\xff\xfe\x00\x00" + LAMBERT.encode("utf-32-le"), 1, 1, "the brick is UTF-32 text"),
]


@pytest.mark.parametrize("case", UNDECODABLE, ids=[c[0] for c in UNDECODABLE])
def test_undecodable_bricks_are_one_located_error(case, tmp_path):
    from generator.library.bricks import load_brick

    _, data, line, col, words = case
    path = tmp_path / "hz.py"
    path.write_bytes(data)
    with pytest.raises(SourceError) as e:
        load_brick(path)
    assert (e.value.line, e.value.col) == (line, col) and words in str(e.value), str(e.value)
    assert "save the brick as UTF-8" in str(e.value)


def test_a_utf8_byte_order_mark_is_read_as_python_reads_it(tmp_path):
    """Windows editors write one; it was 'invalid non-printable character U+FEFF' (a brick) and 'Invalid
    statement' (a scene). Dropped, the brick is the same brick: same source hash, so the same outputs."""
    from generator.scene.load import read_toml

    plain, marked = _load(tmp_path, LAMBERT, "a.py"), _load(tmp_path, b"\xef\xbb\xbf" + LAMBERT.encode(), "b.py")
    assert plain.module.source_hash == marked.module.source_hash
    (tmp_path / "s.toml").write_bytes(b"\xef\xbb\xbf" + b'[scene]\nname = "x"\n')
    assert read_toml(tmp_path / "s.toml", "scene", "")[0] == {"scene": {"name": "x"}}


@pytest.mark.parametrize("data,line,col,words", [
    (b'[scene]\nname = "a\x00"\n', 2, 10, "Illegal character"),
    (b'[scene]\nname = "\xc3("\n', 2, 9, "byte 0xc3 is not UTF-8"),
    (b"\xff\xfe" + '[scene]\nname = "a"\n'.encode("utf-16-le"), 1, 1, "the scene is UTF-16 text"),
], ids=["NUL", "invalid-byte", "UTF-16"])
def test_undecodable_scenes_are_one_located_error(data, line, col, words, tmp_path):
    from generator.scene.load import read_toml

    (tmp_path / "s.toml").write_bytes(data)
    with pytest.raises(SourceError) as e:
        read_toml(tmp_path / "s.toml", "scene", "fix the scene")
    assert (e.value.line, e.value.col) == (line, col) and words in str(e.value), str(e.value)


def test_a_nul_in_a_brick_is_one_line_from_the_cli(tmp_path):
    d = tmp_path / "engine"
    d.mkdir()
    (d / "hz.py").write_bytes(NUL_CASES[0][1].encode())
    r = _cli("bricks", "--bricks", d)
    assert r.returncode == 1 and r.stderr.strip() == "error: engine/hz.py:6:25: a NUL character — remove it: a brick " \
        "is UTF-8 text", r.stderr


PARSER_GIVES_UP = [  # (id, body of diffuse, line, words): what Python's own parser cannot take, located
    ("10000-term-sum", "return vec3(" + " + ".join(["NdotL"] * 10000) + ")", 6, "too long or too deeply nested"),
    ("50000-nots", "return vec3(1.0 if " + "not " * 50000 + "NdotL > 0.0 else 0.0)", 6, "too long or too deeply"),
    ("300-parentheses", "return vec3(" + "(" * 300 + "NdotL" + ")" * 300 + ")", 6, "too many nested parentheses"),
    ("120-indents", ("".join("    " * (i + 1) + "if NdotL > 0.0:\n" for i in range(120)) + "    " * 121 + "pass\n"
     "    return vec3(NdotL)")[4:], 105, "too many levels of indentation"),
]


@pytest.mark.parametrize("case", PARSER_GIVES_UP, ids=[c[0] for c in PARSER_GIVES_UP])
def test_what_pythons_parser_cannot_take_is_located(case, tmp_path):
    """ast.parse raises RecursionError ("during ast construction"), MemoryError (parser stack overflow) or a
    SyntaxError of its own limits: each is one error at the line the parser gave up on."""
    _, body, line, words = case
    e = _error(tmp_path, HEAD + "def diffuse(NdotL: float) -> vec3:\n    " + body + "\n")
    assert e.line == line and words in str(e), str(e)


# ---------------------------------------------------------------- nesting

def test_a_chain_of_5000_ands_is_refused_when_loaded_not_a_recursion_error_in_build(tmp_path):
    """One BoolOp in Python's tree, 4,999 nested binary operations in the IR: `build` died with RecursionError
    in ir.clone. A chain of n operands counts n - 1 levels; the error is at the chain's start."""
    cond = " and ".join(["NdotL > 0.0"] * 5000)
    text = HEAD + f"def diffuse(NdotL: float) -> vec3:\n    x = 1.0 if {cond} else 0.0\n    return vec3(x)\n"
    line = _build_one_error(tmp_path, text)
    assert line.startswith(f"hz.py:6:16: this expression or statement is nested more than {MAX_DEPTH} deep"), \
        line
    ok = " and ".join(["NdotL > 0.0"] * (MAX_DEPTH - 6))
    _load(tmp_path, HEAD + f"def diffuse(NdotL: float) -> vec3:\n    x = 1.0 if {ok} else 0.0\n    return vec3(x)\n")


def _deepest(shape) -> int:
    """The deepest nesting of `shape` the loader accepts."""
    n = 1
    while True:
        try:
            ast_text = HEAD + "def f(x: float) -> float:\n" + shape(n + 1)
            from generator.lang import parse_module
            parse_module(ast_text, "t.py")
        except SourceError as e:
            assert "nested more than" in str(e), str(e)
            return n
        n += 1
        assert n <= 2 * MAX_DEPTH, f"nested {n} deep, and the loader still accepts it"


# Each shape nested as deep as the loader allows. `splat` is the deepest IR per syntax level (a scalar
# argument of max() beside a vector is wrapped in a vec3 constructor): 1.5 IR levels per level of syntax.
SHAPES = {
    "sum": lambda n: "    return " + " + ".join(["x"] * n) + "\n",
    "calls": lambda n: "    return " + "max(" * n + "x" + ", 0.5)" * n + "\n",
    "negations": lambda n: "    return " + "-" * n + "x\n",
    "conditionals": lambda n: "    return " + "x if x > 0.5 else " * n + "x\n",
    "ands": lambda n: "    return 1.0 if " + " and ".join(["x > 0.0"] * n) + " else 0.0\n",
    "swizzles": lambda n: "    v = vec3(x)\n    return v" + ".zyx" * n + ".x\n",
    "ifs": lambda n: "".join("    " * (i + 1) + "if x > 0.5:\n" for i in range(n)) + "    " * (n + 1)
    + "x = x * 0.5\n    return x\n",
    "splat": lambda n: "    v = vec3(0.5)\n    return " + "dot(max(" * n + "x" + ", v), v)" * n + "\n",
}


def _deepest_brick() -> str:
    fns = {f"{name}_{_deepest(shape)}": shape for name, shape in SHAPES.items()}
    defs = [f"def {name}(x: float) -> float:\n" + shape(int(name.rsplit("_", 1)[1])) for name, shape in fns.items()]
    calls = " + ".join(f"{name}(NdotL)" for name in fns)
    return HEAD + "\n\n".join(defs) + f"\n\ndef diffuse(NdotL: float) -> vec3:\n    return vec3({calls})\n"


def test_a_brick_at_the_depth_bound_composes_in_every_language_with_stack_to_spare(tmp_path):
    """The bound protects every recursive walk after the loader (the link stage, the GLSL/HLSL/WGSL emitters):
    the deepest brick it accepts composes in every language even with Python's recursion limit at 850 of its
    1,000 (measured: the splat shape needs about 640 frames, the others 500 or fewer)."""
    from generator.compose import compose_eval
    from generator.library.bricks import load_library

    d = tmp_path / "engine"
    d.mkdir()
    (d / "hz.py").write_text(_deepest_brick())
    lib = load_library([d])
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(850)
    try:
        composed = compose_eval("hz", lib)
    finally:
        sys.setrecursionlimit(limit)
    assert len(composed.sources) == 3


def test_a_brick_at_the_depth_bound_evaluates_in_numpy(tmp_path):
    import numpy as np

    d = tmp_path / "engine"
    d.mkdir()
    (d / "hz.py").write_text(_deepest_brick())
    rng = np.random.default_rng(1)
    v = np.abs(rng.normal(size=(16, 3, 3)))
    v /= np.linalg.norm(v, axis=2, keepdims=True)
    v[:, 2] = [0.0, 0.0, 1.0]
    np.save(tmp_path / "s.npy", v.reshape(16, 9))
    r = _cli("eval", "hz", "--input", tmp_path / "s.npy", "--out", tmp_path / "f.npy", "--target", "numpy",
             "--bricks", d)
    assert r.returncode == 0, r.stderr
    assert np.isfinite(np.load(tmp_path / "f.npy")).all()


def _size_bound_brick() -> str:
    """MAX_STATEMENTS statements (the docstring, BRICK and the def among them), under MAX_NODES nodes."""
    n = MAX_STATEMENTS - 4
    body = "    x0 = vec3(NdotL)\n" + "".join(f"    x{i} = x{i - 1} * 0.999 + vec3(NdotL * {i % 7}.0e-6)\n"
                                              for i in range(1, n))
    return HEAD + f"def diffuse(NdotL: float) -> vec3:\n{body}    return x{n - 1}\n"


@pytest.mark.toolchain
def test_bricks_at_the_bounds_build_with_the_real_compilers(tmp_path):
    """The deepest brick the loader accepts, and one at the statement bound, build for every platform: the
    compilers (glslang, naga, spirv-val) take them too. About 6 s each on this project's machines."""
    tree = ast.parse(_size_bound_brick())
    assert sum(isinstance(n, ast.stmt) for n in ast.walk(tree)) == MAX_STATEMENTS
    assert sum(1 for _ in ast.walk(tree)) <= MAX_NODES
    engine = tmp_path / "engine"
    engine.mkdir()
    (engine / "deep.py").write_text(_deepest_brick().replace('"""Hostile."""', '"""Deep."""'))
    (engine / "long.py").write_text(_size_bound_brick())
    scene = SCENE.replace("BRDF", "deep") + SCENE[SCENE.index("[materials.m]"):SCENE.index("[lights.sun]")] \
        .replace("materials.m", "materials.n").replace("BRDF", "long") + '\n[[objects]]\nname = "p"\nmaterial = ' \
        '"n"\nlights = "s"\n'
    (tmp_path / "scene.toml").write_text(scene)
    r = _cli("build", tmp_path / "scene.toml", "--out", tmp_path / "out", "--bricks", engine, "-q", timeout=300)
    assert r.returncode == 0, r.stderr
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert len(manifest["permutations"]) == 2 and all(p["status"] == "ok" for p in manifest["permutations"])


# ---------------------------------------------------------------- size

def test_a_brick_past_the_statement_bound_is_refused_at_the_first_statement_past_it(tmp_path):
    body = "".join(f"    x{i} = NdotL\n" for i in range(MAX_STATEMENTS))
    e = _error(tmp_path, HEAD + f"def diffuse(NdotL: float) -> vec3:\n{body}    return vec3(NdotL)\n")
    # statements are counted in the order the check walks them: the error is at one of the function's lines
    assert 6 <= e.line <= 6 + MAX_STATEMENTS and f"more than {MAX_STATEMENTS} statements" in str(e), str(e)


def test_a_brick_past_the_node_bound_is_refused(tmp_path):
    e = _error(tmp_path, HEAD + "def diffuse(NdotL: float) -> vec3:\n    return vec3(" + ", ".join(
        ["NdotL"] * MAX_NODES) + ")\n")
    assert e.line == 6 and f"more than {MAX_NODES} syntax nodes" in str(e), str(e)


def test_a_brick_of_100000_statements_fails_in_seconds_not_minutes(tmp_path):
    """It kept `build` busy past 60 s (the compilers on a 100,000-statement shader). The file is past the brick
    size bound, refused before Python parses it; at the size bound, the statement bound refuses it."""
    body = "".join(f"    x{i} = NdotL * {i}.0\n" for i in range(100_000))
    text = HEAD + f"def diffuse(NdotL: float) -> vec3:\n{body}    return vec3(NdotL)\n"
    t = time.perf_counter()
    line = _build_one_error(tmp_path, text)
    assert line.startswith("hz.py:1:1: the brick is") and f"more than the {MAX_BRICK_BYTES} allowed" in line
    assert time.perf_counter() - t < 120  # a hang bound: it ran for minutes before
    dense = HEAD + "def diffuse(NdotL: float) -> vec3:\n" + "    x = NdotL\n" * ((MAX_BRICK_BYTES - 200) // 14) \
        + "    return vec3(x)\n"
    assert len(dense) <= MAX_BRICK_BYTES
    t = time.perf_counter()
    assert f"more than {MAX_STATEMENTS} statements" in str(_error(tmp_path, dense))
    assert time.perf_counter() - t < 120  # a hang bound


def test_the_bounds_are_far_above_every_real_brick():
    """The bounds' comments and messages say they are far above any real brick: the shipped and test bricks
    stay under a quarter of each (a sixteenth of the byte bound)."""
    def depth(tree):
        best, stack = 0, [(tree, 0)]
        while stack:
            node, d = stack.pop()
            best = max(best, d)
            step = d + 1 + (len(node.values) - 1 if isinstance(node, ast.BoolOp) else 0)
            stack.extend((c, step) for c in ast.iter_child_nodes(node))
        return best
    paths = sorted((REPO / "bricks").rglob("*.py")) + sorted(REPO.glob("tests/*bricks/**/*.py"))
    assert len(paths) > 80
    for p in paths:
        text = p.read_text()
        tree = ast.parse(text)
        assert depth(tree) <= MAX_DEPTH // 4, p
        assert sum(isinstance(n, ast.stmt) for n in ast.walk(tree)) <= MAX_STATEMENTS // 4, p
        assert sum(1 for _ in ast.walk(tree)) <= MAX_NODES // 4, p
        assert len(text.encode()) <= MAX_BRICK_BYTES // 16, p


# ---------------------------------------------------------------- names

COLLISIONS = [  # (id, BRICK metadata, function, line, col, words)
    ("param-L", '{"kind": "diffuse", "cite": "x", "params": {"L": {"type": "vec3", "default": [0.5, 0.5, 0.5]}}}',
     "def diffuse(L: vec3) -> vec3:\n    return L\n", 2, 53, "parameter 'L' is named like one of the shading inputs"),
    ("ndf-param-NdotV", '{"kind": "ndf", "cite": "x", "params": {"NdotV": {"type": "float", "default": 0.5}}}',
     "def ndf(NdotH: float, NdotV: float) -> float:\n    return NdotH * NdotV\n", 2, 49, "parameter 'NdotV'"),
    ("glue-intermediate", '{"kind": "diffuse", "cite": "x", "params": {"Hsum": {"type": "vec3", "default": [0.5, 0.5, '
     '0.5]}}}', "def diffuse(Hsum: vec3) -> vec3:\n    return Hsum\n", 2, 53, "parameter 'Hsum'"),
    ("texture-N", '{"kind": "diffuse", "cite": "x", "textures": {"N": {"srgb": False}}}',
     "def diffuse(N: texture2d, NdotL: float) -> vec3:\n    return sample(N, vec2(NdotL)).xyz\n", 2, 55,
     "texture 'N' is named like one of the shading inputs"),
    ("light-param-P", '{"kind": "light", "cite": "x", "params": {"P": {"type": "vec3", "default": [0.0, 1.0, 0.0]}}}',
     "def light_dir(P: vec3) -> vec3:\n    return normalize(P)\n\n\ndef light_radiance(P: vec3) -> vec3:\n"
     "    return P\n", 2, 51, "parameter 'P' is named like one of the surface inputs"),
]


@pytest.mark.parametrize("case", COLLISIONS, ids=[c[0] for c in COLLISIONS])
def test_a_parameter_or_texture_named_like_an_input_is_refused_at_its_key(case, tmp_path):
    """Entries bind parameters by name: `L` as a material parameter was a redefinition in every compiler, a
    texture `N` an AssertionError in link/irgen.py. Refused when loaded, at the key, naming the table."""
    _, meta, fn, line, col, words = case
    e = _error(tmp_path, f'"""Hostile."""\nBRICK = {meta}\n\n\n{fn}')
    assert (e.line, e.col) == (line, col) and words in str(e), str(e)
    assert "generator/library/inputs.py" in str(e) and "rename the" in e.hint, str(e)


def test_a_parameter_named_L_is_one_line_from_build_not_a_compiler_error(tmp_path):
    meta = '{"kind": "diffuse", "cite": "x", "params": {"L": {"type": "vec3", "default": [0.5, 0.5, 0.5]}}}'
    line = _build_one_error(tmp_path, f'"""Hostile."""\nBRICK = {meta}\n\n\ndef diffuse(L: vec3) -> vec3:\n'
                                      "    return L * INV_PI\n")
    assert line.startswith("hz.py:2:53: parameter 'L' is named like one of the shading inputs"), line


# ---------------------------------------------------------------- walks over IR of any depth

def test_clone_and_walk_take_a_tree_of_any_depth():
    """ir.clone and ir.walk use explicit stacks: a 100,000-deep tree (glue-built IR has no loader bound) is
    copied and walked, the copy equal and made of new nodes, tuples (a switch's cases) kept tuples."""
    from generator.lang.types import FLOAT, INT

    loc = ir.Loc("t.py", 1, 1)
    e = ir.Const(FLOAT, loc, 1.0)
    for _ in range(100_000):
        e = ir.Unary(FLOAT, loc, "-", e)
    copy = ir.clone(e)  # (== on dataclasses recurses: compared node by node)
    pairs = list(zip(ir.walk(copy), ir.walk(e), strict=True))
    assert len(pairs) == 100_001 and all(a is not b and type(a) is type(b) for a, b in pairs)
    assert pairs[-1][0].value == 1.0 and pairs[0][0].op == "-"
    sw = ir.Switch(loc, ir.Const(INT, loc, 0), [((0, 1), [ir.Return(loc, e)])], [ir.Return(loc, copy)])
    c = ir.clone(sw)
    assert c.cases[0][0] == (0, 1) and type(c.cases[0]) is tuple and type(c.cases[0][0]) is tuple
    assert c.cases[0][1][0] is not sw.cases[0][1][0] and c.cases[0][1][0].value is not e
    assert [type(n) for n in ir.walk(sw)][:4] == [ir.Switch, ir.Const, ir.Return, ir.Unary]  # pre-order
