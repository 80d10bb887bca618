"""Lowering of loops and switches: `for i in range(N or n)` and `match x: case ...`.

A mixin of the statement checker (generator/lang/typecheck.py), which provides
scopes, block(), expr(), err() and constants.

    for i in range(4):        constant count (ir.For.count)
    for i in range(n):        runtime bound, n an int or uint expression (ir.For.bound);
                              i is uint when n is; the body must not assign what n reads
    match k:                  k int or uint
        case 0:               integer literals (negative ones too), alternatives with |
        case 1 | 2:
        case _:               the default (last, at most once)

Python treats a bare name in a case as a capture pattern, so case values are
literals; `case N:` naming a module constant is rejected with a hint.
"""
from __future__ import annotations

import ast

from . import ir
from .annotations import check_identifier
from .types import INT, UINT


class ControlChecker:
    # ------------------------------------------------------------ for
    def for_loop(self, n: ast.For):
        ok = (isinstance(n.iter, ast.Call) and isinstance(n.iter.func, ast.Name) and n.iter.func.id == "range"
              and len(n.iter.args) == 1 and not n.iter.keywords and isinstance(n.target, ast.Name) and not n.orelse)
        if not ok:
            raise self.err(n, "only `for i in range(N)` loops are allowed",
                           "N is an int constant, or an int or uint expression")
        count_node = n.iter.args[0]
        count, bound = None, None
        if isinstance(count_node, ast.Constant) and type(count_node.value) is int:
            count = count_node.value
        elif isinstance(count_node, ast.Name) and count_node.id in self.constants and self.constants[count_node.id].ty == INT:
            count = self.constants[count_node.id].value
        elif not (isinstance(count_node, ast.UnaryOp) and isinstance(count_node.operand, ast.Constant)):
            bound = self.expr(count_node)
            if bound.ty not in (INT, UINT):
                raise self.err(count_node, f"the loop bound is {bound.ty}: it must be a non-negative int constant "
                               "or an int or uint expression", "convert it, e.g. range(int(x)), or use a constant")
            if isinstance(bound, ir.Const):
                count, bound = bound.value, None
        if bound is None and (count is None or count < 0):
            raise self.err(count_node, "the loop count must be a non-negative int constant",
                           "write range(4) or range(N) with N = 4 at the top of the brick")
        if bound is None and count >= 2**31:
            raise self.err(count_node, f"the loop count {count} does not fit in 32 bits",
                           "a loop runs at most 2147483647 times (a shader's int)")
        check_identifier(self.path, n.target, n.target.id)
        if self.lookup(n.target.id) is not None:
            raise self.err(n.target, f"loop variable '{n.target.id}' is already declared", "use a new name")
        var_ty = UINT if bound is not None and bound.ty == UINT else INT
        self.scopes.append({n.target.id: (var_ty, "loopvar")})
        body = self.block(n.body)
        self.scopes.pop()
        if bound is not None:
            read = {v.name for v in ir.walk(bound) if isinstance(v, ir.Var) and v.scope in ("local", "param")}
            for s in ir.walk_body(body):
                if isinstance(s, ir.Assign) and _root(s.target) in read:
                    raise self.err(count_node, f"the loop body assigns '{_root(s.target)}', which the bound reads "
                                   f"(line {s.loc.line})",
                                   "copy the bound into a local before the loop: n_iter = n")
            return ir.For(self.loc(n), n.target.id, 0, body, bound)
        return ir.For(self.loc(n), n.target.id, count, body)

    # ------------------------------------------------------------ match
    def match_stmt(self, n: ast.Match) -> ir.Switch:
        sel = self.expr(n.subject)
        if sel.ty not in (INT, UINT):
            raise self.err(n.subject, f"match selects on an int or uint, not {sel.ty}",
                           "convert the selector, e.g. match int(x), or use if/elif")
        cases: list[tuple[tuple[int, ...], list[ir.Stmt]]] = []
        default = None
        seen: dict[int, int] = {}
        for c in n.cases:
            if c.guard is not None:
                raise self.err(c.guard, "case guards (case ... if ...) are not allowed",
                               "test the condition with an if inside the case")
            values = self.case_values(c.pattern, sel.ty)
            body = self.block(c.body)
            if values is None:
                if default is not None:
                    raise self.err(c.pattern, "a second default case", "keep one `case _:`")
                default = body
                continue
            for v, node in values:
                if v in seen:
                    raise self.err(node, f"case value {v} appears twice (first on line {seen[v]})",
                                   "each value selects one case; remove the duplicate")
                seen[v] = getattr(node, "lineno", 1)
            cases.append((tuple(v for v, _ in values), body))
        return ir.Switch(self.loc(n), sel, cases, default if default is not None else [])

    def case_values(self, p, ty):
        """[(value, node), ...] of one case pattern, or None for the default `case _`."""
        if isinstance(p, ast.MatchAs) and p.pattern is None and p.name is None:
            return None
        if isinstance(p, ast.MatchOr):
            out = []
            for alt in p.patterns:
                got = self.case_values(alt, ty)
                if got is None:
                    raise self.err(alt, "`_` inside an alternative", "write `case _:` on its own")
                out += got
            return out
        if isinstance(p, ast.MatchValue):
            v, node = p.value, p.value
            sign = 1
            if isinstance(v, ast.UnaryOp) and isinstance(v.op, ast.USub):
                sign, v = -1, v.operand
            if isinstance(v, ast.Constant) and type(v.value) is int:
                value = sign * v.value
                lo, hi = (0, 2**32 - 1) if ty == UINT else (-2**31, 2**31 - 1)
                if not lo <= value <= hi:
                    raise self.err(node, f"case value {value} is outside the range of {ty}", "use a value that fits")
                return [(value, node)]
        if isinstance(p, ast.MatchAs) and p.pattern is None and p.name in self.constants:
            raise self.err(p, f"`case {p.name}:` would bind a new name in Python, not compare with the constant",
                           f"write the value ({self.constants[p.name].value}) with a comment naming it")
        raise self.err(p, f"'{ast.unparse(p)}' is not a case value",
                       "write an integer literal, alternatives like `case 1 | 2:`, or `case _:`")


def _root(e: ir.Expr) -> str:
    while not isinstance(e, ir.Var):
        e = e.base
    return e.name


def always_returns(body: list[ir.Stmt]) -> bool:
    """Every path through `body` ends in a return (the last statement decides)."""
    if not body:
        return False
    last = body[-1]
    if isinstance(last, ir.Return):
        return True
    if isinstance(last, ir.If):
        return always_returns(last.then) and always_returns(last.orelse)
    if isinstance(last, ir.Switch):
        return always_returns(last.default) and all(always_returns(b) for _, b in last.cases)
    return False
