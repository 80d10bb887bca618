"""Lowering of function bodies (ast) to typed IR: functions, scopes and statements.

Expressions are typed by generator/lang/exprs.py (ExprChecker, a base class);
loops and switches by generator/lang/control.py (ControlChecker).
"""
from __future__ import annotations

import ast

from . import ir
from .errors import SourceError
from .control import ControlChecker, always_returns
from .annotations import check_identifier, parse_type
from .exprs import ARITH, ExprChecker
from .intrinsics import CONSTANTS, INTRINSICS
from .types import BOOL, BUILTIN_TYPES, Type


class Checker(ControlChecker, ExprChecker):
    """Lowers one function; holds its scopes. `globals`: the module's resources {name: ir.Global}."""

    def __init__(self, path, structs, constants, sigs, externals, globals=None):
        self.path, self.structs, self.constants = path, structs, constants
        self.sigs, self.externals = sigs, externals
        self.globals: dict[str, ir.Global] = dict(globals or {})
        self.scopes: list[dict[str, tuple[Type, str]]] = []
        self.params: dict[str, ir.Param] = {}
        self.calls: list[str] = []
        self.ret: Type | None = None

    # ------------------------------------------------------------ helpers
    def loc(self, node) -> ir.Loc:
        return ir.Loc(self.path, getattr(node, "lineno", 1), getattr(node, "col_offset", 0) + 1)

    def err(self, node, message, hint=""):
        loc = self.loc(node)
        return SourceError(loc.path, loc.line, loc.col, message, hint)

    def lookup(self, name):
        for scope in reversed(self.scopes):
            if name in scope:
                return scope[name]
        return None

    # ------------------------------------------------------------ functions
    def function(self, f: ast.FunctionDef, sig) -> ir.Function:
        self.ret = sig.ret
        params = [ir.Param(n, t, self.loc(a)) for (n, t), a in zip(sig.params, f.args.args)]
        for p, a in zip(params, f.args.args):
            if (p.name in self.sigs or p.name in self.structs or p.name in CONSTANTS or p.name in BUILTIN_TYPES
                    or p.name in INTRINSICS or p.name in self.globals):
                raise self.err(a, f"parameter '{p.name}' shadows a function, type, intrinsic, constant or buffer",
                               "rename the parameter")
        self.params = {p.name: p for p in params}
        self.scopes = [{p.name: (p.ty, "param") for p in params}]
        body_nodes = f.body
        doc = ast.get_docstring(f) or ""
        if doc:
            body_nodes = body_nodes[1:]
        body = self.block(body_nodes)
        if not always_returns(body):
            raise self.err(f, f"function '{f.name}' can reach its end without returning",
                           "end every path with a return statement")
        return ir.Function(f.name, params, sig.ret, body, self.loc(f), doc, self.calls)

    def block(self, nodes) -> list[ir.Stmt]:
        self.scopes.append({})
        out = []
        for n in nodes:
            s = self.stmt(n)
            if s is not None:
                out.append(s)
        self.scopes.pop()
        return out

    # ------------------------------------------------------------ statements
    def stmt(self, n):
        loc = self.loc(n)
        if isinstance(n, ast.Pass):
            return None
        if isinstance(n, ast.Return):
            if n.value is None:
                raise self.err(n, "return needs a value", f"return a {self.ret}")
            v = self.expr(n.value)
            if v.ty != self.ret:
                raise self.err(n.value, f"returns {v.ty} but the function is declared -> {self.ret}",
                               "convert explicitly or fix the annotation")
            return ir.Return(loc, v)
        if isinstance(n, ast.AnnAssign):
            if not isinstance(n.target, ast.Name) or n.value is None:
                raise self.err(n, "an annotated assignment declares one local with a value", "write x: float = 0.0")
            ty = parse_type(self.path, n.annotation, self.structs, self.constants)
            return self.declare(n, n.target, ty, n.value)
        if isinstance(n, ast.Assign):
            if len(n.targets) != 1 or isinstance(n.targets[0], (ast.Tuple, ast.List)):
                raise self.err(n, "assign one target at a time", "split `a = b = x` or `a, b = ...` into separate lines")
            t = n.targets[0]
            if isinstance(t, ast.Name) and self.lookup(t.id) is None:
                return self.declare(n, t, None, n.value)
            target = self.lvalue(t)
            if isinstance(n.value, ast.List):
                raise self.err(n.value, "an array literal only initializes a declaration (HLSL has no array expression)",
                               "declare a new array: w: array[float, 3] = [a, b, c], or assign element by element")
            value = self.expr(n.value)
            if value.ty != target.ty:
                raise self.err(n.value, f"cannot assign {value.ty} to {target.ty}",
                               "types never convert implicitly; use float(...), vec3(...) or another name")
            if target.ty.kind == "texture":
                raise self.err(t, "textures cannot be reassigned", "pass the texture you want directly")
            return ir.Assign(loc, target, None, value)
        if isinstance(n, ast.AugAssign):
            op = ARITH.get(type(n.op))
            if op is None or op == "%":
                raise self.err(n, "only +=, -=, *= and /= are allowed", "write the operation out")
            target = self.lvalue(n.target)
            value = self.expr(n.value)
            res = self.binary_type(n, op, target.ty, value.ty)
            if res != target.ty:
                raise self.err(n, f"{target.ty} {op}= {value.ty} would give {res}", "write the operation out")
            return ir.Assign(loc, target, op, value)
        if isinstance(n, ast.If):
            cond = self.condition(n.test)
            return ir.If(loc, cond, self.block(n.body), self.block(n.orelse))
        if isinstance(n, ast.For):
            return self.for_loop(n)
        if isinstance(n, ast.Match):
            return self.match_stmt(n)
        if isinstance(n, ast.Expr):
            raise self.err(n, "an expression statement does nothing in a pure brick",
                           "assign its value or remove it (docstrings go first in a function)")
        kind = type(n).__name__
        hints = {"While": "use `for i in range(N)` with a constant N",
                 "Break": "restructure with if/else; loops always run their constant count",
                 "Continue": "wrap the rest of the loop body in an if",
                 "FunctionDef": "define functions at the top level of the brick"}
        raise self.err(n, f"'{kind}' is not allowed in a brick function",
                       hints.get(kind, "allowed: assignments, if/elif/else, for i in range(N), return"))

    def declare(self, n, target: ast.Name, ty, value_node):
        name = target.id
        check_identifier(self.path, target, name)
        if self.lookup(name) is not None:
            raise self.err(target, f"'{name}' is already declared", "assign without an annotation, or use a new name")
        if (name in self.constants or name in CONSTANTS or name in BUILTIN_TYPES or name in INTRINSICS
                or name in self.sigs or name in self.structs or name in self.globals):
            raise self.err(target, f"'{name}' shadows a constant, type, intrinsic or function", "pick another name")
        if isinstance(value_node, ast.List):
            value = self.array_literal(value_node, ty, name)
        else:
            value = self.expr(value_node)
        if ty is not None:
            if value.ty != ty:
                raise self.err(value_node, f"'{name}' is declared {ty} but the value is {value.ty}",
                               "types never convert implicitly; use float(...) or vec3(...)")
        if value.ty.kind == "texture":
            raise self.err(target, "textures cannot be stored in locals", "pass the texture parameter directly")
        if value.ty.kind == "buffer":
            raise self.err(target, "buffers cannot be stored in locals", "read elements by index: lights[i]")
        self.scopes[-1][name] = (value.ty, "local")
        return ir.Decl(self.loc(n), name, value.ty, value)

    def lvalue(self, t) -> ir.Expr:
        if isinstance(t, ast.Name):
            found = self.lookup(t.id)
            if found is None and t.id in self.globals:
                raise self.err(t, f"buffer '{t.id}' is read-only", "copy the element into a local and change that")
            if found is None:
                raise self.err(t, f"'{t.id}' is not declared", "assign it first")
            ty, scope = found
            if scope not in ("local", "param"):
                raise self.err(t, f"cannot assign to {scope} '{t.id}'", "use a local variable")
            if scope == "param":
                self.params[t.id].assigned = True
            return ir.Var(ty, self.loc(t), t.id, scope)
        if isinstance(t, ast.Attribute):
            e = self.expr(t)
            if isinstance(e, ir.Swizzle) and len(e.components) > 1:
                raise self.err(t, "cannot assign to a multi-component swizzle (WGSL forbids it)",
                               "assign one component at a time, or rebuild the vector: v = vec3(a, b, v.z)")
            self.lvalue(t.value)
            return e
        if isinstance(t, ast.Subscript):
            e = self.expr(t)
            self.lvalue(t.value)
            return e
        raise self.err(t, "cannot assign to this expression", "assign to a local, a component (v.x) or a field (s.f)")

    def array_literal(self, node: ast.List, ty: Type | None, name: str) -> ir.Construct:
        if ty is None or ty.kind != "array":
            raise self.err(node, "lists are not allowed except to initialize a local declared as an array",
                           f"annotate it: {name}: array[float, {len(node.elts)}] = [...]")
        elems = [self.expr(e) for e in node.elts]
        if len(elems) != ty.size:
            raise self.err(node, f"{ty} needs {ty.size} elements, got {len(elems)}", "give one value per element")
        for e, en in zip(elems, node.elts):
            if e.ty != ty.elem:
                raise self.err(en, f"element is {e.ty}, the array holds {ty.elem}", "types never convert implicitly")
        return ir.Construct(ty, self.loc(node), elems)

    def condition(self, node) -> ir.Expr:
        c = self.expr(node)
        if c.ty != BOOL:
            raise self.err(node, f"condition is {c.ty}, not bool", "compare explicitly, e.g. x > 0.0")
        return c
