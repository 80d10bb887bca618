"""Linking brick functions into one program, and the generated glue functions.

Linking copies each brick's functions under the name `<brick id>_<function>`
and points slot calls at the filler's entry. The glue — `brdf` (the BRDF from
its terms and the geometric inputs they read) and `shade` (packing, normal,
the unrolled light loop, output) — is generated as brick-language text and
parsed like any brick, so every target emits it from the same IR.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field

from .bricks import GEOMETRY, KINDS, SURFACE, Brick
from .lang import Signature, SourceError, parse_module
from .lang import ir
from .lang.types import Type
from .permutation import Node

GLUE_PATH = "<glue>"

# Geometric inputs in evaluation order: (name, brick-language expression, inputs it uses).
# Policy (DESIGN notes): f_r is 0 for n.l <= 0; n.v is clamped to [1e-4, 1] so a view
# below the horizon after normal mapping shades as grazing instead of black or NaN.
NEEDS = [
    ("NdotL", "min(dot(N, L), 1.0)", ()),
    ("NdotV", "clamp(dot(N, V), 0.0001, 1.0)", ()),
    ("Hsum", "L + V", ()),
    # |l + v|² is floored so that l = -v (possible only for v below the horizon) gives H = 0, not
    # NaN. The floor is a normal float32 far below the mirror configuration at grazing, where
    # |l + v|² = 4 cos²θ (a floor of 1e-12 left H unnormalized, n·h wrong, for cos θ < 5e-7).
    ("H", "Hsum * rsqrt(max(dot(Hsum, Hsum), 1e-30))", ("Hsum",)),
    ("NdotH", "clamp(dot(N, H), 0.0, 1.0)", ("H",)),
    # sin²θ_h = |n × h|² (Filament): keeps its digits as h → n, where 1 - (n·h)² is all rounding
    # in float32 (ACCURACY-FACTS pitfall 4); 1 where n·h is clamped to 0, as 1 - 0².
    ("NxH", "cross(N, H)", ("H",)),
    ("NxH2", "dot(NxH, NxH) if NdotH > 0.0 else 1.0", ("NxH", "NdotH")),
    ("LdotH", "clamp(dot(L, H), 0.0, 1.0)", ("H",)),
    ("VdotH", "clamp(dot(V, H), 0.0, 1.0)", ("H",)),
    ("LdotV", "dot(L, V)", ()),
    ("RdotV", "clamp(dot(reflect(-L, N), V), 0.0, 1.0)", ()),
]


def mangle(brick: Brick, fname: str) -> str:
    return f"{brick.id}_{fname}"


@dataclass
class Program:
    """Linked brick functions (callees first) and the signatures of their entries."""

    functions: list[ir.Function] = field(default_factory=list)
    structs: list[Type] = field(default_factory=list)
    signatures: dict[str, Signature] = field(default_factory=dict)
    bricks: dict[str, Brick] = field(default_factory=dict)  # display path -> brick
    _done: set = field(default_factory=set)

    def link(self, node: Node) -> None:
        """Add a brick with its fillers; entries become callable as <id>_<entry>."""
        for _, filler in node.fillers:
            self.link(filler)
        b = node.brick
        key = node.canonical() + "@" + b.kind
        if key in self._done:
            return
        self._done.add(key)
        self.bricks[b.display_path] = b
        rename = {name: mangle(b, name) for name in b.module.functions}
        for slot, filler in node.fillers:
            entry = KINDS[filler.brick.kind].entries[0] if KINDS[filler.brick.kind].entries else None
            if KINDS[b.slots[slot]["kind"]].interface is not None and entry:
                rename[slot] = mangle(filler.brick, entry)
        for name in _call_order(b.module):
            f = copy.deepcopy(b.module.functions[name])
            new = rename[name]
            if new in self.signatures:
                raise SourceError(b.display_path, f.loc.line, f.loc.col,
                                  f"function name '{new}' is generated twice when linking",
                                  "two bricks produce the same <id>_<function> name; rename a function")
            f.name = new
            for node_ in ir.walk_body(f.body):
                if isinstance(node_, ir.Call):
                    node_.func = rename[node_.func]
            f.calls = [rename[c] for c in f.calls]
            self.functions.append(f)
            self.signatures[new] = Signature(tuple((p.name, p.ty) for p in f.params), f.ret)
        for st in b.module.structs.values():
            if st not in self.structs:
                self.structs.append(st)

    def add_glue(self, text: str) -> list[ir.Function]:
        """Parse generated glue against the linked signatures and append its functions."""
        module = parse_module(text, GLUE_PATH, dict(self.signatures))
        fns = [module.functions[n] for n in _call_order(module)]
        for f in fns:
            self.signatures[f.name] = Signature(tuple((p.name, p.ty) for p in f.params), f.ret)
        self.functions.extend(fns)
        return fns


def _call_order(module: ir.Module) -> list[str]:
    """Function names of a module, callees before callers, otherwise in file order."""
    order: list[str] = []

    def visit(name):
        if name in order or name not in module.functions:
            return
        for c in module.functions[name].calls:
            visit(c)
        order.append(name)

    for name in module.functions:
        visit(name)
    return order


def glue_header(doc: str) -> str:
    return f'"""{doc}"""\nBRICK = {{"kind": "glue"}}\n\n'


def entry_args(f: ir.Function, bind) -> str:
    """Arguments for a call to entry `f`, each parameter bound by name through `bind`."""
    return ", ".join(bind(p) for p in f.params)


def brdf_glue(prog: Program, nodes: list[Node], params: dict[str, Type]) -> tuple[str, list[tuple[str, Type]]]:
    """Glue text for `brdf(L, V, N[, T, B], params...) -> vec3` and its parameter list."""
    entries = [(n.brick, n.brick.entries[0]) for n in nodes]
    used = {p.name for _, f in entries for p in f.params if p.name in GEOMETRY}
    frame = [("L", GEOMETRY["L"]), ("V", GEOMETRY["V"]), ("N", GEOMETRY["N"])]
    if used & {"T", "B"}:
        frame += [("T", GEOMETRY["T"]), ("B", GEOMETRY["B"])]
    sig = frame + [(name, ty) for name, ty in params.items()]
    lines = [f"def brdf({', '.join(f'{n}: {t}' for n, t in sig)}) -> vec3:",
             "    if dot(N, L) <= 0.0:",
             "        return vec3(0.0)"]
    needed = set(used)
    for name, _, deps in reversed(NEEDS):
        if name in needed:
            needed.update(deps)
    for name, expr, _ in NEEDS:
        if name in needed:
            lines.append(f"    {name} = {expr}")
    terms = [f"{mangle(b, f.name)}({entry_args(f, lambda p: p.name)})" for b, f in entries]
    lines.append(f"    return {' + '.join(terms)}")
    return "\n".join(lines) + "\n", sig


def surface_inputs(fns: list[ir.Function]) -> set[str]:
    """Which of P, N, T, B, uv the given entries read."""
    return {p.name for f in fns for p in f.params if p.name in SURFACE}
