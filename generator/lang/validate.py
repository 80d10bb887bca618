"""The IR validator: a pure check of the invariants the emitters assume (lang/ir.py's module docstring).

The brick checker (typecheck.py) enforces these rules on parsed bricks; the link stage also builds IR
directly (the glue, the ubershader's switches, threaded parameters), and a mistake there would otherwise
surface as a glslang or naga error in generated text. validate_program() walks every function of a linked
program with an explicit stack (no recursion: a program's depth is bounded by the loader, but the validator
must not be the walk that overflows) and returns every violation found, each naming the function and the
node's location; check_program() raises one InternalError listing them.
"""
from __future__ import annotations

from dataclasses import dataclass

from . import ir
from .intrinsics import INTRINSICS
from .types import BOOL, Type

ARITH_OPS = frozenset("+ - * / %".split())
COMPARE_OPS = frozenset("< <= > >= == !=".split())
LOGIC_OPS = frozenset(("and", "or"))
UNARY_OPS = frozenset(("-", "not"))
SCOPES = frozenset(("local", "param", "const", "global"))
# intrinsics the link stage and the templates may call beyond the brick table (buffer_length: dynamic lights)
EXTRA_INTRINSICS = frozenset(("buffer_length",))


@dataclass(frozen=True)
class Violation:
    function: str
    loc: ir.Loc | None
    message: str

    def __str__(self) -> str:
        return f"{self.loc or '<generated>'}: in {self.function}: {self.message}"


class InternalError(Exception):
    """The link stage produced IR that breaks an emitter invariant: a generator bug, not a user error."""


def _is_int(t: Type) -> bool:
    return t.kind == "scalar" and t.scalar in ("int", "uint")


