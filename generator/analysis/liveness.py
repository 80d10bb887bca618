"""Liveness over a function's control-flow graph and the register-pressure estimate.

SSA liveness with phis: a phi's operand is live at the end of the
predecessor it comes from, the phi's result from the top of its block. The
live sets are solved to a fixpoint (loops carry values around the back
edge). Pressure is then the largest total width, in 32-bit scalar
components, of the values live at any point: just before and just after
each instruction (a result that is never read still takes its register for
that moment).

What counts as a value: every result of an instruction inside the function
and every parameter, of a numeric or boolean type (a vec3 is 3, a mat4 16,
a bool 1, a 64-bit scalar 2). Not counted: constants and OpUndef (a GPU
takes them as immediates or from constant memory), pointers (variables and
access chains: addressing is folded into the load or store that uses them,
so a pointer's dynamic indices stay live until that use instead), and
opaque handles (images, samplers). A value loaded from a uniform counts
like any other value while it is live (loaded once, it occupies its
components until its last use). At a call, the callee's own peak is added
to what stays live across the call.

It is an estimate: drivers reschedule, rematerialize, keep uniform values
in scalar registers and pack 16-bit values, so real register counts differ;
it ranks permutations and bricks, it does not predict occupancy.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from .spirv import Function, Instruction, Module, successors

POINTER_OPS = {"AccessChain", "InBoundsAccessChain", "PtrAccessChain", "InBoundsPtrAccessChain"}
_IMAGE_FIXED = {"ImageSampleImplicitLod": 2, "ImageSampleExplicitLod": 2, "ImageSampleDrefImplicitLod": 3,
                "ImageSampleDrefExplicitLod": 3, "ImageSampleProjImplicitLod": 2,
                "ImageSampleProjExplicitLod": 2, "ImageSampleProjDrefImplicitLod": 3,
                "ImageSampleProjDrefExplicitLod": 3, "ImageFetch": 2, "ImageGather": 3, "ImageDrefGather": 3,
                "ImageRead": 2, "ImageSparseSampleImplicitLod": 2, "ImageSparseSampleExplicitLod": 2,
                "ImageSparseSampleDrefImplicitLod": 3, "ImageSparseSampleDrefExplicitLod": 3,
                "ImageSparseFetch": 2, "ImageSparseGather": 3, "ImageSparseDrefGather": 3, "ImageSparseRead": 2}


_NONE: frozenset = frozenset()


def _image_ids(k: int):
    return lambda ops, w: list(ops[:k]) + list(ops[k + 1:])


# How each instruction that is not "all operands after the result" names its ids: (operands, words) -> ids.
_ID_RULES = {
    "VectorShuffle": lambda ops, w: list(ops[:2]),
    "CompositeInsert": lambda ops, w: list(ops[:2]),
    "CompositeExtract": lambda ops, w: list(ops[:1]),
    "ExtInst": lambda ops, w: list(ops[2:]),
    **dict.fromkeys(("Switch", "BranchConditional", "ReturnValue"), lambda ops, w: [w[0]]),
    **dict.fromkeys(("Branch", "SelectionMerge", "LoopMerge", "Label"), lambda ops, w: []),
    **dict.fromkeys(("Load", "AtomicLoad"), lambda ops, w: list(ops[:1])),
    **dict.fromkeys(("Store", "CopyMemory", "CopyMemorySized"), lambda ops, w: list(w[:2])),
    "ImageWrite": lambda ops, w: list(w[:3]) + list(w[4:]),
    **{n: _image_ids(k) for n, k in _IMAGE_FIXED.items()},
    "Phi": lambda ops, w: list(ops[0::2]),
    "Variable": lambda ops, w: list(ops[1:]),
    "FunctionCall": lambda ops, w: list(ops[1:]),
}


def id_operands(ins: Instruction) -> list[int]:
    """The operands of an instruction that are ids (literals, labels and masks left out)."""
    rule = _ID_RULES.get(ins.name)
    if rule is not None:
        return rule(ins.operands, ins.words)
    return list(ins.operands) if ins.type_id or ins.result else list(ins.words)


@dataclass
class Liveness:
    """Live values (ids) at the top and bottom of each block, and the peak pressure."""

    live_in: dict[int, frozenset]    # block label -> values live at its top (its live phis included)
    live_out: dict[int, frozenset]   # block label -> values live at its end (phi operands included)
    peak: int                        # max live 32-bit scalars anywhere in the function
    peak_block: int                  # a block where the peak is reached


class _Values:
    """The function's values (id -> width) and what each pointer's address uses."""

    def __init__(self, mod: Module, fn: Function):
        widths: dict[int, int] = {}
        for p in fn.params:
            widths[p.result] = mod.width(p.type_id)
        ptr_deps: dict[int, tuple] = {}
        type_width = mod.type_widths
        for b in fn.blocks:
            for ins in b.body:
                if ins.name in POINTER_OPS:
                    ptr_deps[ins.result] = tuple(id_operands(ins))
                elif ins.type_id:
                    widths[ins.result] = type_width[ins.type_id]
        self.widths = {k: v for k, v in widths.items() if v > 0}
        self.ptr_deps = ptr_deps
        # One look-up per operand: the values an id stands for (itself when a value, what its address uses
        # when a pointer); ids that are neither (constants, globals, labels) are absent.
        self.lookup = {p: tuple(self.pointer_uses(p)) for p in ptr_deps}
        self.lookup.update((v, (v,)) for v in self.widths)

    def uses(self, ids) -> list[int]:
        """The values among `ids`, a pointer standing for the values its address uses (a value may come more
        than once). The same values as one walk over all of them: a pointer's own are worked out once."""
        out: list[int] = []
        lookup = self.lookup
        for i in ids:
            t = lookup.get(i)
            if t:
                out += t
        return out

    def pointer_uses(self, pointer: int) -> set[int]:
        """The values a pointer's address uses (through the access chains it is made of)."""
        out: set[int] = set()
        stack, seen = [pointer], set()
        while stack:
            i = stack.pop()
            if i in self.widths:
                out.add(i)
            elif i in self.ptr_deps and i not in seen:
                seen.add(i)
                stack.extend(self.ptr_deps[i])
        return out

    def block_rows(self, body: list[Instruction], callee_peak: dict[int, int]):
        """A block's instructions bottom to top as (value defined or None, its width, values used, callee
        peak), phis left out, with the block's upward-exposed uses (gen) and definitions (kill): the backward
        walk from a live-out set L ends with gen | (L - kill) live at the top. A value may be listed twice
        among an instruction's uses: adding it to a live set twice is adding it once. Last, the values its
        phis define and their (value, predecessor) pairs."""
        widths, lookup, rules = self.widths, self.lookup, _ID_RULES
        rows, gen, kill, phi_defs, phi_pairs = [], set(), set(), set(), []
        for ins in reversed(body):
            name = ins.name
            if name == "Phi":
                if ins.result in widths:
                    phi_defs.add(ins.result)
                ops = ins.operands
                phi_pairs += zip(ops[0::2], ops[1::2])
                continue
            rule = rules.get(name)  # id_operands, inlined: this runs for every instruction
            ids = (ins.operands if ins.type_id or ins.result else ins.words) if rule is None \
                else rule(ins.operands, ins.words)
            used: list[int] = []  # uses(ids), inlined
            for i in ids:
                t = lookup.get(i)
                if t:
                    used += t
            r = ins.result
            if r in widths:
                d, wd = r, widths[r]
                gen.discard(r)
                kill.add(r)
            else:
                d, wd = None, 0
            gen.update(used)
            extra = callee_peak.get(ins.operands[0], 0) if name == "FunctionCall" else 0
            rows.append((d, wd, used, extra if extra > 0 else 0))
        return rows, gen, kill, phi_defs, phi_pairs


