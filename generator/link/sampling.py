"""The sampling program of a BRDF: per term, `sample_<k>` and `pdf_<k>` (library/kinds.py states the contract).

- `sample_<k>(u, V, N, T, B, params...) -> vec3`: a direction L drawn by term k's sampler;
- `pdf_<k>(L, V, N, T, B, params...) -> float`: the density (per unit solid angle) that sampler draws L with.
Every term takes the BRDF's whole parameter list (the eval program's order), bound by name, so one call
shape serves every term. A term whose brick has no sampler, or whose slot filler lacks the sampling entry
the host calls (a microfacet BRDF with an NDF that has no `sample_h`), is sampled cosine-weighted: this
module decides it, and `SamplingProgram.how` says so per term.

The one-sample mixture over the terms (the lecture's multi-layer rule) is linked here too, as the kernel
entries every target runs (`KERNELS`):
- `sampling_sample(L, V, N, T, B, params..., mis_w0..mis_w7) -> vec3`: L carries the uniforms u3; u3.z picks
  term k with probability w_k, u3.xy samples it;
- `sampling_pdf(L, V, N, T, B, params..., mis_w0..mis_w7) -> vec3`: (Σ_k w_k pdf_k(L), 0, 0).
Their signature is the eval kernel's (link.EvalProgram, tangent frame always passed), so the eval kernel
machinery composes, compiles and runs them unchanged. The weights are host values: `mis_w<j>` holds up to 4
terms' unnormalized weights at n·v = j/7, linearly interpolated in n·v (eval/sampling.py computes them
from each term's directional albedo).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..lang import SourceError, ir, parse_module
from ..lang.types import FLOAT, INT, VEC2, VEC3, VEC4, Type
from ..library.bricks import Library
from ..library.kinds import KINDS
from ..spec.params import Params, ParamSpec
from ..spec.resolve import ResolvedBrdf, resolve_brdf
from ..spec.where import spec_where
from .irgen import Builder
from .program import Program, function_name

FRAME_ARGS = {"sample": ("u", VEC2), "pdf": ("L", VEC3)}
KERNELS = {"sample": "sampling_sample", "pdf": "sampling_pdf"}  # the mixture's entries (eval-kernel shaped)
MIS_VIEWS = 8  # view cosines n.v = j / (MIS_VIEWS - 1) at which the host tabulates the selection weights
MIS_TERMS = 4  # terms one vec4 of weights holds: the GPU mixture's limit
MIS_PARAMS = tuple(f"mis_w{j}" for j in range(MIS_VIEWS))

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
    rb: ResolvedBrdf | None = None
    kernel_specs: Params | None = None  # the BRDF's parameters then the weight table: the KERNELS' parameters

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
    kspecs = _mixture(prog, b, sigs, len(rb.nodes), rb)
    return SamplingProgram(rb.key, prog, params, tuple(how), sigs, rb, kspecs)


def _mixture(prog: Program, b: Builder, sigs, terms: int, rb: ResolvedBrdf) -> Params:
    """Add the one-sample mixture over `terms` terms and its kernel entries (module docstring); its parameters."""
    params = rb.params
    clash = [n for n in MIS_PARAMS if n in params]
    where = rb.where or spec_where(rb.text)
    if clash:
        raise where.error(f"parameter '{clash[0]}' of {params[clash[0]].owners[0]} has the name of the sampling "
                          "mixture's weight table", "rename the brick parameter")
    if terms > MIS_TERMS:
        raise where.error(f"BRDF '{rb.key}' has {terms} terms and the sampling mixture takes at most {MIS_TERMS}",
                          "sample such a BRDF term by term (term=k)")
    _Mixture(prog, b, sigs, terms).add()
    return Params(dict(params) | {n: ParamSpec(n, VEC4, [1.0, 0.0, 0.0, 0.0], None,
                                              "sampling mixture weights at n.v = j/7 (host values)", ("<sampling>",))
                                  for n in MIS_PARAMS})


class _Mixture:
    """Builds the mixture's functions as IR: mis_weights, mis_pdf, mis_sample and the two kernel entries."""

    def __init__(self, prog: Program, b: Builder, sigs, terms: int):
        self.prog, self.b, self.terms = prog, b, terms
        self.frame, self.flat = sigs["sample"][1:5], sigs["sample"][5:]
        self.table = [(n, VEC4) for n in MIS_PARAMS]
        self.mix_sig = [("L", VEC3)] + self.frame + self.flat + [("w", VEC4)]

    def v(self, name, ty=VEC3):
        return self.b.var(name, ty)

    def comp(self, e, i):
        return ir.Swizzle(FLOAT, self.b.here(), e, "xyzw"[i])

    def clamp01(self, e):
        return self.b.intrinsic("clamp", FLOAT, e, self.b.const(0.0), self.b.const(1.0))

    def total(self, e_of, upto=None):  # e_of(0) + ... + e_of(upto) (every term by default)
        out = e_of(0)
        for k in range(1, (self.terms - 1 if upto is None else upto) + 1):
            out = self.b.arith("+", out, e_of(k))
        return out

    def term_args(self, first):
        return [first] + [self.v(n, t) for n, t in self.frame + self.flat]

    def weights_body(self):  # piecewise-linear in n.v through the table's nodes: a chain of mixes, no indexing
        b, v = self.b, self.v
        x = b.arith("*", self.clamp01(b.intrinsic("dot", FLOAT, v("N"), v("V"))), b.const(MIS_VIEWS - 1))
        stmts = [b.decl("x", x), b.decl("w", v(MIS_PARAMS[0], VEC4))]
        for j in range(1, MIS_VIEWS):
            t = b.construct(VEC4, self.clamp01(b.arith("-", v("x", FLOAT), b.const(j - 1))))
            stmts.append(b.assign(v("w", VEC4), b.intrinsic("mix", VEC4, v("w", VEC4), v(MIS_PARAMS[j], VEC4), t)))
        return stmts + [b.ret(v("w", VEC4))]

    def pdf_body(self):  # Σ w_k pdf_k(L) / Σ w_k (a term of weight 0 adds nothing, whatever its pdf there)
        b, w = self.b, self.v("w", VEC4)
        pdfs = [self.prog.by_name[f"pdf_{k}"] for k in range(self.terms)]
        scaled = self.total(lambda k: ir.Select(FLOAT, b.here(), b.compare(">", self.comp(w, k), b.const(0.0)),
                                                b.arith("*", self.comp(w, k), b.call(pdfs[k], self.term_args(self.v("L")))),
                                                b.const(0.0)))
        return [b.ret(b.arith("/", scaled, self.total(lambda k: self.comp(w, k))))]

    def sample_body(self):  # u3.z scaled by Σ w picks the first term whose running sum of weights exceeds it
        b, w = self.b, self.v("w", VEC4)
        samplers = [self.prog.by_name[f"sample_{k}"] for k in range(self.terms)]

        def uv():
            return ir.Swizzle(VEC2, b.here(), self.v("L"), "xy")

        stmts = [b.decl("c", b.arith("*", self.comp(self.v("L"), 2), self.total(lambda k: self.comp(w, k)))),
                 b.decl("s", b.call(samplers[-1], self.term_args(uv())))]
        for k in reversed(range(self.terms - 1)):  # the last assignment made is the smallest k with c < w.x+..+w[k]
            stmts.append(b.if_(b.compare("<", self.v("c", FLOAT), self.total(lambda i: self.comp(w, i), k)),
                               [b.assign(self.v("s"), b.call(samplers[k], self.term_args(uv())))]))
        return stmts + [b.ret(self.v("s"))]

    def add(self) -> None:
        b, prog = self.b, self.prog
        weights = prog.add(b.function("mis_weights", [("V", VEC3), ("N", VEC3)] + self.table, VEC4, self.weights_body))
        mis_pdf = prog.add(b.function("mis_pdf", self.mix_sig, FLOAT, self.pdf_body))
        mis_sample = prog.add(b.function("mis_sample", self.mix_sig, VEC3, self.sample_body))
        entry_sig = [("L", VEC3)] + self.frame + self.flat + self.table

        def entry_body(f, wrap):
            def body():
                w = b.call(weights, [self.v("V"), self.v("N")] + [self.v(n, VEC4) for n in MIS_PARAMS])
                return [b.ret(wrap(b.call(f, [self.v(n, t) for n, t in self.mix_sig[:-1]] + [w])))]
            return body

        prog.add(b.function(KERNELS["sample"], entry_sig, VEC3, entry_body(mis_sample, lambda e: e)))
        prog.add(b.function(KERNELS["pdf"], entry_sig, VEC3,
                            entry_body(mis_pdf, lambda e: b.construct(VEC3, e, b.const(0.0), b.const(0.0)))))


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



def kernel_programs(sp: SamplingProgram) -> dict:
    """The mixture's KERNELS as eval programs ("sample" / "pdf" -> link.EvalProgram): the eval kernel's
    signature and parameter block (tangent frame passed), so compose.compose_eval and runtime.eval_kernel
    compose, compile and run them as they do a BRDF."""
    from . import EvalProgram, _eval_interface

    rb = sp.rb
    sig = [("L", VEC3)] + sp.signature["sample"][1:5] + [(n, t) for n, _, _, t, _ in sp.kernel_specs.flat]
    slots, count, iface = _eval_interface(sp.kernel_specs, ["L", "V", "N", "T", "B"], [], [rb])
    return {what: EvalProgram(f"{sp.spec};sampling={what}", list(rb.nodes), sp.program, sp.kernel_specs, sig, slots,
                              count, True, iface, entry=entry)
            for what, entry in KERNELS.items()}
