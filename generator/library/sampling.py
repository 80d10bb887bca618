"""The sampling entries of a brick, kept apart from its shading code.

A diffuse or specular brick may define `sample` and `pdf`, an NDF slot filler `sample_h` and `pdf_h`
(library/kinds.py states the contract). They are parsed with the brick, checked against the contract, then
moved out of the brick's module with the helpers only they call (`Brick.sampling`): a shading program links
the module's functions, so a shader never carries a sampler it does not call, and only a sampling program
(link/sampling.py) links them. A host calls its filler's sampling entry as `<slot>_<entry>(...)`
(`ndf_sample_h(u, V, N, T, B, alpha)`), typed against the slot kind's contract.
"""
from __future__ import annotations

from ..lang import SourceError, ir
from ..lang.parse import Signature
from .kinds import KINDS, Kind


def slot_sampling_externals(slot: str, kind: Kind) -> dict[str, Signature]:
    """{`<slot>_<entry>`: its signature} for each sampling entry of a slot kind."""
    return {f"{slot}_{e.name}": Signature(kind.signature(e.name), e.ret) for e in kind.entries if e.sampling}


def _reach(fns: dict[str, ir.Function], starts) -> set[str]:
    seen: set[str] = set()
    todo = [s for s in starts if s in fns]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        todo.extend(c for c in fns[name].calls if c in fns and c not in seen)
    return seen


def _slot_calls(f: ir.Function, names: set[str]) -> list[ir.Call]:
    return [n for n in ir.walk_body(f.body) if isinstance(n, ir.Call) and n.func in names]


def split_sampling(brick) -> dict[str, ir.Function]:
    """Move the brick's sampling entries, and the helpers only they reach, out of its module; return them.

    A shading function that calls a sampling entry, or a filler's (`ndf_sample_h`), is an error: the shading
    program would not have it."""
    kind = KINDS[brick.kind]
    fns = brick.module.functions
    entries = [e.name for e in kind.entries if e.sampling and e.name in fns]
    slot_entries = {f"{s}_{e.name}" for s, d in brick.slots.items() if KINDS[d["kind"]].slot
                    for e in KINDS[d["kind"]].entries if e.sampling}
    if not entries:
        stray = [(f, c) for f in fns.values() for c in _slot_calls(f, slot_entries)]
        if stray:
            f, c = stray[0]
            raise SourceError(brick.display_path, c.loc.line, c.loc.col,
                              f"'{f.name}' calls the sampling entry '{c.func}', but the brick defines no sampling entry",
                              "call a filler's sample_h / pdf_h only from this brick's sample and pdf")
        return {}
    sampling = _reach(fns, entries)
    shading_entries = [e.name for e in kind.entries if not e.sampling]
    shading = _reach(fns, [n for n in fns if n not in sampling or n in shading_entries])
    for name in shading:
        f = fns[name]
        bad = [c for c in f.calls if c in entries] + [c.func for c in _slot_calls(f, slot_entries)]
        if bad:
            raise SourceError(brick.display_path, f.loc.line, f.loc.col,
                              f"'{name}' calls the sampling entry '{bad[0]}', which no shading program links",
                              "keep shading code and sampling code apart: share a helper both call instead")
    moved = {n: f for n, f in fns.items() if n in sampling and n not in shading}
    brick.module.functions = {n: f for n, f in fns.items() if n not in moved}
    return moved