def analyze_function(mod: Module, fn: Function, callee_peak: dict[int, int] | None = None) -> Liveness:
    """Liveness and peak register pressure of one function (callee peaks for its calls)."""
    callee_peak = callee_peak or {}
    values = _Values(mod, fn)
    widths = values.widths

    blocks = {b.label: b for b in fn.blocks}
    succ = {b.label: [s for s in successors(mod, b) if s in blocks] for b in fn.blocks}
    rows, phi_defs = {}, {}
    phi_uses: dict[tuple[int, int], set[int]] = {}  # edge (pred, block) -> values the block's phis read from pred
    for b in fn.blocks:
        block_rows, gen, kill, phi_defs[b.label], phi_pairs = values.block_rows(b.body, callee_peak)
        rows[b.label] = block_rows, gen, kill
        for value, pred in phi_pairs:
            phi_uses.setdefault((pred, b.label), set()).update(values.uses([value]))

    order = _postorder(fn.blocks[0].label, succ) if fn.blocks else []
    reached = set(order)
    order += [b.label for b in fn.blocks if b.label not in reached]  # unreachable blocks last
    live_in: dict[int, set | frozenset] = {label: frozenset() for label in blocks}
    live_out: dict[int, set | frozenset] = {label: frozenset() for label in blocks}
    # A worklist from postorder: a block is worked out again only when a successor's top changed (a block's
    # top is gen | (out - kill)). The transfer is monotone, so this reaches the same least fixpoint as sweeping
    # every block until none changes, with fewer visits (a loop no longer sweeps the whole function again).
    edges = {label: [(s, phi_defs[s], phi_uses.get((label, s), _NONE)) for s in succ[label]] for label in order}
    preds: dict[int, list[int]] = {label: [] for label in blocks}
    for label, targets in succ.items():
        for s in targets:
            preds[s].append(label)
    work, pending = deque(order), set(order)
    while work:
        label = work.popleft()
        pending.discard(label)
        es = edges[label]
        if len(es) == 1 and not es[0][1] and not es[0][2]:
            out = live_in[es[0][0]]  # shared, never changed in place
        else:
            out = set()
            for s, defs, from_phis in es:
                out |= live_in[s] - defs if defs else live_in[s]
                out |= from_phis
        live_out[label] = out
        _, gen, kill = rows[label]
        top = gen | (out - kill) if kill else gen | out
        if top != live_in[label]:
            live_in[label] = top
            for p in preds[label]:
                if p not in pending:
                    pending.add(p)
                    work.append(p)

    peak, peak_block = 0, fn.blocks[0].label if fn.blocks else 0
    for label in blocks:
        p = _block_peak(rows[label][0], live_out[label], widths)
        if p > peak:
            peak, peak_block = p, label
    return Liveness({k: frozenset(v) for k, v in live_in.items()}, {k: frozenset(v) for k, v in live_out.items()},
                    peak, peak_block)


def _block_peak(rows, live_out, widths: dict[int, int]) -> int:
    """Walk a block backward from its live-out set: the widest live set just before and just after each
    instruction. The width is kept as values enter and leave, not summed again per instruction."""
    live = set(live_out)
    w = 0
    for v in live:
        w += widths[v]
    peak = w
    for d, wd, used, extra in rows:
        if d in live:  # live above its definition: no longer
            live.remove(d)
            w -= wd
        c = w + wd + extra  # the result takes its register (with a call, the callee's peak on top)
        if c > peak:
            peak = c
        for u in used:
            if u not in live:
                live.add(u)
                w += widths[u]
        if w > peak:
            peak = w
    return peak


def _postorder(entry: int, succ: dict[int, list[int]]) -> list[int]:
    """Blocks reachable from entry in depth-first postorder (iterative: no recursion limit)."""
    seen, order = {entry}, []
    stack = [(entry, iter(succ[entry]))]
    while stack:
        node, it = stack[-1]
        for s in it:
            if s not in seen:
                seen.add(s)
                stack.append((s, iter(succ[s])))
                break
        else:
            order.append(node)
            stack.pop()
    return order
