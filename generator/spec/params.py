"""The one parameter policy: the parameters of a set of resolved bricks, computed once.

Scene validation, `eval`, `accuracy`, the references and the link stage's layout all
read `spec_params`. A name shared by several bricks of one spec (canonical names:
`alpha`, `f0`, `n`, ...) is one parameter: its type must agree, its range is the
intersection of the bricks' ranges (which must not be empty), its default is the
first declaring brick's (callers first, in spec order) and must lie in that range.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..lang.errors import SourceError
from ..lang.types import Type
from ..library.bricks import check_value


@dataclass(frozen=True)
class ParamSpec:
    """One parameter of a spec: name, type, allowed range, default, and the bricks that declare it."""

    name: str
    ty: Type
    default: object
    range: tuple | None
    doc: str
    owners: tuple[str, ...]  # display paths, in declaration order

    def check(self, value) -> str:
        """'' when `value` fits the type and range, else what is wrong."""
        return check_value(self.ty, self.range, value)


def _error(brick, message: str, hint: str) -> SourceError:
    loc = brick.module.meta_loc
    return SourceError(brick.display_path, loc.line, loc.col, message, hint)


def spec_params(nodes) -> dict[str, ParamSpec]:
    """{name: ParamSpec} over every brick below `nodes` (Nodes, or bricks with no fillers), in order."""
    out: dict[str, ParamSpec] = {}
    first: dict[str, object] = {}
    for top in nodes:
        for node in (top.walk() if hasattr(top, "walk") else [top]):
            b = getattr(node, "brick", node)
            for name, p in b.params.items():
                old = out.get(name)
                if old is None:
                    out[name] = ParamSpec(name, p.ty, p.default, p.range, p.doc, (b.display_path,))
                    first[name] = b
                    continue
                if b.display_path in old.owners:
                    continue
                if old.ty != p.ty:
                    raise _error(b, f"parameter '{name}' is {p.ty} here but {old.ty} in {old.owners[0]}, "
                                    "another brick of the same spec",
                                 "one canonical name has one type (DESIGN.md): rename the parameter or fix its type")
                rng = old.range
                if p.range is not None:
                    rng = p.range if rng is None else (max(rng[0], p.range[0]), min(rng[1], p.range[1]))
                    if rng[0] > rng[1]:
                        raise _error(b, f"parameter '{name}' has range [{p.range[0]}, {p.range[1]}] here, disjoint "
                                        f"from [{old.range[0]}, {old.range[1]}] in {old.owners[0]}",
                                     "the bricks of one spec share the parameter: make the ranges overlap")
                problem = check_value(p.ty, rng, old.default)
                if problem:
                    raise _error(first[name], f"default of '{name}' does not fit {b.display_path}'s range: {problem}",
                                 "move the default inside the range every brick of the spec allows")
                out[name] = ParamSpec(name, old.ty, old.default, rng, old.doc or p.doc, old.owners + (b.display_path,))
    return out


def flat(specs: dict[str, ParamSpec]) -> list[tuple[str, str, int | None, Type, ParamSpec]]:
    """(shader name, parameter, element, type, spec) per value a shader receives: an array parameter
    becomes one value per element (`lobes_0`, `lobes_1`, ...; the glue rebuilds the array)."""
    out = []
    for k, p in specs.items():
        if p.ty.kind == "array":
            out += [(f"{k}_{i}", k, i, p.ty.elem, p) for i in range(p.ty.size)]
        else:
            out.append((k, k, None, p.ty, p))
    return out
