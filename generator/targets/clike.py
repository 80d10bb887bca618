"""The tree walk shared by the C-like targets (GLSL, HLSL, WGSL), driven by per-target tables.

A subclass supplies tables (type spellings, intrinsic spellings, literal
suffixes) and overrides the few hooks where a language's structure differs
(declarations, signatures, matrix products in HLSL, `select` in WGSL).
Switches and runtime-bounded loops are in clike_control.py, buffers, global
declarations and arrays in clike_resources.py (mixins).
Every binary and unary expression is parenthesized, so no precedence table
is needed and every target reads the same.
"""
from __future__ import annotations

import math

from ..lang import ir
from ..lang.intrinsics import CONSTANTS
from ..lang.types import Type
from . import reserved
from .base import Emitted
from .clike_control import ControlMixin, wrap  # noqa: F401  (wrap: re-exported)
from .clike_resources import ResourceMixin

INDENT = "    "


class Writer:
    """Collects lines, the line map and (where the target has them) #line directives."""

    def __init__(self, directives: bool):
        self.directives = directives
        self.lines: list[str] = []
        self.line_map: list[tuple[int, str, int]] = []
        self.depth = 0
        self._next: tuple[str, int] | None = None  # what the compiler believes the next line is

    def line(self, text: str, loc: ir.Loc | None = None) -> None:
        """Append one line; a line with a brick location is mapped (and #line-tagged) to it."""
        if loc is not None:
            where = (loc.path, loc.line)
            if self.directives and self._next != where:
                self.lines.append(f'#line {loc.line} "{directive_path(loc.path)}"')
                self._next = where
            self.line_map.append((len(self.lines) + 1, loc.path, loc.line))
        self.lines.append(INDENT * self.depth + text if text else "")
        if self._next is not None:
            self._next = (self._next[0], self._next[1] + 1)

    def text(self) -> str:
        return "\n".join(self.lines) + "\n" if self.lines else ""


def directive_path(path: str) -> str:
    """A brick path as written inside a #line directive (forward slashes, no quotes)."""
    path = str(path).replace("\\", "/")
    assert '"' not in path and "\n" not in path, f"path not usable in #line: {path!r}"
    return path


def float_literal(v: float) -> str:
    """Shortest repr that round-trips and still reads as a float (1.0, 0.04, 1e-07)."""
    v = float(v)
    assert math.isfinite(v), f"non-finite float literal {v!r} reached the emitter"
    s = repr(v)
    if "." not in s and "e" not in s:
        s += ".0"
    return s


