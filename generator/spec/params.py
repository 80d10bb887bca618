"""The one parameter policy: the parameters of a permutation's bricks, computed once, in one place.

`spec_params` is the policy and `resolve` (spec/resolve.py) its only caller on a permutation's
way to a shader: scene validation, `eval`, `accuracy`, the references, the link stage's layout
and the ubershader read the groups it returns (Resolved.brdf_params, .light_params …). A name
shared by several bricks of one group (canonical names: `alpha`, `f0`, `n`, ...) is one
parameter: its type must agree, its range is the intersection of the bricks' ranges (which must
not be empty), its default is the first declaring brick's (callers first, in spec order) and
must lie in that range.
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


class Frozen(dict):
    """A dict that refuses every change: the mappings held by a frozen resolved value (read like any dict)."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("a resolved value is frozen: build a new one instead of changing it")

    __setitem__ = __delitem__ = __ior__ = clear = pop = popitem = setdefault = update = _refuse

    def __reduce__(self):  # pickled by value (build workers return what they composed)
        return type(self), (dict(self),)


class Params(Frozen):
    """One parameter group ({name: ParamSpec}, in declaration order), with `flat`: what a shader receives
    of it (flat(): one value per array element), computed once."""

    def __init__(self, specs=()):
        super().__init__(specs)
        object.__setattr__(self, "flat", tuple(flat(self)))

    def __setattr__(self, name, value):
        self._refuse()

    def __reduce__(self):
        return type(self), (dict(self),)


def _error(brick, message: str, hint: str) -> SourceError:
    loc = brick.module.meta_loc
    return SourceError(brick.display_path, loc.line, loc.col, message, hint)


def _merge(nodes, start: tuple[dict, dict] | None = None) -> Params:
    """The policy over every brick below `nodes` (spec Nodes, callers first), in order; from `start` (the state
    _merged left after the nodes before these: the merge goes brick by brick, so a permutation's material group
    continues from its BRDF's instead of walking the BRDF's bricks again)."""
    return _merged(nodes, start)[0]


def _merged(nodes, start: tuple[dict, dict] | None = None) -> tuple[Params, tuple[dict, dict]]:
    """(_merge's Params, the state it ends in: {name: ParamSpec}, {name: the brick that declared it first})."""
    out: dict[str, ParamSpec] = dict(start[0]) if start else {}
    first: dict[str, object] = dict(start[1]) if start else {}
    for top in nodes:
        for node in top.walk():
            b = node.brick
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
                                 "one canonical name has one type: rename the parameter or fix its type")
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
    return Params(out), (out, first)


@dataclass(frozen=True)
class LightPolicy:
    """The groups of one light: its brick and shadow filter as one group (the light's block), each alone
    (the ubershader lays light types and shadow filters out separately)."""

    params: Params
    light: Params
    shadow: Params


@dataclass(frozen=True)
class Policy:
    """Every parameter group of one permutation (or of a BRDF alone, or of one light)."""

    brdf: Params  # the BRDF's terms and their fillers
    packing: Params  # the packing's (its normal filler's too) that the BRDF does not declare
    output: Params
    material: Params  # BRDF, packing and output as one group: the names a scene's material may set
    lights: tuple[LightPolicy, ...] = ()


def spec_params(brdf=(), packing=None, output=None, lights=(), memo: dict | None = None) -> Policy:
    """The one parameter policy of a permutation: brdf (its term Nodes), packing and output (a Node each, or
    None), lights ((light Node, shadow Node) per light). Raises a SourceError at the brick that breaks it.

    memo (the library's): each group of bricks merged once — a scene's permutations share their BRDFs, packings,
    lights and output, and only the material group (BRDF, packing and output together) is theirs alone."""
    def merged(nodes):
        return _merged(nodes) if memo is None else _cached(nodes, memo)

    own, state = merged(brdf)
    material = _merge([*([packing] if packing is not None else []), *([output] if output is not None else [])], state)
    packed = merged([packing])[0] if packing is not None else Params()
    out = merged([output])[0] if output is not None else Params()
    groups = tuple(LightPolicy(merged([ln, sh])[0], merged([ln])[0], merged([sh])[0]) for ln, sh in lights)
    return Policy(own, Params({k: s for k, s in packed.items() if k not in own}), out, material, groups)


def group(nodes, memo: dict | None = None) -> Params:
    """The policy over `nodes` as one group of their own (an environment brick's: its values are the light
    set's, laid out after the lights)."""
    return (_merged(nodes) if memo is None else _cached(nodes, memo))[0]


def _cached(nodes, memo: dict):
    """_merged(nodes), kept in `memo` per these very Node objects (the entry holds them, so their ids name no
    other node while it lives): the spec stage keeps one Node per spec string and brick (parse_spec's memo), made
    again when a brick is replaced, so a hit is always a merge of the bricks the nodes hold. A merge that raises
    is not kept."""
    key = ("params", *map(id, nodes))
    hit = memo.get(key)
    if hit is not None:
        return hit[1]
    value = _merged(nodes)
    memo[key] = (tuple(nodes), value)
    return value


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
