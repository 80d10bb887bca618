"""A permutation's way from its key to shader text moves forward through the stages and enters each once.

The trace (sys.setprofile) records every Python call into generator/ while one example permutation
(the cobblestone material under the outdoor lights: two lights, a shadow map, a normal map, textures)
is resolved (spec), linked (link), emitted and composed (backends, compose), and checks that the
sequence of stages never goes back to one it has left, in tests/project/test_layout.py's ORDER.

What is counted, and why:
- a call of a function or method defined in generator/<stage>/ counts as entering that stage;
- lang/, io.py and library/ are below every stage (the brick language's types, errors and IR helpers,
  atomic file I/O, the bricks every stage reads): calls into them are not counted, nor calls into
  spec/where.py, the positions errors point at and the `within` wrapper that applies them, which the
  later stages use as they use lang/errors.py;
- a method or property of a dataclass value (Permutation.canonical, Node.walk, Interface.block) reads a
  value a stage handed on, where the value's class is defined: it does not enter that stage. Module-level
  functions (spec_params, parse_spec, resolve, flat) and methods of the classes that do a stage's work
  (the emitters, the glue's builder and binder) count;
- the back ends and compose are one step, "emit": compose renders each language's templates, which call
  their back end's spelling helpers (target.header, target.ident) while they run.
Measured with these rules on the main before resolve() was computed once, composing from the key
(compose_permutation(perm, lib)): 15 files entered 925 times (mostly the emitters), the stages
emit → link → spec → link → … → emit with 15 steps back (link asked spec 15 times: spec_params 10 calls,
flat 9, parse_spec 4, check_packing). Now: resolve → link → compose is spec → link → emit, none back;
composing from the key still goes emit → link → spec → link → emit, 2 steps back (the second test).
"""
from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import pytest

from .test_layout import ORDER

REPO = Path(__file__).resolve().parents[2]
GENERATOR = str(REPO / "generator") + "/"
BELOW = {"lang", "io", "library"}  # below every stage: not counted
BELOW_FILES = {"spec/where.py"}  # error positions, used by every later stage
EMIT = {"backends": "emit", "compose": "emit"}  # one step (module docstring)


def _stage(path: str) -> str:
    part = path[len(GENERATOR):].split("/")[0]
    return part[:-3] if part.endswith(".py") else part


def _reads_a_value(frame) -> bool:
    """Whether the frame runs a method of a dataclass (a handed-on value's accessor)."""
    qual = frame.f_code.co_qualname.split(".")
    if len(qual) < 2 or qual[1] == "<locals>":
        return False
    cls = frame.f_globals.get(qual[0])
    return isinstance(cls, type) and dataclasses.is_dataclass(cls)


def trace(fn):
    """(stage, file, function) of every counted call while fn() runs, in order; and fn's result."""
    calls = []

    def profile(frame, event, arg):
        if event != "call":
            return
        path = frame.f_code.co_filename
        if not path.startswith(GENERATOR):
            return
        stage = _stage(path)
        if stage in BELOW or path[len(GENERATOR):] in BELOW_FILES or _reads_a_value(frame):
            return
        calls.append((EMIT.get(stage, stage), path[len(GENERATOR):], frame.f_code.co_qualname))

    sys.setprofile(profile)
    try:
        out = fn()
    finally:
        sys.setprofile(None)
    return calls, out


def entries(calls) -> list:
    """Consecutive calls in one stage collapsed: the stages entered, in order, with the first call of each."""
    out = []
    for stage, path, name in calls:
        if not out or out[-1][0] != stage:
            out.append((stage, path, name))
    return out


def steps_back(seq) -> list:
    """(from, to) per step to a stage earlier in the layout than the one before it (emit sits at compose)."""
    rank = {s: ORDER.index(s) for s in ORDER} | {"emit": ORDER.index("compose")}
    return [(a, b) for a, b in zip(seq, seq[1:]) if rank[b[0]] < rank[a[0]]]


@pytest.fixture(scope="module")
def example():
    from generator.library.bricks import load_library
    from generator.scene.load import load_scene

    lib = load_library()
    scene = load_scene(REPO / "scenes" / "example.toml", lib)
    h = next(o["permutation"] for o in scene.objects if o["material"] == "cobblestone")
    return lib, scene.permutations[h]


def test_one_permutation_moves_forward_through_the_stages(example):
    from generator.compose import compose_permutation
    from generator.link import link_permutation
    from generator.spec.resolve import resolve

    lib, perm = example
    calls, composed = trace(lambda: compose_permutation(link_permutation(resolve(perm, lib), lib), lib))
    seq = entries(calls)
    assert [s for s, _, _ in seq] == ["spec", "link", "emit"], seq
    assert not steps_back(seq)
    assert composed.hash == perm.hash and len(composed.sources) == 6  # it did compose, in every language
    # the parameter policy and the spec parser run inside the spec step only
    assert {s for s, _, name in calls if name in ("spec_params", "parse_spec", "_merge")} == {"spec"}


def test_the_trace_sees_a_step_back(example):
    """The rule can fail: composing from the key (compose asks link, which asks spec) is two steps back."""
    from generator.compose import compose_permutation

    lib, perm = example
    from dataclasses import replace
    fresh = replace(perm, output=perm.output)  # an equal key: resolved from the library's memo, linked again
    calls, _ = trace(lambda: compose_permutation(fresh, lib))
    seq = entries(calls)
    assert [s for s, _, _ in seq][:3] == ["emit", "link", "spec"], seq
    assert len(steps_back(seq)) == 2, seq
