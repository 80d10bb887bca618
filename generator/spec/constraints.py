"""The constraints a permutation's bricks must satisfy, as data: one Constraint per rule.

Each rule is a predicate over a permutation's resolved bricks that returns
(what is wrong, what to do), ('', '') when it holds. Scene loading refuses a
material that breaks one (resolve.check_packing: the first broken rule, located
at the material's packing; spec/resolve.py keeps every broken rule as the permutation's verdict); `shadermatrix matrix --explain` lists every combination
of a scene's axes that breaks one, and why. tests/scene/test_explain.py holds the truth
table: which permutations must and must not exist.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Constraint:
    name: str
    doc: str
    problem: Callable  # (Resolved) -> (what is wrong, what to do); ('', '') when the rule holds


def _brdf_text(r) -> str:
    return r.brdf_key


def _provides_unread(r) -> tuple[str, str]:
    params = r.brdf_params
    for f in r.packing.brick.entries:
        name = f.name[len("get_"):]
        if name not in params:
            return (f"packing '{r.packing.brick.id}' provides {name}, which BRDF '{_brdf_text(r)}' does not read",
                    "use a packing that provides only what this BRDF reads: constants, or f0_roughness_texture "
                    "for a textured specular-only microfacet BRDF (`shadermatrix bricks` lists each packing's "
                    "inputs)")
    return "", ""


def _provides_wrong_type(r) -> tuple[str, str]:
    params = r.brdf_params
    for f in r.packing.brick.entries:
        name = f.name[len("get_"):]
        if name in params and f.ret != params[name].ty:
            return (f"packing '{r.packing.brick.id}' provides {name} as {f.ret} ({r.packing.brick.display_path}:"
                    f"{f.loc.line}), but BRDF '{_brdf_text(r)}' reads {name} as {params[name].ty}",
                    f"make get_{name} return {params[name].ty}")
    return "", ""


def supplies_tangent(packing) -> bool:
    """Whether a packing's bricks (its normal filler's) read the vertex tangent T/B."""
    return any(p.name in ("T", "B") for x in packing.walk() for f in x.brick.entries for p in f.params)


def _tangent_frame(r) -> tuple[str, str]:
    tangent, frame = r.tangent, r.packing_tangent
    if tangent and not frame:
        return (f"BRDF '{_brdf_text(r)}' reads {', '.join(tangent)} (the tangent frame), but packing "
                f"'{r.packing.canonical()}' supplies no tangent",
                f"fill its normal slot with vertex_tangent or normal_map, e.g. {r.packing.brick.id}(normal=vertex_tangent)")
    return "", ""


CONSTRAINTS: tuple[Constraint, ...] = (
    Constraint("packing-provides-unread", "a packing may provide only parameters the BRDF reads", _provides_unread),
    Constraint("packing-type", "a packing provides a parameter with the type the BRDF reads it as",
               _provides_wrong_type),
    Constraint("tangent-frame", "a BRDF reading the tangent frame needs a packing whose normal filler reads T/B "
               "(vertex_tangent, normal_map)", _tangent_frame),
)


def first_problem(r) -> tuple[str, str]:
    """(what is wrong, what to do) of the first constraint a resolved permutation breaks; ('', '') if none."""
    for c in CONSTRAINTS:
        problem = c.problem(r)
        if problem[0]:
            return problem
    return "", ""
