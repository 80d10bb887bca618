"""A seeded fuzz suite over the inputs: mutated copies of the shipped bricks, the example scene and
sample files.

Every case must either load (and, for a BRDF term, compose in every language), or fail with exactly one
located message (`path:line:col: what — what to do`, a SourceError or UserError) — never another exception
(a traceback), and within a time bound. Sample files for `eval` fail with one line naming the file. Builds
of the example scene with one of its bricks replaced by a mutated copy go through the real compilers: exit 0
with every output valid, or exit 1 with every failure located. `make test` runs FUZZ_CASES of each
(FUZZ_BUILDS builds); the `slow` marker runs FUZZ_SLOW (FUZZ_BUILDS_SLOW builds):
`pytest -m slow tests/lang/test_fuzz.py`.
"""
from __future__ import annotations

import random
import re
import time
import warnings
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BRICKS = sorted((REPO / "bricks").rglob("*.py"))
SCENE = (REPO / "scenes" / "example.toml").read_text()
FUZZ_CASES, FUZZ_SLOW = 150, 5000
FUZZ_BUILDS, FUZZ_BUILDS_SLOW = 6, 300  # builds run the real compilers
TIME_BOUND_S = 10.0
LOCATED = re.compile(r"^[^\n]+:\d+:\d+: [^\n]+$")

VALUES = ["[]", "{}", "1", "-1", "0", "1e400", "-1e400", "3000000000", '"x"', '""', "true", "1979-05-27",
          '"' + "a" * 2000 + '"', "[1, [2, [3]]]", '["a", 1]', "{ a = 1 }", '"\\u2028"', "nan", "inf"]
PY_VALUES = ["[]", "{}", "1", "-1", "1e400", "3000000000", '"x"', '""', "True", "None", "(1, 2)", '{"a": 1}',
             '"' + "a" * 2000 + '"', "[1, [2]]", "vec3(1.0)", "x", "1 / 0"]


def _mutate(text: str, rng: random.Random, values) -> str:
    lines = text.split("\n")
    for _ in range(rng.randint(1, 3)):
        op = rng.randrange(8)
        i = rng.randrange(len(lines)) if lines else 0
        if not lines:
            break
        if op == 0:
            del lines[i]
        elif op == 1:
            lines.insert(i, lines[i])
        elif op == 2 and "=" in lines[i]:
            key, _, _ = lines[i].partition("=")
            lines[i] = f"{key}= {rng.choice(values)}"
        elif op == 3 and ":" in lines[i]:
            head, _, _ = lines[i].partition(":")
            lines[i] = f"{head}: {rng.choice(values)},"
        elif op == 4:
            words = re.findall(r"[A-Za-z_]+", lines[i])
            if words:
                w = rng.choice(words)
                lines[i] = lines[i].replace(w, w[:-1] + rng.choice("aeioux_") if len(w) > 1 else w + "x", 1)
        elif op == 5:
            cut = rng.randrange(len(text) + 1)
            return text[:cut]
        elif op == 6:
            j = rng.randrange(len(lines[i]) + 1)
            lines[i] = lines[i][:j] + rng.choice(["(", ")", "[", "]", "{", "}", '"', "'", "\t", "#", "\\", "\x00"]) \
                + lines[i][j:]
        else:
            lines.insert(i, rng.choice(lines))
    return "\n".join(lines)


def _check(fn, path: Path):
    from generator.lang.errors import UserError
    from generator.lang import SourceError

    t = time.perf_counter()
    try:
        fn(path)
    except (SourceError, UserError) as e:
        text = str(e)
        named = text.split(":")[0]  # the file itself (an engine brick: relative to its directory's parent)
        assert LOCATED.match(text) and " — " in text and (named == str(path) or named.endswith(
            f"{path.parent.name}/{path.name}")), text
    assert time.perf_counter() - t < TIME_BOUND_S, f"{path}: took {time.perf_counter() - t:.1f} s"


