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

from ..library.bricks import GEOMETRY, KINDS, SURFACE, Brick
from ..lang import Signature, SourceError, parse_module
from ..lang import ir
from ..lang.types import TEXTURE2D, Type
from ..matrix.permutation import Node, Resolved

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


def brdf_params(nodes: list[Node]) -> dict[str, Type]:
    """Material parameters of a BRDF (union over its bricks; a shared name must agree on type)."""
    out: dict[str, Type] = {}
    for top in nodes:
        for n in top.walk():
            for name, p in n.brick.params.items():
                if name in out and out[name] != p.ty:
                    raise SourceError(n.brick.display_path, 1, 1,
                                      f"parameter '{name}' is {p.ty} here but {out[name]} in another brick of the BRDF",
                                      "canonical parameter names have one type (DESIGN.md)")
                out.setdefault(name, p.ty)
    return out


def _signature(sig: list[tuple[str, Type]]) -> str:
    return ", ".join(f"{n}: {t}" for n, t in sig)


def brdf_glue(prog: Program, nodes: list[Node], params: dict[str, Type],
              guarded: bool = True) -> tuple[str, list[tuple[str, Type]]]:
    """Glue text for `brdf_lit(L, V, N[, T, B], params...) -> vec3` and its parameter list.

    `brdf_lit` computes the geometric inputs the terms read and sums the terms,
    for n·l > 0. With `guarded`, also `brdf`, which returns 0 below the horizon
    and calls it (the eval kernel's entry). The light loop tests n·l itself, to
    skip shadow and radiance work, so shade() calls `brdf_lit` and gets no `brdf`.
    """
    entries = [(n.brick, n.brick.entries[0]) for n in nodes]
    used = {p.name for _, f in entries for p in f.params if p.name in GEOMETRY}
    frame = [("L", GEOMETRY["L"]), ("V", GEOMETRY["V"]), ("N", GEOMETRY["N"])]
    if used & {"T", "B"}:
        frame += [("T", GEOMETRY["T"]), ("B", GEOMETRY["B"])]
    sig = frame + [(name, ty) for name, ty in params.items()]
    lines = [f"def brdf_lit({_signature(sig)}) -> vec3:"]
    needed = set(used)
    for name, _, deps in reversed(NEEDS):
        if name in needed:
            needed.update(deps)
    for name, expr, _ in NEEDS:
        if name in needed:
            lines.append(f"    {name} = {expr}")
    terms = [f"{mangle(b, f.name)}({entry_args(f, lambda p: p.name)})" for b, f in entries]
    lines.append(f"    return {' + '.join(terms)}")
    if guarded:
        lines += ["", "",
                  f"def brdf({_signature(sig)}) -> vec3:",
                  "    if dot(N, L) <= 0.0:",
                  "        return vec3(0.0)",
                  f"    return brdf_lit({', '.join(n for n, _ in sig)})"]
    return "\n".join(lines) + "\n", sig


def check_packing(r: Resolved) -> str:
    """'' when the packing fits the BRDF, else why not (a provided input the BRDF does not read)."""
    params = brdf_params(r.brdf)
    for f in r.packing.brick.entries:
        name = f.name[len("get_"):]
        if name not in params:
            return (f"packing '{r.packing.brick.id}' provides {name}, which BRDF "
                    f"'{'+'.join(n.canonical() for n in r.brdf)}' does not read")
    return ""


@dataclass
class ShadeGlue:
    """The fragment glue of a permutation and what its template must feed `shade()`."""

    signature: list[tuple[str, Type]]  # shade()'s parameters, in order
    inputs: list[str]  # interpolants read: P, N, then T, B and uv where needed
    material: list[tuple[str, Type]]  # m_<param>: BRDF, packing and normal parameters
    lights: list[list[tuple[str, Type]]]  # l<i>_<param> per light: light and shadow parameters
    textures: list[dict]  # {"name", "srgb", "group": "material" | "light"}


