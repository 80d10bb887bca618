"""The sampling program of a BRDF: per term, `sample_<k>` and `pdf_<k>` (library/kinds.py states the contract).

- `sample_<k>(u, V, N, T, B, params...) -> vec3`: a direction L drawn by term k's sampler;
- `pdf_<k>(L, V, N, T, B, params...) -> float`: the density (per unit solid angle) that sampler draws L with.
Every term takes the BRDF's whole parameter list (the eval program's order), bound by name, so one call
shape serves every term. A term whose brick has no sampler, or whose slot filler lacks the sampling entry
the host calls (a microfacet BRDF with an NDF that has no `sample_h`), is sampled cosine-weighted: this
module decides it, and `SamplingProgram.how` says so per term. The lobe mixture (pick a term, pdf = the
weighted sum of the terms' pdfs) is the caller's: the terms' selection weights are host values.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..lang import SourceError, ir, parse_module
from ..lang.types import INT, VEC2, VEC3, Type
from ..library.bricks import Library
from ..library.kinds import KINDS
from ..spec.params import Params
from ..spec.resolve import ResolvedBrdf, resolve_brdf
from .irgen import Builder
from .program import Program, function_name

FRAME_ARGS = {"sample": ("u", VEC2), "pdf": ("L", VEC3)}

# The fallback of a term without a sampler: cosine-weighted hemisphere sampling (Malley's method: a uniform
# point of the unit disk, by u = (r², φ / 2π), lifted to the hemisphere; pdf = cos θ / π; pbrt-v3 §13.6.3).
_FALLBACK_PATH = "<cosine sampler>"
_FALLBACK = '''"""Cosine-weighted hemisphere sampling, the fallback of a BRDF term without a sampler."""
BRICK = {"kind": "diffuse", "cite": "pbrt-v3 13.6.3"}


def cosine_sample(u: vec2, N: vec3, T: vec3, B: vec3) -> vec3:
    r = sqrt(u.x)
    phi = TWO_PI * u.y
    return T * (r * cos(phi)) + B * (r * sin(phi)) + N * sqrt(max(1.0 - u.x, 0.0))


def cosine_pdf(L: vec3, N: vec3) -> float:
    c = dot(N, L)
    return c * INV_PI if c > 0.0 else 0.0
'''


@dataclass
class SamplingProgram:
    """The linked sampling functions of one BRDF."""

    spec: str
    program: Program
    specs: Params
    how: tuple[str, ...]  # per term: "<brick id>: own sampler" or "<brick id>: cosine-weighted fallback (why)"
    signature: dict[str, list[tuple[str, Type]]]  # "sample" / "pdf": the glue functions' parameters

    @property
    def terms(self) -> int:
        return len(self.how)


def _fallback_module() -> ir.Module:
    return parse_module(_FALLBACK, _FALLBACK_PATH)


def _order(fns: dict[str, ir.Function]) -> list[str]:
    order: list[str] = []

    def visit(name):
        if name in order or name not in fns:
            return
        for c in fns[name].calls:
            visit(c)
        order.append(name)

    for name in fns:
        visit(name)
    return order


class _Linker:
    """Links the sampling functions of nodes into a program whose shading functions are already linked."""

    def __init__(self, prog: Program):
        self.prog = prog
        self.linked: dict[str, dict[str, str] | None] = {}  # node key -> {function: linked name}; None: unavailable
        self.why: dict[str, str] = {}

    def link(self, node) -> dict[str, str] | None:
        if node.key in self.linked:
            return self.linked[node.key]
        b = node.brick
        fillers = {}
        for slot, filler in node.fillers:
            if KINDS[b.slots[slot]["kind"]].slot:
                fillers[slot] = (filler, self.link(filler))
        result = self._link(node, fillers) if b.sampling else None
        if not b.sampling:
            self.why[node.key] = f"{b.id} has no sampler"
        self.linked[node.key] = result
        return result

    def _link(self, node, fillers) -> dict[str, str] | None:
        b = node.brick
        main = self.prog._linked[(b.kind, node.key)]
        rename = dict(main) | {n: function_name(node, n) for n in b.sampling}
        fns = {n: ir.clone(b.sampling[n]) for n in _order(b.sampling)}
        extra: dict[str, dict[str, Type]] = {}
        for name, f in fns.items():
            need: dict[str, Type] = {}
            for n in ir.walk_body(f.body):
                if not isinstance(n, ir.Call):
                    continue
                bound = self._slot_call(b, n, fillers)
                if bound is False:
                    return None
                if bound is not None:
                    need.update(bound)
                elif n.func in extra:
                    need.update(extra[n.func])
                    n.args = n.args + [ir.Var(t, n.loc, p, "param") for p, t in extra[n.func].items()]
                elif n.func in main:  # a shading helper: it may have gained threaded parameters when linked
                    target = self.prog.by_name[main[n.func]]
                    more = {p.name: p.ty for p in target.params[len(n.args):]}
                    need.update(more)
                    n.args = n.args + [ir.Var(t, n.loc, p, "param") for p, t in more.items()]
            extra[name] = Program._thread(b, f, need)
        for name, f in fns.items():
            for n in ir.walk_body(f.body):
                if isinstance(n, ir.Call) and n.func in rename:
                    n.func = rename[n.func]
            f.calls = [rename.get(c, c) for c in f.calls]
            f.name = rename[name]
            self.prog.add(f, b)
        return {n: rename[n] for n in fns}

    def _slot_call(self, host, call: ir.Call, fillers):
        """Bind `<slot>_<entry>(...)` to the filler's linked entry (threaded names returned); None: not a slot
        call; False: the filler has no such entry (the host's sampler is unavailable)."""
        for slot, (filler, linked) in fillers.items():
            kind = KINDS[filler.brick.kind]
            for e in kind.entries:
                if not e.sampling or call.func != f"{slot}_{e.name}":
                    continue
                if not linked or e.name not in linked:
                    self.why[host.id] = f"its {slot} filler {filler.brick.id} has no {e.name}"
                    return False
                entry = self.prog.by_name[linked[e.name]]
                given = {a.name: arg for a, arg in zip(e.args, call.args)}
                args, threaded = [], {}
                for p in entry.params:
                    if p.name in given:
                        args.append(given[p.name])
                    else:
                        args.append(ir.Var(p.ty, call.loc, p.name, "param"))
                        threaded[p.name] = p.ty
                call.func, call.args = entry.name, args
                return threaded
        return None


def sampling_program(spec: str | ResolvedBrdf, lib: Library) -> SamplingProgram:
    """Link the sampling program of a BRDF spec (see the module docstring)."""
    rb = spec if isinstance(spec, ResolvedBrdf) else resolve_brdf(spec, lib)
    prog = Program(lib_memo=lib.memo)
    for n in rb.nodes:
        prog.link(n)
    linker = _Linker(prog)
    fallback = None
    b = Builder()
    params = rb.params
    flat = [(n, t) for n, _, _, t, _ in params.flat]
    sigs = {what: [first, ("V", VEC3), ("N", VEC3), ("T", VEC3), ("B", VEC3)] + flat
            for what, first in FRAME_ARGS.items()}
    how = []
    for k, node in enumerate(rb.nodes):
        linked = linker.link(node)
        if linked and "sample" in linked and "pdf" in linked:
            entries = {w: prog.by_name[linked[w]] for w in FRAME_ARGS}
            how.append(f"{node.brick.id}: own sampler")
        else:
            if fallback is None:
                fallback = {f.name: prog.add(ir.clone(f)) for f in _fallback_module().functions.values()}
            entries = {w: fallback[f"cosine_{w}"] for w in FRAME_ARGS}
            why = linker.why.get(node.key) or linker.why.get(node.brick.id) or f"{node.brick.id} defines no sample and pdf"
            how.append(f"{node.brick.id}: cosine-weighted fallback ({why})")
        counts = {f"{a}_count": c for x in node.tree for a, c in x.counts}
        for what, f in entries.items():
            prog.add(b.function(f"{what}_{k}", sigs[what], f.ret, _body(b, f, sigs[what], params, counts, rb)))
    return SamplingProgram(rb.key, prog, params, tuple(how), sigs)


def _body(b: Builder, f: ir.Function, sig, params: Params, counts: dict[str, int], rb: ResolvedBrdf):
    def body():
        stmts = []
        for k, spec in params.items():  # array parameters arrive as elements; the entry takes the array
            if spec.ty.kind == "array" and any(p.name == k for p in f.params):
                elems = [b.var(f"{k}_{i}", spec.ty.elem) for i in range(spec.ty.size)]
                stmts.append(b.decl(k, b.construct(spec.ty, *elems)))
        env = dict(sig) | {k: s.ty for k, s in params.items()}
        args = []
        for p in f.params:
            if p.name in counts:
                args.append(ir.Const(INT, b.here(), counts[p.name]))
            elif p.name in env:
                args.append(b.var(p.name, env[p.name]))
            else:
                raise SourceError(p.loc.path, p.loc.line, p.loc.col, f"'{p.name}' of '{f.name}' is bound by nothing "
                                  f"in BRDF '{rb.key}'", "a sampling entry reads its arguments and the parameters")
        stmts.append(b.ret(b.call(f, args)))
        return stmts
    return body

