"""The product brick × filler × language, compiled with the real tools.

`make test` compiles a fixed sample (every brick appears at least once); the full product
is the `slow` tier: `.venv/bin/python -m pytest -m slow tests/toolchain/test_sweep.py`.
"""
from __future__ import annotations

import itertools

import pytest

from generator.library.bricks import load_library
from generator.library.kinds import KINDS

LIB = load_library()


def _fillings(brick) -> list[str]:
    """Every canonical spec of `brick` over all fillers of its slots."""
    if not brick.slots:
        return [brick.id]
    options = [[f"{s}={f.id}" for f in LIB.of_kind(spec["kind"])] for s, spec in brick.slots.items()]
    return [f"{brick.id}({','.join(c)})" for c in itertools.product(*options)]


def all_brdfs() -> list[str]:
    diffuse = [s for b in LIB.of_kind("diffuse") for s in _fillings(b)]
    specular = [s for b in LIB.of_kind("specular") for s in _fillings(b)]
    return diffuse + specular + [f"{d}+{s}" for d in diffuse for s in specular]


def sample(items: list[str]) -> list[str]:
    """A deterministic cover: for every BRDF brick and filler, the first spec that names it, plus the last spec."""
    import re

    out = []
    for kind in ("diffuse", "specular") + tuple(k for k, v in KINDS.items() if v.slot):
        for b in LIB.of_kind(kind):
            if not any(re.search(rf"\b{b.id}\b", s) for s in out):
                out.append(next(s for s in items if re.search(rf"\b{b.id}\b", s)))
    return out + [items[-1]]


def _compile(specs: list[str]) -> dict:
    from generator.compose import compose_eval
    from generator.toolchain import CompileJob, compile_many

    jobs = []
    for i, spec in enumerate(specs):
        for src in compose_eval(spec, LIB).sources:
            jobs.append(CompileJob(f"s{i}.comp.{src.language}", src.language, "comp", src.text,
                                   line_map=tuple(src.line_map)))
    return {k: r for k, r in compile_many(jobs).items() if not r.ok}


def test_the_sample_covers_every_brdf_brick_and_filler():
    import re

    specs = sample(all_brdfs())
    assert len(specs) < len(all_brdfs()) / 3
    for kind in ("diffuse", "specular") + tuple(k for k, v in KINDS.items() if v.slot):
        for b in LIB.of_kind(kind):
            # as a whole brick name (phong_normalized is not inside blinn_phong_normalized's cover)
            pattern = rf"(?<![\w]){b.id}(?![\w])" if kind in ("diffuse", "specular") else rf"={b.id}(?![\w])"
            assert any(re.search(pattern, s) for s in specs), f"{kind} {b.id} is in no sampled spec"


@pytest.mark.toolchain
def test_sampled_brdf_eval_kernels_compile_in_every_language():
    assert _compile(sample(all_brdfs())) == {}


@pytest.mark.slow
@pytest.mark.toolchain
def test_every_brdf_eval_kernel_compiles_in_every_language():
    specs = all_brdfs()
    assert len(specs) >= 40
    assert _compile(specs) == {}