class CLikeTarget(ControlMixin, ResourceMixin):
    """GLSL, HLSL and WGSL: one walk over the IR, spelled by the tables below."""

    reserved = reserved.ALL
    line_directives = True          # emit `#line N "brick"` before mapped lines

    # ---- tables a subclass fills in
    SCALARS: dict[str, str] = {}    # brick scalar -> spelling
    VECTORS: dict[str, str] = {}    # brick scalar -> format with {n}
    MATRIX = ""                     # format with {n}
    TEXTURE = ""                    # texture2d parameter type
    TEXTURE_CUBE = ""               # texturecube parameter type
    SAMPLER = ""                    # separate sampler parameter type ("" = combined)
    FLOAT_SUFFIX = ""
    INT_SUFFIX = ""
    UINT_SUFFIX = "u"
    BINARY_OPS = {"and": "&&", "or": "||"}
    SIGNED_MOD_BY_DIVISION = True   # write signed int % as a - b*(a/b) (see expr_binary)
    UNARY_OPS = {"-": "-", "not": "!"}
    # intrinsic -> format over {0}, {1}, ... (texture args also give {smp}); missing = same name;
    # "name@cube" overrides "name" when the first argument is a cube texture
    INTRINSICS: dict[str, str] = {}

    # ------------------------------------------------------------ public interface
    def ident(self, name: str) -> str:
        """A brick identifier as spelled in every C-like target (reserved words get the prefix '_r_')."""
        if name in self.reserved or name.startswith(reserved.RESERVED_PREFIXES):
            return reserved.PREFIX + name
        return name

    def sampler_name(self, texture: str) -> str:
        """The sampler that travels with texture `texture` ('_smp_' + its brick name: never a brick's name)."""
        return reserved.SAMPLER_PREFIX + texture

    def header(self) -> str:
        """Preamble lines the source needs before any emitted code ("" if none)."""
        return ""

    def line_reset(self, line: int, path: str) -> str:
        """A directive making the *next* line count as `line` of `path` ("" if unsupported)."""
        if not self.line_directives:
            return ""
        return f'#line {int(line)} "{directive_path(path)}"'

    def declare_texture(self, name: str, set: int, binding: int, dim: str = "2d") -> str:
        """A global texture resource NAME ("2d" or "cube") and its sampler at bindings B and B+1 of set S."""
        raise NotImplementedError

    def type_name(self, t: Type) -> str:
        if t.kind == "scalar":
            return self.SCALARS[t.scalar]
        if t.kind == "vector":
            return self.VECTORS[t.scalar].format(n=t.size)
        if t.kind == "matrix":
            return self.MATRIX.format(n=t.size)
        if t.kind == "texture":
            return self.TEXTURE_CUBE if t.dim == "cube" else self.TEXTURE
        if t.kind == "struct":
            return self.ident(t.name)
        if t.kind == "array":
            return self.array_type(t)
        raise AssertionError(f"no {self.name} spelling for type {t}")

    def emit(self, structs: list[Type], functions: list[ir.Function], globals: list[ir.Global] = ()) -> Emitted:
        """Structs, then the declarations of `globals` (buffers, textures), then functions."""
        w = Writer(self.line_directives)
        for s in structs:
            self.struct_decl(w, s)
            w.line("")
        for g in globals:
            for text in self.declare_global(g).splitlines():
                w.line(text)
            w.line("")
        for f in functions:
            self._function_cached(w, f)
            w.line("")
        return Emitted(w.text(), w.line_map)

    def _function_cached(self, w: Writer, f: ir.Function) -> None:
        """self.function(w, f), replayed from the function's own record when this target has emitted it
        before from the same writer state (linked brick functions are shared by every program of a library,
        and never change: link/program.py); the bytes are the same, the walk is skipped."""
        key = (type(self), w.directives, w._next, w.depth)
        memo = f.__dict__.setdefault("_emitted", {})
        hit = memo.get(key)
        if hit is not None:
            lines, mapped, end = hit
            base = len(w.lines)
            w.lines.extend(lines)
            w.line_map.extend((base + g, path, line) for g, path, line in mapped)
            w._next = end
            return
        start, start_map = len(w.lines), len(w.line_map)
        self.function(w, f)
        memo[key] = (w.lines[start:], [(g - start, path, line) for g, path, line in w.line_map[start_map:]], w._next)

    # ------------------------------------------------------------ declarations
    def struct_decl(self, w: Writer, s: Type) -> None:
        w.line(f"struct {self.ident(s.name)} {{")
        w.depth += 1
        for f, t in s.fields:
            w.line(self.field_decl(f, t))
        w.depth -= 1
        w.line("};")

    def field_decl(self, name: str, t: Type) -> str:
        return f"{self.var_decl(self.ident(name), t)};"

    def params(self, p: ir.Param) -> list[str]:
        """Parameter declarations for one brick parameter (a texture brings its sampler)."""
        out = [self.var_decl(self.ident(p.name), p.ty)]
        if p.ty.kind == "texture" and self.SAMPLER:
            out.append(self.var_decl(self.sampler_name(p.name), None))
        return out

    def var_decl(self, name: str, t: Type | None) -> str:
        """`T name` (None = the sampler type); `T name[N]` for arrays."""
        if t is not None and t.kind == "array":
            return f"{self.type_name(t.elem)} {name}[{t.size}]"
        return f"{self.type_name(t) if t is not None else self.SAMPLER} {name}"

    def param_list(self, f: ir.Function) -> list[str]:
        return [d for p in f.params for d in self.params(p)]

    def function(self, w: Writer, f: ir.Function) -> None:
        w.line(self.signature(f, ", ".join(self.param_list(f))), f.loc)
        w.depth += 1
        self.prologue(w, f)
        self.block(w, f.body)
        w.depth -= 1
        w.line("}")

    def signature(self, f: ir.Function, params: str) -> str:
        return f"{self.type_name(f.ret)} {self.ident(f.name)}({params}) {{"

    def prologue(self, w: Writer, f: ir.Function) -> None:
        """Lines before the body (WGSL copies assigned parameters into vars)."""

    # ------------------------------------------------------------ statements
    def block(self, w: Writer, stmts: list[ir.Stmt]) -> None:
        for s in stmts:
            self.stmt(w, s)

    def stmt(self, w: Writer, s: ir.Stmt) -> None:
        if isinstance(s, ir.Decl):
            w.line(self.decl(self.ident(s.name), s.ty, self.initializer(s.value)), s.loc)
        elif isinstance(s, ir.Assign):
            self.assign(w, s)
        elif isinstance(s, ir.If):
            self.if_stmt(w, s, "")
        elif isinstance(s, ir.Switch):
            self.switch(w, s)
        elif isinstance(s, ir.For):
            if s.bound is not None:
                w.line(self.for_bound_head(self.ident(s.var), s.var_type, self.expr(s.bound)), s.loc)
            else:
                w.line(self.for_head(self.ident(s.var), s.count), s.loc)
            w.depth += 1
            self.block(w, s.body)
            w.depth -= 1
            w.line("}")
        elif isinstance(s, ir.Return):
            w.line(f"return {self.expr(s.value)};", s.loc)
        else:
            raise AssertionError(f"unknown statement {type(s).__name__}")

    def initializer(self, e: ir.Expr) -> str:
        """A declaration's value (HLSL spells an array value here, and only here, as {a, b})."""
        return self.expr(e)

    def decl(self, name: str, t: Type, value: str) -> str:
        return f"{self.var_decl(name, t)} = {value};"

    def assign(self, w: Writer, s: ir.Assign) -> None:
        w.line(f"{self.expr(s.target)} {s.op or ''}= {self.expr(s.value)};", s.loc)

    def for_head(self, var: str, count: int) -> str:
        return f"for (int {var} = 0; {var} < {self.int_literal(count)}; {var}++) {{"

    def if_head(self, cond: str) -> str:
        return f"if {wrap(cond)} {{"

    def if_stmt(self, w: Writer, s: ir.If, prefix: str) -> None:
        w.line(prefix + self.if_head(self.expr(s.cond)), s.loc)
        w.depth += 1
        self.block(w, s.then)
        w.depth -= 1
        if len(s.orelse) == 1 and isinstance(s.orelse[0], ir.If):
            # `elif`: a #line directive cannot sit inside `} else if`, so split the line there
            if self.line_directives:
                w.line("}")
                self.if_stmt(w, s.orelse[0], "else ")
            else:
                self.if_stmt(w, s.orelse[0], "} else ")
            return
        if s.orelse:
            w.line("} else {")
            w.depth += 1
            self.block(w, s.orelse)
            w.depth -= 1
        w.line("}")

    # ------------------------------------------------------------ expressions
    def expr(self, e: ir.Expr) -> str:
        """The target spelling of an IR expression (fully parenthesized)."""
        method = getattr(self, "expr_" + type(e).__name__.lower())
        return method(e)

    def expr_const(self, e: ir.Const) -> str:
        return self.literal(e.ty, e.value)

    def literal(self, t: Type, v) -> str:
        if t.scalar == "bool":
            assert type(v) is bool
            return "true" if v else "false"
        if t.scalar == "float":
            s = float_literal(v) + self.FLOAT_SUFFIX
        elif t.scalar == "uint":
            assert 0 <= v < 2**32, f"uint literal {v} out of range"
            s = f"{int(v)}{self.UINT_SUFFIX}"
        else:
            s = self.int_literal(v)
        return f"({s})" if s.startswith("-") else s

    def int_literal(self, v: int) -> str:
        assert type(v) is int and -2**31 < v < 2**31, f"int literal {v!r} out of range"
        return f"{v}{self.INT_SUFFIX}"

    def expr_var(self, e: ir.Var) -> str:
        if e.scope == "const":
            return self.literal(e.ty, CONSTANTS[e.name])
        return self.ident(e.name)

    def expr_unary(self, e: ir.Unary) -> str:
        return f"({self.UNARY_OPS[e.op]}{self.expr(e.operand)})"

    def expr_binary(self, e: ir.Binary) -> str:
        if e.op == "%" and e.ty.scalar == "int" and self.SIGNED_MOD_BY_DIVISION:
            # glslang compiles a signed % to OpSMod (the sign of the divisor), which spirv-opt
            # folds one way and drivers compute another; a - b*(a/b) is the truncated remainder
            # (the sign of the dividend), as WGSL's % and the numpy target's fmod.
            a, b = self.expr(e.lhs), self.expr(e.rhs)
            return f"({a} - ({b} * ({a} / {b})))"
        op = self.BINARY_OPS.get(e.op, e.op)
        return f"({self.expr(e.lhs)} {op} {self.expr(e.rhs)})"

    def args(self, args: list[ir.Expr]) -> list[str]:
        """Call arguments; a texture argument brings its sampler along."""
        out = []
        for a in args:
            out.append(self.expr(a))
            if a.ty.kind == "texture" and self.SAMPLER:
                assert isinstance(a, ir.Var), "a texture argument is always a parameter or global"
                out.append(self.sampler_name(a.name))
        return out

    def expr_call(self, e: ir.Call) -> str:
        return f"{self.ident(e.func)}({', '.join(self.args(e.args))})"

    def expr_intrinsic(self, e: ir.Intrinsic) -> str:
        if e.name == "buffer_length":
            return self.buffer_length(e.args[0])
        fmt = None
        if e.args and e.args[0].ty.dim == "cube":
            fmt = self.INTRINSICS.get(e.name + "@cube")
        fmt = fmt or self.INTRINSICS.get(e.name)
        if fmt is None:
            return f"{e.name}({', '.join(self.expr(a) for a in e.args)})"
        args = [self.expr(a) for a in e.args]
        smp = self.sampler_name(e.args[0].name) if e.args[0].ty.kind == "texture" else ""
        return fmt.format(*args, smp=smp)

    def expr_construct(self, e: ir.Construct) -> str:
        args = [self.expr(a) for a in e.args]
        t = e.ty
        if t.kind == "vector" and len(e.args) == 1 and e.args[0].ty.kind == "scalar":
            return self.splat(t, args[0])
        if t.kind == "matrix":
            return self.matrix(t, args)
        if t.kind == "struct":
            return self.struct_value(t, args)
        if t.kind == "array":
            return self.array_value(t, args)
        return f"{self.type_name(t)}({', '.join(args)})"

    def splat(self, t: Type, x: str) -> str:
        return f"{self.type_name(t)}({x})"

    def matrix(self, t: Type, columns: list[str]) -> str:
        return f"{self.type_name(t)}({', '.join(columns)})"

    def struct_value(self, t: Type, args: list[str]) -> str:
        return f"{self.type_name(t)}({', '.join(args)})"

    def expr_swizzle(self, e: ir.Swizzle) -> str:
        return f"{self.expr(e.base)}.{e.components}"

    def expr_member(self, e: ir.Member) -> str:
        return f"{self.expr(e.base)}.{self.ident(e.field)}"

    def expr_index(self, e: ir.Index) -> str:
        if e.base.ty.kind == "buffer":
            return self.buffer_element(e.base, self.expr(e.index))
        return f"{self.expr(e.base)}[{self.expr(e.index)}]"

    def expr_select(self, e: ir.Select) -> str:
        return self.select(self.expr(e.cond), self.expr(e.if_true), self.expr(e.if_false))

    def select(self, cond: str, if_true: str, if_false: str) -> str:
        return f"({cond} ? {if_true} : {if_false})"