class _Calls:
    """Binds entry parameters by name to shade()'s locals, parameters and textures."""

    def __init__(self):
        self.textures: list[dict] = []
        self.entries: list[ir.Function] = []

    def call(self, brick: Brick, f: ir.Function, param_prefix: str, texture_prefix: str, group: str) -> str:
        self.entries.append(f)
        args = []
        for p in f.params:
            if p.ty.kind == "texture":
                name = texture_prefix + p.name
                if name not in {t["name"] for t in self.textures}:
                    self.textures.append({"name": name, "srgb": bool(brick.textures[p.name].get("srgb")),
                                          "group": group})
                args.append(name)
            elif p.name == "N":
                args.append("Ng")  # surface bricks read the interpolated normal
            elif p.name in SURFACE:
                args.append(p.name)
            else:
                args.append(param_prefix + p.name)
        return f"{mangle(brick, f.name)}({', '.join(args)})"


def shade_glue(prog: Program, r: Resolved) -> ShadeGlue:
    """Link a permutation's bricks into `prog` and add the brdf() and shade() glue.

    shade(P, Ng, V[, T, B][, uv], material..., lights..., textures...) -> vec4:
    the packing's material inputs, the shading normal, the unrolled light loop
    L_o += pi f_r c_light (n.l) visibility (Hoffman & Baker 2006), the output.
    """
    for n in r.brdf:
        prog.link(n)
    params = brdf_params(r.brdf)
    brdf_text, brdf_sig = brdf_glue(prog, r.brdf, params, guarded=False)
    normal = dict(r.packing.fillers)["normal"]
    prog.link(r.packing)
    for lb, sh in r.lights:
        prog.link(Node(lb, ()))
        prog.link(sh)
    prog.link(Node(r.output, ()))

    material = [(f"m_{k}", t) for k, t in params.items()]
    for n in r.packing.walk():
        material += [(f"m_{k}", p.ty) for k, p in n.brick.params.items()]
    calls = _Calls()
    body, provided = [], {}
    for f in r.packing.brick.entries:
        name = f.name[len("get_"):]
        body.append(f"    p_{name} = {calls.call(r.packing.brick, f, 'm_', 't_', 'material')}")
        provided[name] = f"p_{name}"
    body.append(f"    N = {calls.call(normal.brick, normal.brick.entries[0], 'm_', 't_', 'material')}")
    body.append("    Lo = vec3(0.0)")
    tangent = any(n == "T" for n, _ in brdf_sig)
    brdf_args = ["V", "N"] + (["T", "B"] if tangent else []) + [provided.get(k, f"m_{k}") for k in params]
    lights = []
    for i, (lb, sh) in enumerate(r.lights):
        values = [(f"l{i}_{k}", p.ty) for k, p in lb.params.items()]
        for n in sh.walk():
            values += [(f"l{i}_{k}", p.ty) for k, p in n.brick.params.items()]
        lights.append(values)
        fns = lb.module.functions
        pre = f"l{i}_"
        body += [f"    L{i} = {calls.call(lb, fns['light_dir'], pre, pre, 'light')}",
                 f"    NdotL{i} = dot(N, L{i})",
                 f"    if NdotL{i} > 0.0:",
                 f"        c{i} = {calls.call(lb, fns['light_radiance'], pre, pre, 'light')}",
                 f"        s{i} = {calls.call(sh.brick, sh.brick.entries[0], pre, pre, 'light')}",
                 f"        Lo += PI * brdf_lit({', '.join([f'L{i}'] + brdf_args)}) * c{i} * (NdotL{i} * s{i})"]
    body.append(f"    return {mangle(r.output, 'output')}(Lo)")

    surf = surface_inputs(calls.entries)
    inputs = ["P", "N"] + (["T", "B"] if tangent or surf & {"T", "B"} else []) + (["uv"] if "uv" in surf else [])
    sig = [("P", GEOMETRY["L"]), ("Ng", GEOMETRY["N"]), ("V", GEOMETRY["V"])]
    sig += [(x, SURFACE[x]) for x in inputs if x in ("T", "B", "uv")]
    sig += material + [v for vals in lights for v in vals] + [(t["name"], TEXTURE2D) for t in calls.textures]
    shade = f"def shade({_signature(sig)}) -> vec4:\n" + "\n".join(body) + "\n"
    prog.add_glue(glue_header("BRDF and shading glue") + brdf_text + "\n\n" + shade)
    return ShadeGlue(sig, inputs, material, lights, calls.textures)


def surface_inputs(fns: list[ir.Function]) -> set[str]:
    """Which of P, N, T, B, uv the given entries read."""
    return {p.name for f in fns for p in f.params if p.name in SURFACE}
