"""Typed IR construction for the glue: small constructors, so glue is built as nodes, never as text."""
from __future__ import annotations


from ..lang import ir
from ..lang.types import BOOL, FLOAT, Type

GLUE_PATH = "<glue>"


class Builder:
    """Makes IR nodes; each statement gets the next line of the glue's pseudo-file (for line maps)."""

    def __init__(self, path: str = GLUE_PATH):
        self.path = path
        self.line = 0

    def loc(self) -> ir.Loc:
        self.line += 1
        return ir.Loc(self.path, self.line, 1)

    def here(self) -> ir.Loc:
        return ir.Loc(self.path, max(self.line, 1), 1)

    # ---- expressions
    def var(self, name: str, ty: Type, scope: str = "local") -> ir.Var:
        return ir.Var(ty, self.here(), name, scope)

    def const(self, value: float) -> ir.Const:
        return ir.Const(FLOAT, self.here(), float(value))

    def named_const(self, name: str) -> ir.Var:
        return ir.Var(FLOAT, self.here(), name, "const")

    def call(self, f: ir.Function, args: list[ir.Expr]) -> ir.Call:
        assert len(args) == len(f.params), (f.name, [p.name for p in f.params], len(args))
        for p, a in zip(f.params, args):
            assert p.ty == a.ty, (f.name, p.name, p.ty, a.ty)
        return ir.Call(f.ret, self.here(), f.name, list(args))

    def arith(self, op: str, a: ir.Expr, b: ir.Expr) -> ir.Binary:
        ty = a.ty if a.ty.kind != "scalar" else b.ty
        return ir.Binary(ty, self.here(), op, a, b)

    def compare(self, op: str, a: ir.Expr, b: ir.Expr) -> ir.Binary:
        return ir.Binary(BOOL, self.here(), op, a, b)

    def intrinsic(self, name: str, ty: Type, *args: ir.Expr) -> ir.Intrinsic:
        return ir.Intrinsic(ty, self.here(), name, list(args))

    def construct(self, ty: Type, *args: ir.Expr) -> ir.Construct:
        return ir.Construct(ty, self.here(), list(args))

    def copy(self, e: ir.Expr) -> ir.Expr:
        """A fresh copy of a shared expression (IR trees are not shared between statements)."""
        return ir.clone(e)

    # ---- statements
    def decl(self, name: str, value: ir.Expr) -> ir.Decl:
        return ir.Decl(self.loc(), name, value.ty, value)

    def assign(self, target: ir.Expr, value: ir.Expr, op: str | None = None) -> ir.Assign:
        return ir.Assign(self.loc(), target, op, value)

    def ret(self, value: ir.Expr) -> ir.Return:
        return ir.Return(self.loc(), value)

    def if_(self, cond: ir.Expr, then: list[ir.Stmt], orelse: list[ir.Stmt] | None = None) -> ir.If:
        return ir.If(self.loc(), cond, then, orelse or [])

    def _renumber(self, stmts: list[ir.Stmt]) -> None:
        for s in stmts:
            s.loc = self.loc()
            if isinstance(s, ir.If):
                self._renumber(s.then)
                self._renumber(s.orelse)
            elif isinstance(s, ir.For):
                self._renumber(s.body)
            elif type(s).__name__ == "Switch":
                for _, body in s.cases:
                    self._renumber(body)
                self._renumber(s.default)

    def function(self, name: str, params: list[tuple[str, Type]], ret: Type, body_fn, doc: str = "") -> ir.Function:
        """A function whose body `body_fn()` builds; its statements are numbered in emission order."""
        first = self.line
        body = body_fn()
        self.line = first  # number the statements in the order they are emitted: one #line per function
        loc = self.loc()
        self._renumber(body)
        calls = []
        for n in ir.walk_body(body):
            if isinstance(n, ir.Call) and n.func not in calls:
                calls.append(n.func)
        return ir.Function(name, [ir.Param(n, t, loc) for n, t in params], ret, body, loc, doc, calls)
