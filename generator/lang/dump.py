"""A readable, deterministic text dump of linked IR: structs, globals, then functions with their statements.

The goldens keep one per linked program (tests/golden/ir/), so a change that moved through linking shows
there and one that only changed emission does not. What is printed is what the emitters read, spelled
in one neutral syntax; what a brick's comments or docstrings move is left out: no source line or column
(a function says only which file it came from), no docstrings, no source hashes, no object ids.

Every walk here is iterative (explicit stacks), so a program of any nesting depth dumps without
recursion, whatever the parser's depth limits are.
"""
from __future__ import annotations

from . import ir

INDENT = "    "


def dump_program(functions, structs=(), globals_=()) -> str:
    """The text of one linked program: its structs, its global resources, its functions in program order."""
    lines = [f"// linked program: {len(structs)} structs, {len(globals_)} globals, {len(functions)} functions"]
    for s in structs:
        lines += ["", *dump_struct(s)]
    if globals_:
        lines.append("")
        lines += [dump_global(g) for g in globals_]
    for f in functions:
        lines += ["", *dump_function(f)]
    return "\n".join(lines) + "\n"


def dump_struct(ty) -> list[str]:
    return [f"struct {ty.name} {{", *(f"{INDENT}{name}: {fty}" for name, fty in ty.fields), "}"]


def dump_global(g: ir.Global) -> str:
    if g.ty.kind == "scalar":  # an int or uint specialization constant: `binding` is its SpecId
        return f"spec constant {g.name}: {g.ty} (id {g.binding})"
    return f"global {g.name}: {g.ty} (set {g.set}, binding {g.binding})"


def dump_function(f: ir.Function) -> list[str]:
    params = ", ".join(f"{'mut ' if p.assigned else ''}{p.name}: {p.ty}" for p in f.params)
    head = f"fn {f.name}({params}) -> {f.ret} {{  // {f.loc.path}"
    return [head, *dump_statements(f.body, 1), "}"]


def dump_statements(body, depth: int = 0) -> list[str]:
    """Statement lines, indented `depth` levels; nested bodies are expanded from a stack, not by recursion."""
    lines: list[str] = []
    stack: list[tuple] = [("body", body, depth)]
    while stack:
        item = stack.pop()
        if item[0] == "line":
            lines.append(INDENT * item[2] + item[1])
            continue
        _, stmts, d = item
        todo: list[tuple] = []
        for s in stmts:
            todo += _statement(s, d)
        stack += reversed(todo)
    return lines


def _statement(s: ir.Stmt, d: int) -> list[tuple]:
    """One statement as ("line", text, depth) and ("body", statements, depth) items, in order."""
    if isinstance(s, ir.Decl):
        return [("line", f"var {s.name}: {s.ty} = {dump_expr(s.value)}", d)]
    if isinstance(s, ir.Assign):
        return [("line", f"{dump_expr(s.target)} {s.op or ''}= {dump_expr(s.value)}", d)]
    if isinstance(s, ir.Return):
        return [("line", "return" if s.value is None else f"return {dump_expr(s.value)}", d)]
    if isinstance(s, ir.If):
        out = [("line", f"if {dump_expr(s.cond)} {{", d), ("body", s.then, d + 1)]
        if s.orelse:
            out += [("line", "} else {", d), ("body", s.orelse, d + 1)]
        return out + [("line", "}", d)]
    if isinstance(s, ir.For):
        rng = f"{s.var}: {s.var_type} in range({dump_expr(s.bound)})" if s.bound is not None \
            else f"{s.var} in range({s.count})"
        return [("line", f"for {rng} {{", d), ("body", s.body, d + 1), ("line", "}", d)]
    if isinstance(s, ir.Switch):
        out = [("line", f"switch {dump_expr(s.selector)} {{", d)]
        for values, body in s.cases:
            out += [("line", f"case {', '.join(map(str, values))}: {{", d + 1), ("body", body, d + 2),
                    ("line", "}", d + 1)]
        if s.default:
            out += [("line", "default: {", d + 1), ("body", s.default, d + 2), ("line", "}", d + 1)]
        return out + [("line", "}", d)]
    raise TypeError(f"no dump for statement node {type(s).__name__}")


def dump_expr(root: ir.Expr) -> str:
    """An expression, fully parenthesized: nodes are expanded into their pieces on an explicit stack and the
    pieces joined once, so time and memory are linear in the expression's size at any depth."""
    out: list[str] = []
    stack: list = [root]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            out.append(item)
        else:
            stack += reversed(_pieces(item))
    return "".join(out)


def _join(args: list, sep: str = ", ") -> list:
    out: list = []
    for i, a in enumerate(args):
        out += [sep, a] if i else [a]
    return out


def _pieces(e: ir.Expr) -> list:
    """One node as strings and sub-expressions, in reading order."""
    if isinstance(e, ir.Const):
        return [_const(e)]
    if isinstance(e, ir.Var):
        return [e.name]
    if isinstance(e, ir.Unary):
        return ["(-", e.operand, ")"] if e.op == "-" else [f"({e.op} ", e.operand, ")"]
    if isinstance(e, ir.Binary):
        return ["(", e.lhs, f" {e.op} ", e.rhs, ")"]
    if isinstance(e, ir.Call):
        return [f"{e.func}(", *_join(e.args), ")"]
    if isinstance(e, ir.Intrinsic):
        return [f"{e.name}(", *_join(e.args), ")"]
    if isinstance(e, ir.Construct):
        return [f"{e.ty}(", *_join(e.args), ")"]
    if isinstance(e, ir.Swizzle):
        return [e.base, f".{e.components}"]
    if isinstance(e, ir.Member):
        return [e.base, f".{e.field}"]
    if isinstance(e, ir.Index):
        return [e.base, "[", e.index, "]"]
    if isinstance(e, ir.Select):
        return ["(", e.cond, " ? ", e.if_true, " : ", e.if_false, ")"]
    raise TypeError(f"no dump for expression node {type(e).__name__}")


def _const(e: ir.Const) -> str:
    v = e.value
    if isinstance(v, bool):
        return "true" if v else "false"
    if e.ty.scalar == "float" and isinstance(v, (int, float)):
        return repr(float(v))
    if e.ty.scalar == "uint":
        return f"{v}u"
    return repr(v)
