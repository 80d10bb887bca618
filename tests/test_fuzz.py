"""A seeded fuzz suite over the inputs (issue 10): mutated copies of the shipped bricks and the example scene.

Every case must either load (and, for a BRDF term, compose in every language), or fail with exactly one
located message (`path:line:col: what — what to do`,
a SourceError or UserError) — never another exception (a traceback), and within a time bound. `make test`
runs FUZZ_CASES of each; the `slow` marker runs FUZZ_SLOW (`pytest -m slow tests/test_fuzz.py`).
"""
from __future__ import annotations

import random
import re
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
BRICKS = sorted((REPO / "bricks").rglob("*.py"))
SCENE = (REPO / "scenes" / "example.toml").read_text()
FUZZ_CASES, FUZZ_SLOW = 150, 5000
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
    from generator.matrix.scene import load_scene
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
