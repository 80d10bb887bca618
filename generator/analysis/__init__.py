"""Static cost of SPIR-V entry points: instruction classes, scalarized counts, register pressure.

Read from the module's binary words after ``spirv-opt -O`` (which inlines
every function, so an entry point is one function). Counts are static: each
instruction once, wherever it sits in the control flow (both sides of a
branch count; a loop body counts once). Classes and the scalar rules are in
:mod:`generator.analysis.classify`, the register estimate in
:mod:`generator.analysis.liveness`.
"""
from __future__ import annotations

import hashlib
from collections import Counter
from pathlib import Path
from dataclasses import dataclass, field, fields

from .classify import NOT_EXECUTED, count_rows, storage_class
from .liveness import analyze_function
from .spirv import Module, SpirvError, read

__all__ = ["Cost", "analyze", "entry_cost", "cost_dict", "SpirvError", "read"]

# Cost fields in report order; "alu" etc. are instruction counts, "*_scalar" scalarized counts.
COUNT_FIELDS = ("instructions", "alu", "transcendental", "texture", "branches", "loads", "stores", "other",
                "alu_scalar", "transcendental_scalar", "loads_scalar", "stores_scalar", "registers", "calls")
_CLASS_FIELD = {"alu": "alu", "transcendental": "transcendental", "texture": "texture", "branch": "branches",
                "load": "loads", "store": "stores", "other": "other"}


@dataclass
class Cost:
    """Static cost of one entry point (or a difference of two: fields may then be negative)."""

    instructions: int = 0     # every instruction executed as code (merge declarations excluded)
    alu: int = 0
    transcendental: int = 0
    texture: int = 0
    branches: int = 0         # conditional branches
    loads: int = 0
    stores: int = 0
    other: int = 0            # moves, shuffles, phis, access chains, jumps, returns
    alu_scalar: int = 0
    transcendental_scalar: int = 0
    loads_scalar: int = 0     # 32-bit components loaded
    stores_scalar: int = 0
    registers: int = 0        # peak live 32-bit scalars (an estimate: see generator.analysis.liveness)
    calls: int = 0            # OpFunctionCall left after optimization (0 when fully inlined)
    opcodes: dict = field(default_factory=dict)           # histogram: "OpFMul" / "Exp" -> count
    loads_by_storage: dict = field(default_factory=dict)  # "Uniform" / "Input" / ... -> load count

    def __add__(self, other: "Cost") -> "Cost":
        return _combine(self, other, 1)

    def __sub__(self, other: "Cost") -> "Cost":
        return _combine(self, other, -1)

    def as_dict(self, histograms: bool = True) -> dict:
        """Plain JSON-ready dict (histograms sorted, zero entries dropped; left out unless `histograms`)."""
        d = {f: getattr(self, f) for f in COUNT_FIELDS}
        if not histograms:
            return d
        d["opcodes"] = {k: v for k, v in sorted(self.opcodes.items()) if v}
        d["loads_by_storage"] = {k: v for k, v in sorted(self.loads_by_storage.items()) if v}
        return d


def _combine(a: Cost, b: Cost, sign: int) -> Cost:
    out = Cost(**{f.name: getattr(a, f.name) + sign * getattr(b, f.name)
                  for f in fields(Cost) if f.name in COUNT_FIELDS})
    for name in ("opcodes", "loads_by_storage"):
        c = Counter(getattr(a, name))
        for k, v in getattr(b, name).items():
            c[k] += sign * v
        setattr(out, name, {k: v for k, v in sorted(c.items()) if v})
    return out


def _function_cost(mod: Module, fn_id: int, memo: dict[int, Cost]) -> Cost:
    """Own instructions plus, per call site, the callee's cost (as if inlined); peak registers."""
    if fn_id in memo:
        return memo[fn_id]
    fn = mod.functions[fn_id]
    cost = Cost()
    # Each instruction's figures as a tuple; the distinct tuples counted, then summed once each (keys and
    # classes taken in the order of their first instruction, as counting one by one would).
    body = [ins for block in fn.blocks for ins in block.body if ins.name not in NOT_EXECUTED]
    rows = count_rows(mod, body)
    ops: dict[str, int] = {}
    classes = dict.fromkeys(_CLASS_FIELD, 0)
    alu = transcendental = loads = stores = 0
    for (cls, key, a, t, ld, st), n in Counter(rows).items():
        classes[cls] += n
        ops[key] = ops.get(key, 0) + n
        alu += a * n
        transcendental += t * n
        loads += ld * n
        stores += st * n
    for cls, n in classes.items():
        setattr(cost, _CLASS_FIELD[cls], n)
    cost.instructions = len(rows)
    cost.alu_scalar, cost.transcendental_scalar, cost.loads_scalar, cost.stores_scalar = \
        alu, transcendental, loads, stores
    cost.opcodes = ops
    cost.loads_by_storage = dict(Counter([storage_class(mod, ins.words[2]) for ins, row in zip(body, rows)
                                          if row[0] == "load" and ins.name == "Load"]))
    callees = [ins.operands[0] for ins in body if ins.name == "FunctionCall"]
    cost.calls = len(callees)
    memo[fn_id] = cost  # placeholder against (invalid) recursion
    peaks = {}
    for callee in callees:
        sub = _function_cost(mod, callee, memo)
        peaks[callee] = sub.registers
        registers = cost.registers
        cost = cost + sub
        cost.registers = registers
    cost.registers = analyze_function(mod, fn, peaks).peak
    memo[fn_id] = cost
    return cost


def analyze(spirv: bytes) -> dict[str, Cost]:
    """Cost of every entry point of a SPIR-V module, by entry-point name."""
    from ..io.bulk import collector_paused

    # The analysis makes several small containers per instruction, none cyclic, all freed on return: the
    # cyclic collector, run by their count, would walk them in vain (measured: ~8 % of the analysis).
    with collector_paused():
        mod = read(spirv)
        memo: dict[int, Cost] = {}
        return {name: _function_cost(mod, fid, memo) for name, (_, fid) in sorted(mod.entry_points.items())}


def entry_cost(spirv: bytes, entry: str | None = None) -> Cost:
    """Cost of one entry point (the only one when `entry` is None)."""
    costs = analyze(spirv)
    if entry is None:
        if len(costs) != 1:
            raise SpirvError(f"module has {len(costs)} entry points ({', '.join(costs)}); name one")
        return next(iter(costs.values()))
    if entry not in costs:
        raise SpirvError(f"no entry point '{entry}' (found: {', '.join(costs) or 'none'})")
    return costs[entry]


# Every analysis source file: a change to a rule changes every cached figure's key.
_RULES_HASH = hashlib.sha256(b"".join(
    p.read_bytes() for p in sorted(Path(__file__).resolve().parent.glob("*.py")))).hexdigest()
COST_NAMESPACE = "cost-v2"


def cost_dict(spirv: bytes, store=None) -> dict:
    """``entry_cost(spirv).as_dict(histograms=False)``, served from an io.Store when it holds it (keyed by the
    SPIR-V's sha256 and the analysis rules' sources) and put there when it did not."""
    import json

    from ..io import content_key
    key = content_key(COST_NAMESPACE, hashlib.sha256(spirv).hexdigest(), _RULES_HASH)
    if store is not None:
        data = store.get(COST_NAMESPACE, key)
        if data is not None:
            try:
                return json.loads(data)
            except ValueError:
                pass
    d = entry_cost(spirv).as_dict(histograms=False)
    if store is not None:
        store.put(COST_NAMESPACE, key, json.dumps(d).encode())  # in as_dict order: the manifest keeps it
    return d
