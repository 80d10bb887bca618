"""Switches and runtime-bounded loops in the numpy target (a mixin of emit.py's _FunctionEmitter).

Both run under masks, like `if`: a switch evaluates its selector once, computes one
mask per case (and the default's, the lanes no case takes) and runs every body for
its lanes; a loop `for i in range(n)` with a per-lane n runs to the largest n over
the lanes (0 if none is positive) with the body masked to `i < n`.
"""
from __future__ import annotations

from ...lang import ir


class ControlEmitter:
    def masked_bodies(self, arms) -> None:
        """Run each (mask, body) one level down, under its mask."""
        parent = self.mask
        self.level += 1
        for mask, body in arms:
            if mask is not None and body:
                self.mask = mask
                self.scopes.append({})
                for st in body:
                    self.stmt(st)
                self.scopes.pop()
        self.level -= 1
        self.mask = parent

    def switch_stmt(self, s: ir.Switch) -> None:
        sel = self.fresh("s")
        self.line(f"{sel} = {self.expr(s.selector)}", s.loc)
        dt = "np.uint32" if s.selector.ty.scalar == "uint" else "np.int32"
        taken = []
        arms = []
        for values, body in s.cases:
            c = self.fresh("c")
            test = " | ".join(f"({sel} == {dt}({int(v)}))" for v in values) or "np.False_"
            self.line(f"{c} = {test}", s.loc)
            taken.append(c)
            arms.append((self.under(c, s.loc), body))
        if s.default:
            d = self.fresh("c")
            self.line(f"{d} = ~({' | '.join(taken)})" if taken else f"{d} = np.True_", s.loc)
            arms.append((self.under(d, s.loc), s.default))
        self.masked_bodies(arms)

    def under(self, cond: str, loc) -> str:
        """The mask for `cond` within the current mask."""
        if self.mask is None:
            return cond
        m = self.fresh("m")
        self.line(f"{m} = {self.mask} & {cond}", loc)
        return m

    def runtime_for(self, s: ir.For) -> None:
        b = self.fresh("b")
        dt = "np.uint32" if s.var_type.scalar == "uint" else "np.int32"
        var = self.t.ident(s.var)
        self.line(f"{b} = {self.expr(s.bound)}", s.loc)
        self.line(f"for {var} in _range(_bmax({b}), {dt}):", s.loc)
        self.depth += 1
        c = self.fresh("c")
        self.line(f"{c} = {var} < {b}", s.loc)
        mask = self.under(c, s.loc)
        self.scopes.append({s.var: self.level})
        self.masked_bodies([(mask, s.body)])
        if not s.body:
            self.line("pass", None)
        self.scopes.pop()
        self.depth -= 1


def returns_under_mask(stmts, inside=False) -> bool:
    """Does a return run under a mask (in a branch, a case or a runtime loop), so lanes finish apart?"""
    for s in stmts:
        if isinstance(s, ir.Return) and inside:
            return True
        if isinstance(s, ir.If) and (returns_under_mask(s.then, True) or returns_under_mask(s.orelse, True)):
            return True
        if isinstance(s, ir.Switch) and any(returns_under_mask(b, True) for b in [*(b for _, b in s.cases), s.default]):
            return True
        if isinstance(s, ir.For) and returns_under_mask(s.body, inside or s.bound is not None):
            return True
    return False