def _bricks(n: int, seed: int, tmp_path):
    from generator.library.bricks import load_brick
    rng = random.Random(seed)
    for k in range(n):
        src = rng.choice(BRICKS)
        path = tmp_path / f"case{k}" / src.name
        path.parent.mkdir(parents=True)
        if rng.random() < 0.05:
            path.write_bytes(src.read_bytes()[:rng.randrange(200)] + bytes([rng.randrange(128, 256)]))
        else:
            path.write_text(_mutate(src.read_text(), rng, PY_VALUES))
        _check(load_brick, path)


def _scenes(n: int, seed: int, tmp_path):
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene
    lib = load_library()
    rng = random.Random(seed)
    tmp_path.mkdir(parents=True, exist_ok=True)
    for k in range(n):
        path = tmp_path / f"scene{k}.toml"
        if rng.random() < 0.05:
            path.write_bytes(SCENE.encode()[:rng.randrange(300)] + bytes([rng.randrange(128, 256)]))
        else:
            path.write_text(_mutate(SCENE, rng, VALUES))
        _check(lambda p: load_scene(p, lib), path)


def _composed(n: int, seed: int, tmp_path):
    """Mutated BRDF bricks that load are also linked and emitted in every language (compose_eval: no tools)."""
    from generator.compose import compose_eval
    from generator.library.bricks import load_library
    rng = random.Random(seed)
    terms = [p for p in BRICKS if p.parent.name in ("diffuse", "specular")]
    for k in range(n):
        src = rng.choice(terms)
        d = tmp_path / f"lib{k}"
        d.mkdir(parents=True)
        path = d / f"fz{src.stem}.py"  # its own id: no clash with the shipped brick
        path.write_text(_mutate(src.read_text(), rng, PY_VALUES))

        def both(p):
            compose_eval(p.stem, load_library([d]))
        _check(both, path)