class _FunctionCheck:
    """The checks of one function; `known` maps the names of functions defined before it to themselves."""

    def __init__(self, f: ir.Function, known: dict[str, ir.Function], globals_: dict[str, ir.Global]):
        self.f, self.known, self.globals = f, known, globals_
        self.params = {p.name: p for p in f.params}
        self.out: list[Violation] = []

    def bad(self, node, message: str) -> None:
        self.out.append(Violation(self.f.name, getattr(node, "loc", None), message))

    def run(self) -> list[Violation]:
        f = self.f
        if f.ret.kind in ("array", "buffer", "texture"):
            self.bad(f, f"returns a {f.ret.kind} ({f.ret}); functions return values only")
        if len(self.params) != len(f.params):
            self.bad(f, "two parameters share a name")
        for p in f.params:
            if p.ty.kind == "buffer":
                self.bad(p, f"parameter '{p.name}' is a buffer; buffers are globals only")
        # (statement list, declared names of the enclosing scopes) pairs: blocks are checked with the names
        # declared before them; a Decl adds its name to its own block's scope
        stack: list[tuple[list, frozenset]] = [(f.body, frozenset())]
        while stack:
            body, outer = stack.pop()
            declared = set(outer)
            for s in body:
                self.stmt(s, declared, stack)
        return self.out

    # ---------------------------------------------------------------- statements

    def stmt(self, s: ir.Stmt, declared: set, stack: list) -> None:
        if not isinstance(s, ir.Stmt):
            self.bad(s, f"a {type(s).__name__} where a statement belongs")
            return
        if not isinstance(s.loc, ir.Loc):
            self.bad(s, f"{type(s).__name__} without a location")
        if isinstance(s, ir.Decl):
            self.expr(s.value, declared)
            if s.ty.kind == "array" and not (isinstance(s.value, ir.Construct) and s.value.ty == s.ty):
                self.bad(s, f"array local '{s.name}' is not built by a constructor of its type")
            elif s.value.ty != s.ty:
                self.bad(s, f"'{s.name}: {s.ty}' is given a {s.value.ty}")
            if s.ty.kind == "buffer":
                self.bad(s, f"local '{s.name}' is a buffer")
            declared.add(s.name)
        elif isinstance(s, ir.Assign):
            self.assign(s, declared)
        elif isinstance(s, ir.If):
            self.expr(s.cond, declared)
            if s.cond.ty != BOOL:
                self.bad(s, f"if condition is {s.cond.ty}, not bool")
            stack += [(s.then, frozenset(declared)), (s.orelse, frozenset(declared))]
        elif isinstance(s, ir.For):
            if s.bound is not None:
                self.expr(s.bound, declared)
                if not _is_int(s.bound.ty):
                    self.bad(s, f"loop bound is {s.bound.ty}, not int or uint")
            elif not (isinstance(s.count, int) and s.count >= 0):
                self.bad(s, f"loop count {s.count!r} is not a constant int ≥ 0")
            stack.append((s.body, frozenset(declared | {s.var})))
        elif isinstance(s, ir.Switch):
            self.switch(s, declared, stack)
        elif isinstance(s, ir.Return):
            if s.value is None:
                if self.f.ret.kind != "void" and self.f.ret.name != "void":
                    self.bad(s, f"bare return in a function returning {self.f.ret}")
            else:
                self.expr(s.value, declared)
                if s.value.ty != self.f.ret:
                    self.bad(s, f"returns {s.value.ty} from a function returning {self.f.ret}")
        else:
            self.bad(s, f"unknown statement {type(s).__name__}")

    def assign(self, s: ir.Assign, declared: set) -> None:
        t = s.target
        if isinstance(t, ir.Swizzle) and len(t.components) != 1:
            self.bad(s, f"assignment to the swizzle .{t.components} (only one component may be assigned)")
        elif not isinstance(t, (ir.Var, ir.Swizzle, ir.Member, ir.Index)):
            self.bad(s, f"assignment to a {type(t).__name__}")
        root = t
        while isinstance(root, (ir.Swizzle, ir.Member, ir.Index)):
            root = root.base
        if isinstance(root, ir.Var):
            if root.scope in ("const", "global"):
                self.bad(s, f"assignment to the {root.scope} '{root.name}'")
            if root.name in self.params and root.name not in declared and not self.params[root.name].assigned:
                self.bad(s, f"parameter '{root.name}' is assigned but not marked assigned (WGSL copies it then)")
        self.expr(t, declared, target=True)
        self.expr(s.value, declared)
        if s.op is None and s.value.ty != t.ty:
            self.bad(s, f"a {s.value.ty} is assigned to a {t.ty}")
        if s.op is not None and s.op not in ARITH_OPS:
            self.bad(s, f"unknown compound assignment '{s.op}='")

    def switch(self, s: ir.Switch, declared: set, stack: list) -> None:
        self.expr(s.selector, declared)
        if not _is_int(s.selector.ty):
            self.bad(s, f"switch selector is {s.selector.ty}, not int or uint")
        seen: set[int] = set()
        for values, body in s.cases:
            for v in values:
                if not isinstance(v, int) or isinstance(v, bool):
                    self.bad(s, f"case value {v!r} is not an int")
                elif v in seen:
                    self.bad(s, f"case value {v} appears twice")
                elif s.selector.ty.scalar == "uint" and v < 0:
                    self.bad(s, f"case value {v} is out of the uint selector's range")
                seen.add(v)
            stack.append((body, frozenset(declared)))
        stack.append((s.default, frozenset(declared)))

    # ---------------------------------------------------------------- expressions

    def expr(self, root: ir.Expr, declared: set, target: bool = False) -> None:
        todo: list[tuple[ir.Expr, ir.Expr | None]] = [(root, None)]
        while todo:
            e, parent = todo.pop()
            if not isinstance(e, ir.Expr):
                self.bad(parent or root, f"a {type(e).__name__} where an expression belongs")
                continue
            if not isinstance(e.ty, Type):
                self.bad(e, f"{type(e).__name__} without a type")
                continue
            self.node(e, parent, declared)
            todo += [(c, e) for c in ir.children(e)]

    def node(self, e: ir.Expr, parent, declared: set) -> None:
        if isinstance(e, ir.Var):
            self.var(e, parent, declared)
        elif isinstance(e, ir.Unary):
            if e.op not in UNARY_OPS:
                self.bad(e, f"unknown unary operator '{e.op}'")
        elif isinstance(e, ir.Binary):
            if e.op not in ARITH_OPS | COMPARE_OPS | LOGIC_OPS:
                self.bad(e, f"unknown binary operator '{e.op}'")
            elif e.op in COMPARE_OPS | LOGIC_OPS and e.ty.scalar != "bool":
                self.bad(e, f"'{e.op}' gives {e.ty}, not a bool")
        elif isinstance(e, ir.Call):
            self.call(e)
        elif isinstance(e, ir.Intrinsic):
            if e.name not in INTRINSICS and e.name not in EXTRA_INTRINSICS:
                self.bad(e, f"unknown intrinsic '{e.name}'")
        elif isinstance(e, ir.Index):
            if e.base.ty.kind not in ("array", "buffer", "vector", "matrix"):
                self.bad(e, f"index into a {e.base.ty.kind} ({e.base.ty})")
            if not _is_int(e.index.ty):
                self.bad(e, f"index is {e.index.ty}, not int or uint")
        elif isinstance(e, ir.Swizzle):
            if not e.components or set(e.components) - set("xyzw"):
                self.bad(e, f"swizzle '.{e.components}'")
        elif isinstance(e, ir.Select):
            if e.cond.ty.scalar != "bool" or e.if_true.ty != e.if_false.ty:
                self.bad(e, f"select of {e.if_true.ty} and {e.if_false.ty} on a {e.cond.ty}")
        elif isinstance(e, ir.Construct):
            if e.ty.kind == "array" and not isinstance(parent, type(None)):
                self.bad(e, f"an array value ({e.ty}) outside a declaration")
        if e.ty.kind == "buffer" and not self.buffer_use_ok(e, parent):
            self.bad(e, f"buffer '{getattr(e, 'name', e.ty)}' used other than indexed or by buffer_length")

    def var(self, e: ir.Var, parent, declared: set) -> None:
        if e.scope not in SCOPES:
            self.bad(e, f"variable '{e.name}' has the unknown scope '{e.scope}'")
        elif e.scope == "param":
            p = self.params.get(e.name)
            if p is None:
                self.bad(e, f"'{e.name}' is read as a parameter but the function has none of that name")
            elif p.ty != e.ty:
                self.bad(e, f"parameter '{e.name}' is {p.ty} but read as {e.ty}")
        elif e.scope == "local" and e.name not in declared and e.name not in self.params:
            # bricks read their parameters as locals: the emitters spell both alike
            self.bad(e, f"'{e.name}' is read but is neither a parameter nor a local declared before")
        elif e.scope == "global" and self.globals and e.name not in self.globals:
            self.bad(e, f"global '{e.name}' is not declared by the program")

    def buffer_use_ok(self, e: ir.Expr, parent) -> bool:
        if isinstance(parent, ir.Index) and parent.base is e:
            return True
        return isinstance(parent, ir.Intrinsic) and parent.name == "buffer_length"

    def call(self, e: ir.Call) -> None:
        callee = self.known.get(e.func)
        if callee is None:
            what = "itself" if e.func == self.f.name else "a function not defined before it"
            self.bad(e, f"calls '{e.func}', {what} (callees come first)")
            return
        if len(e.args) != len(callee.params):
            self.bad(e, f"calls '{e.func}' with {len(e.args)} arguments; it takes {len(callee.params)}")
            return
        for a, p in zip(e.args, callee.params):
            if a.ty != p.ty:
                self.bad(e, f"passes a {a.ty} as '{p.name}: {p.ty}' of '{e.func}'")
        if e.ty != callee.ret:
            self.bad(e, f"the call of '{e.func}' is typed {e.ty}; it returns {callee.ret}")


def validate_program(functions, globals_=()) -> list[Violation]:
    """Every violation of the emitters' invariants in `functions` (callees first) and their `globals_`."""
    known: dict[str, ir.Function] = {}
    gl = {g.name: g for g in globals_}
    out: list[Violation] = []
    for f in functions:
        if f.name in known:
            out.append(Violation(f.name, f.loc, "defined twice"))
        out += _FunctionCheck(f, known, gl).run()
        known[f.name] = f
    return out


def check_program(program) -> None:
    """Raise InternalError listing every violation in a linked program (link.Program or anything with
    `.functions` and `.globals`)."""
    found = validate_program(program.functions, getattr(program, "globals", ()))
    if found:
        shown = "\n  ".join(str(v) for v in found[:20])
        more = f"\n  … and {len(found) - 20} more" if len(found) > 20 else ""
        raise InternalError(f"the linked program breaks {len(found)} IR invariant(s):\n  {shown}{more}")
