"""One IR program from any set of resolved brick nodes.

Function names are keyed by the canonical node: a brick without fillers or array
counts keeps `<id>_<function>`; any other is `<id>_<6 hex of sha256(canonical)>_<function>`,
so several fillers of one host (microfacet with ggx and with beckmann) coexist in
one program, and the same node always gets the same name.

Slot calls are bound by name (library/kinds.py): the host passes the contract's
arguments positionally; every other parameter of the filler's entry (a shading
input, a parameter or texture of the filler) is threaded: the host functions on
the way to the call gain it as a parameter, bound in turn by their callers, up to
the host's entry, which the glue binds by name.
"""
from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..lang import SourceError, ir
from ..lang.types import Type
from ..library.bricks import Brick
from ..library.kinds import KINDS
from ..spec.permutation import Node


def function_name(node: Node, fname: str) -> str:
    """The linked name of function `fname` of `node` (see the module docstring)."""
    if not node.fillers and not node.counts:
        return f"{node.brick.id}_{fname}"
    digest = hashlib.sha256(node.key.encode()).hexdigest()[:6]
    return f"{node.brick.id}_{digest}_{fname}"


def call_order(module: ir.Module) -> list[str]:
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


@dataclass
class Program:
    """Linked functions (callees first), the structs they use, and the bricks they came from."""

    functions: list[ir.Function] = field(default_factory=list)
    structs: list[Type] = field(default_factory=list)
    globals: list[ir.Global] = field(default_factory=list)  # buffers the glue reads (bindings set by link)
    bricks: dict[str, Brick] = field(default_factory=dict)  # display path -> brick
    by_name: dict[str, ir.Function] = field(default_factory=dict)
    _linked: dict = field(default_factory=dict)  # (kind, canonical) -> {function: linked name}
    lib_memo: dict | None = None  # Library.memo: linked nodes shared between programs of one library
    _struct_from: dict = field(default_factory=dict)  # struct name -> the brick that declared it first

    def add(self, f: ir.Function, brick: Brick | None = None) -> ir.Function:
        """Append one function (callees must already be in the program)."""
        if f.name in self.by_name:
            where = brick.display_path if brick else f.loc.path
            raise SourceError(where, f.loc.line, f.loc.col, f"function name '{f.name}' is generated twice when linking",
                              "two bricks of different kinds share an id and a function name: rename one")
        self.functions.append(f)
        self.by_name[f.name] = f
        return f

    def entry(self, node: Node, fname: str) -> ir.Function:
        """The linked function `fname` of `node` (link it first)."""
        return self.by_name[self._linked[(node.brick.kind, node.key)][fname]]

    def link(self, node: Node) -> None:
        """Add a brick with its fillers (once per canonical node)."""
        for _, filler in node.fillers:
            self.link(filler)
        b = node.brick
        key = (b.kind, node.key)
        if key in self._linked:
            return
        self.bricks[b.display_path] = b
        # A node links to the same functions in every program (names are keyed by canonical node), so the
        # library keeps them: the next program that links this node shares them (linked IR is never
        # mutated after link(); tests/link/test_link.py checks), instead of deep-copying the brick again.
        memo_key = ("link", key, tuple(x.brick.module.source_hash for x in node.tree))
        hit = self.lib_memo.get(memo_key) if self.lib_memo is not None else None
        if hit is not None:
            functions, structs, rename = hit
            for f in functions:
                self.add(f, b)
            self._add_structs(structs, b)
            self._linked[key] = rename
            return
        rename = {name: function_name(node, name) for name in b.module.functions}
        fillers = {slot: filler for slot, filler in node.fillers
                   if KINDS[b.slots[slot]["kind"]].slot}
        fns = {name: ir.clone(b.module.functions[name]) for name in call_order(b.module)}
        extra: dict[str, dict[str, Type]] = {}  # host function -> threaded parameters it gains
        for name, f in fns.items():  # callees first, so a helper's threaded names are known at its callers
            need: dict[str, Type] = {}
            for n in ir.walk_body(f.body):
                if not isinstance(n, ir.Call):
                    continue
                if n.func in fillers:
                    need.update(self._bind_slot(b, n, fillers[n.func]))
                elif n.func in extra:
                    need.update(extra[n.func])
                    n.args = n.args + [ir.Var(t, n.loc, p, "param") for p, t in extra[n.func].items()]
            extra[name] = self._thread(b, f, need)
        for name, f in fns.items():
            for n in ir.walk_body(f.body):
                if isinstance(n, ir.Call) and n.func in rename:
                    n.func = rename[n.func]
            f.calls = [c if c not in rename else rename[c] for c in f.calls]
            f.name = rename[name]
            self.add(f, b)
        self._add_structs(b.module.structs.values(), b)
        self._linked[key] = rename
        if self.lib_memo is not None:
            self.lib_memo[memo_key] = (list(fns.values()), list(b.module.structs.values()), rename)

    def _add_structs(self, structs, brick: Brick) -> None:
        """A brick's structs, once each; two bricks declaring one struct name differently is an error (both would
        reach the shader: a redefinition to every compiler)."""
        for st in structs:
            other = next((s for s in self.structs if s.name == st.name), None)
            if other is None:
                self.structs.append(st)
                self._struct_from[st.name] = brick
            elif other != st:
                first, declared = self._struct_from[st.name], rf"class\s+{st.name}\b"
                raise SourceError(brick.display_path, _line_of(brick, declared), 1,
                                  f"struct '{st.name}' is also declared, differently, by {first.display_path}:"
                                  f"{_line_of(first, declared)}, and both bricks are linked into one shader",
                                  "rename the struct in one of them")

    def _bind_slot(self, host: Brick, call: ir.Call, filler: Node) -> dict[str, Type]:
        """Point a slot call at the filler's entry, its parameters bound by name; returns the threaded ones."""
        kind = KINDS[filler.brick.kind]
        contract = kind.entries[0]
        entry = self.entry(filler, contract.name)
        given = {a.name: arg for a, arg in zip(contract.args, call.args)}
        args, threaded = [], {}
        for p in entry.params:
            if p.name in given:
                args.append(given[p.name])
            else:
                args.append(ir.Var(p.ty, call.loc, p.name, "param"))
                threaded[p.name] = p.ty
        call.func, call.args = entry.name, args
        return threaded

    @staticmethod
    def _thread(b: Brick, f: ir.Function, need: dict[str, Type]) -> dict[str, Type]:
        """Give `f` the parameters `need` it lacks; returns those added."""
        have = {p.name: p for p in f.params}
        local = {n.name for n in ir.walk_body(f.body) if isinstance(n, ir.Decl)}
        added = {}
        for name, ty in need.items():
            if name in have:
                if have[name].ty != ty:
                    raise SourceError(b.display_path, f.loc.line, f.loc.col,
                                      f"'{f.name}' takes {name}: {have[name].ty}, but a slot filler reads {name}: {ty}",
                                      "a shading input or parameter has one type everywhere")
                continue
            if name in local:
                raise SourceError(b.display_path, f.loc.line, f.loc.col,
                                  f"a slot filler reads '{name}', which '{f.name}' uses as a local variable",
                                  f"rename the local '{name}' in {b.display_path}")
            f.params.append(ir.Param(name, ty, f.loc))
            added[name] = ty
        return added


def _line_of(brick: Brick, pattern: str) -> int:
    """The first line of a brick's file that matches `pattern` (1 when none does): for messages."""
    try:
        lines = Path(brick.path).read_text(errors="replace").splitlines()
    except OSError:
        return 1
    return next((i + 1 for i, line in enumerate(lines) if re.match(pattern, line)), 1)