def _samples(n: int, seed: int, tmp_path):
    """Mutated sample files for `eval`: flipped and inserted header and data bytes, truncation, other shapes and
    dtypes, non-finite and non-unit rows. load_samples returns the samples or raises one line naming the file."""
    import io as _io

    import numpy as np

    from generator.cli.commands.eval import _BadInput, load_samples
    rng = random.Random(seed)
    gen = np.random.default_rng(seed)
    tmp_path.mkdir(parents=True, exist_ok=True)
    for k in range(n):
        path = tmp_path / f"s{k}.npy"
        rows = int(gen.integers(0, 6))
        cols = rng.choice([9, 9, 12, 3, 10])
        v = gen.normal(size=(rows, cols))
        if cols in (9, 12):
            w = v.reshape(rows, cols // 3, 3)
            v = (w / np.linalg.norm(w, axis=2, keepdims=True)).reshape(rows, cols)
        if rows and rng.random() < 0.3:
            v[rng.randrange(rows), rng.randrange(cols)] = rng.choice([np.nan, np.inf, -np.inf, 1e300, 0.0, 2.0])
        dtype = rng.choice(["<f8", "<f4", "<f2", ">f8", "<i4", "|u1", "<c8"])
        buf = _io.BytesIO()
        with np.errstate(over="ignore", invalid="ignore"):  # 1e300 as float16, NaN as an integer: whatever it gives
            np.save(buf, v.astype(dtype) if dtype[-2] != "c" else v.astype(np.complex64))
        data = bytearray(buf.getvalue())
        for _ in range(rng.randint(0, 3)):
            if not data:  # truncated to nothing: an empty file is a case too
                break
            op, i = rng.randrange(4), rng.randrange(len(data))
            if op == 0:
                data[i] = rng.randrange(256)
            elif op == 1:
                data.insert(i, rng.choice(b"(),:'0123456789 {}Lx\n\x00\xff"))
            elif op == 2:
                del data[i:]
            else:
                data[i:i] = data[:rng.randrange(1, 16)]
        path.write_bytes(bytes(data))
        t = time.perf_counter()
        with warnings.catch_warnings(record=True) as printed:  # nothing besides the message (NumPy's casts warn)
            warnings.simplefilter("always")
            try:
                load_samples(str(path))
            except _BadInput as e:
                text = str(e)
                assert text.startswith(f"{path}: ") and "\n" not in text and " — " in text, text
        assert not printed, [str(w.message) for w in printed]
        assert time.perf_counter() - t < TIME_BOUND_S


def _builds(n: int, seed: int, tmp_path):
    """`shadermatrix build` of the example scene with one of its bricks replaced by a mutated engine copy: exit 0
    with every permutation and the ubershader ok; or exit 1 with one located line (the brick or scene did not
    load) or with every failure located (the scene position that asks for the permutation, then the brick lines). Never a traceback, within a bound.
    The compilers are real: a shared cache keeps the unmutated shaders from being compiled twice."""
    import json
    import subprocess
    import sys

    used = [b for b in BRICKS if re.search(rf"[\"(+=]{b.stem}[\",)+]", SCENE) or f'"{b.stem}"' in SCENE]
    rng = random.Random(seed)
    cache = tmp_path / "cache"
    for k in range(n):
        src = rng.choice(used)
        case = tmp_path / f"b{k}"
        (case / "engine").mkdir(parents=True)
        (case / "engine" / f"fz{src.stem}.py").write_text(_mutate(src.read_text(), rng, PY_VALUES))
        scene = case / "scene.toml"
        scene.write_text(re.sub(rf"(?<=[\"(+=]){src.stem}(?=[\",)+])", f"fz{src.stem}", SCENE))
        t = time.perf_counter()
        r = subprocess.run([sys.executable, "-m", "generator.cli", "build", str(scene), "--out", str(case / "out"),
                            "--bricks", str(case / "engine"), "--cache-dir", str(cache), "-q"],
                           cwd=REPO, capture_output=True, text=True, timeout=120)
        took = time.perf_counter() - t
        what = f"case {k} ({src.name}): exit {r.returncode}\n{r.stderr}"
        assert "Traceback" not in r.stderr and r.returncode in (0, 1), what
        errors = [line for line in r.stderr.splitlines() if line.startswith("error: ")]
        if r.returncode == 0:
            m = json.loads((case / "out" / "manifest.json").read_text())
            assert not errors and all(p["status"] == "ok" for p in m["permutations"]), what
            assert m["ubershader"]["status"] == "ok", what
        elif not (case / "out" / "manifest.json").exists():  # the brick or the scene did not load: one line
            assert len(errors) == 1 and LOCATED.match(errors[0][len("error: "):]), what
            assert r.stderr.strip() == errors[0], what
        else:  # compile failures: each located at the scene, then the brick lines the compilers refused
            assert errors and all(LOCATED.match(e[len("error: "):]) and " — " in e for e in errors), what
            detail = [line for line in r.stderr.splitlines() if line.startswith("  ")]
            # under each failure: the permutation key, then the compilers' messages, each at a brick line
            assert all(line.startswith("  brdf=") or re.match(r"^  [^\n]+:\d+:\d+: ", line) for line in detail), what
        assert took < 60, f"{what}: took {took:.1f} s"


def test_mutated_sample_files_load_or_fail_with_one_message(tmp_path):
    _samples(FUZZ_CASES, 7, tmp_path)


@pytest.mark.toolchain
def test_builds_with_a_mutated_brick_succeed_or_fail_located(tmp_path):
    _builds(FUZZ_BUILDS, 8, tmp_path)


def test_mutated_bricks_load_or_fail_with_one_located_message(tmp_path):
    _bricks(FUZZ_CASES, 1, tmp_path)


def test_mutated_bricks_that_load_compose_or_fail_with_one_located_message(tmp_path):
    _composed(FUZZ_CASES // 3, 5, tmp_path)


def test_mutated_scenes_load_or_fail_with_one_located_message(tmp_path):
    _scenes(FUZZ_CASES, 2, tmp_path)


@pytest.mark.slow
def test_mutated_inputs_at_full_size(tmp_path):
    _bricks(FUZZ_SLOW, 3, tmp_path / "b")
    _scenes(FUZZ_SLOW, 4, tmp_path / "s")
    _composed(FUZZ_SLOW // 5, 6, tmp_path / "c")
    _samples(FUZZ_SLOW, 9, tmp_path / "n")


@pytest.mark.slow
@pytest.mark.toolchain
def test_builds_with_a_mutated_brick_at_full_size(tmp_path):
    _builds(FUZZ_BUILDS_SLOW, 10, tmp_path)
