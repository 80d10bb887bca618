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


def id_operands(ins: Instruction) -> list[int]:
    """The operands of an instruction that are ids (literals, labels and masks left out)."""
    n, ops, w = ins.name, ins.operands, ins.words
    if n == "VectorShuffle" or n == "CompositeInsert":
        return list(ops[:2])
    if n == "CompositeExtract":
        return list(ops[:1])
    if n == "ExtInst":
        return list(ops[2:])
    if n in ("Switch", "BranchConditional", "ReturnValue"):
        return [w[0]]
    if n in ("Branch", "SelectionMerge", "LoopMerge", "Label"):
        return []
    if n in ("Load", "AtomicLoad"):
        return list(ops[:1])
    if n in ("Store", "CopyMemory", "CopyMemorySized"):
        return list(w[:2])
    if n == "ImageWrite":
        return list(w[:3]) + list(w[4:])
    if n in _IMAGE_FIXED:
        k = _IMAGE_FIXED[n]
        return list(ops[:k]) + list(ops[k + 1:])
    if n == "Phi":
        return list(ops[0::2])
    if n == "Variable":
        return list(ops[1:])
    if n == "FunctionCall":
        return list(ops[1:])
    return list(ops) if ins.type_id or ins.result else list(w)


@dataclass
class Liveness:
    """Live values (ids) at the top and bottom of each block, and the peak pressure."""

    live_in: dict[int, frozenset]    # block label -> values live at its top (its live phis included)
    live_out: dict[int, frozenset]   # block label -> values live at its end (phi operands included)
    peak: int                        # max live 32-bit scalars anywhere in the function
    peak_block: int                  # a block where the peak is reached


def analyze_function(mod: Module, fn: Function, callee_peak: dict[int, int] | None = None) -> Liveness:
    """Liveness and peak register pressure of one function (callee peaks for its calls)."""
    callee_peak = callee_peak or {}
    widths: dict[int, int] = {}
    for p in fn.params:
        widths[p.result] = mod.width(p.type_id)
    ptr_deps: dict[int, tuple] = {}
    for b in fn.blocks:
        for ins in b.body:
            if ins.name in POINTER_OPS:
                ptr_deps[ins.result] = tuple(id_operands(ins))
            elif ins.type_id:
                widths[ins.result] = mod.width(ins.type_id)
    widths = {k: v for k, v in widths.items() if v > 0}

    def uses(ids) -> set[int]:
        out: set[int] = set()
        stack, seen = list(ids), set()
        while stack:
            i = stack.pop()
            if i in widths:
                out.add(i)
            elif i in ptr_deps and i not in seen:  # a pointer stands for the values its address uses
                seen.add(i)
                stack.extend(ptr_deps[i])
        return out

    def width(values) -> int:
        return sum(widths[v] for v in values)

    blocks = {b.label: b for b in fn.blocks}
    succ = {b.label: [s for s in successors(mod, b) if s in blocks] for b in fn.blocks}
    phi_defs = {b.label: {i.result for i in b.body if i.name == "Phi" and i.result in widths} for b in fn.blocks}
    # edge (pred, block) -> values the block's phis read from pred
    phi_uses: dict[tuple[int, int], set[int]] = {}
    for b in fn.blocks:
        for ins in b.body:
            if ins.name == "Phi":
                ops = ins.operands
                for value, pred in zip(ops[0::2], ops[1::2]):
                    phi_uses.setdefault((pred, b.label), set()).update(uses([value]))

    order = _postorder(fn.blocks[0].label, succ) if fn.blocks else []
    order += [b.label for b in fn.blocks if b.label not in order]  # unreachable blocks last
    live_in = {label: frozenset() for label in blocks}
    live_out = {label: frozenset() for label in blocks}

    def scan(label: int):
        """Walk a block backward from its live-out set; returns (live at top, peak in block). The width of the
        live set is kept as it changes (one value in or out at a time), not summed again per instruction."""
        live = set(live_out[label])
        w = width(live)
        peak = w
        for ins in reversed(blocks[label].body):
            if ins.name == "Phi":
                continue
            d = ins.result if ins.result in widths else None
            if d is not None and d in live:  # live above its definition: no longer
                live.discard(d)
                w -= widths[d]
            wd = widths[d] if d is not None else 0
            if ins.name == "FunctionCall":
                peak = max(peak, w + callee_peak.get(ins.operands[0], 0) + wd)
            peak = max(peak, w + wd)
            for u in uses(id_operands(ins)):
                if u not in live:
                    live.add(u)
                    w += widths[u]
            peak = max(peak, w)
        return live, peak

    changed = True
    while changed:
        changed = False
        for label in order:
            out = set()
            for s in succ[label]:
                out |= live_in[s] - phi_defs[s]
                out |= phi_uses.get((label, s), set())
            live_out[label] = frozenset(out)
            top, _ = scan(label)
            top = frozenset(top)
            if top != live_in[label]:
                live_in[label] = top
                changed = True

    peak, peak_block = 0, fn.blocks[0].label if fn.blocks else 0
    for label in blocks:
        _, p = scan(label)
        if p > peak:
            peak, peak_block = p, label
    return Liveness(live_in, live_out, peak, peak_block)


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
