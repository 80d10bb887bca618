"""The tree walk shared by the C-like targets (GLSL, HLSL, WGSL), driven by per-target tables.

A subclass supplies tables (type spellings, intrinsic spellings, literal
suffixes) and overrides the few hooks where a language's structure differs
(declarations, signatures, matrix products in HLSL, `select` in WGSL).
Switches and runtime-bounded loops are in control.py, buffers, global
declarations and arrays in resources.py (mixins).
Every binary and unary expression is parenthesized, so no precedence table
is needed and every target reads the same.
"""
from __future__ import annotations

import math
import struct

from ...lang import ir
from ...lang.intrinsics import CONSTANTS
from ...lang.types import BUILTIN_TYPES, Type
from . import reserved
from ..base import Emitted
from .control import ControlMixin, wrap  # noqa: F401  (wrap: re-exported)
from .records import FunctionRecords
from .resources import ResourceMixin

INDENT = "    "
HALF_MAX = 65504.0  # the largest finite fp16 value
# fp16 names (generated names start with '_', which brick names never do):
MIRROR_PREFIX = "_w32_"  # the 32-bit twin of a buffer's element struct
LOAD_PREFIX = "_load_"  # the function converting a buffer's 32-bit element to its half struct
ENTRY32_PREFIX = "_f32_"  # the 32-bit wrapper of an entry point (entry32), and its half copies of arrays
SAMPLING = ("sample", "sample_level", "sample_compare")  # the intrinsics that read a texture


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
    # "fp32" or "fp16": at fp16 the brick language's `float` is the language's 16-bit float (the
    # *Half subclasses); what crosses the interface (uniforms, buffers, samples, textures, stage
    # inputs and outputs) stays 32-bit and is converted where brick code meets it (from32/to32).
    precision = "fp32"

    # ---- tables a subclass fills in
    SCALARS: dict[str, str] = {}    # brick scalar -> spelling
    VECTORS: dict[str, str] = {}    # brick scalar -> format with {n}
    MATRIX = ""                     # format with {n}
    TEXTURE = ""                    # texture2d parameter type
    TEXTURE_CUBE = ""               # texturecube parameter type
    TEXTURE_SHADOW = ""             # texture2d_shadow parameter type (a depth texture)
    TEXTURE_ARRAY = ""              # texture2d_array parameter type
    TEXTURE_CUBE_ARRAY = ""         # texturecube_array parameter type
    TEXTURE_ARRAY_SHADOW = ""       # texture2d_array_shadow parameter type
    SAMPLER = ""                    # separate sampler parameter type ("" = combined)
    SAMPLER_COMPARE = ""            # the comparison sampler of a texture2d_shadow
    FLOAT_SUFFIX = ""
    INT_SUFFIX = ""
    UINT_SUFFIX = "u"
    BINARY_OPS = {"and": "&&", "or": "||"}
    SIGNED_MOD_BY_DIVISION = True   # write signed int % as a - b*(a/b) (see expr_binary)
    UNARY_OPS = {"-": "-", "not": "!"}
    # intrinsic -> format over {0}, {1}, ... (texture args also give {smp}); missing = same name;
    # "name@DIM" overrides "name" when the first argument is a texture of dimension DIM other than "2d"
    # ("sample@cube", "sample_compare@2d_array"); an array's {2} is its int or uint layer
    INTRINSICS: dict[str, str] = {}

    # ------------------------------------------------------------ public interface
    def ident(self, name: str) -> str:
        """A brick identifier as spelled in every C-like target (reserved words get the prefix '_r_')."""
        if name in self.reserved or name.startswith(reserved.RESERVED_PREFIXES):
            return reserved.PREFIX + name
        return name

    @property
    def half(self) -> bool:
        """True for the fp16 variant of a language (generator.backends.get_target(name, "fp16"))."""
        return self.precision == "fp16"

    def convert(self, t: Type, x: str) -> str:
        """x converted to this target's spelling of t (a value conversion, e.g. float -> half)."""
        return f"{self.type_name(t)}({x})"

    def from32(self, t, x: str) -> str:
        """A 32-bit value x (a uniform, a sample, a stage input) as brick type t (a Type or a builtin
        type name like "vec3"): x itself at fp32, a conversion to half at fp16."""
        t = BUILTIN_TYPES[t] if isinstance(t, str) else t
        if not self.half or not _has_float(t) or self.type_name(t) == self.full().type_name(t):
            return x
        return self.convert(t, x)

    def to32(self, t, x: str) -> str:
        """A value x of brick type t as its 32-bit spelling (results leaving brick code, texture coordinates)."""
        t = BUILTIN_TYPES[t] if isinstance(t, str) else t
        if not self.half or not _has_float(t) or self.type_name(t) == self.full().type_name(t):
            return x
        return self.full().convert(t, x)

    def mirror_decl(self, w: Writer, elem: Type) -> None:
        """fp16: struct MIRROR_PREFIX+S, S's fields at 32 bits (what a buffer of S holds), and the function
        LOAD_PREFIX+S converting one to S (field by field; arrays element by element)."""
        mirror = Type("struct", name=MIRROR_PREFIX + elem.name, fields=elem.fields)
        self.full().struct_decl(w, mirror)
        w.line("")
        w.line(self.signature(ir.Function(LOAD_PREFIX + elem.name, [], elem, [], None),
                              self.var_decl("w", mirror)))
        w.depth += 1
        w.line(self.declare_local("s", elem))
        for f, t in elem.fields:
            name = self.ident(f)
            if t.kind == "array":
                for i in range(t.size):
                    w.line(f"s.{name}[{i}] = {self.from32(t.elem, f'w.{name}[{i}]')};")
            else:
                w.line(f"s.{name} = {self.from32(t, f'w.{name}')};")
        w.line("return s;")
        w.depth -= 1
        w.line("}")
        w.line("")

    def entry32(self, emitted: Emitted, f: ir.Function) -> tuple[Emitted, str]:
        """At fp16: `emitted` plus a wrapper of entry `f` that takes and returns 32-bit values (what the
        templates pass: samples, uniform reads, stage inputs), converting them to half and the result back;
        and the wrapper's name. At fp32: (emitted, f's name) unchanged. The templates are precision-blind:
        they call the returned name."""
        if not self.half:
            return emitted, self.ident(f.name)
        full, name = self.full(), ENTRY32_PREFIX + f.name
        params, args, body = [], [], []
        for p in f.params:
            pname = self.ident(p.name)
            params += full.params(p)
            if p.ty.kind == "texture":
                args += [pname] + ([self.sampler_name(p.name)] if self.SAMPLER else [])
            elif p.ty.kind == "array" and _has_float(p.ty.elem):  # element by element into a half copy
                local = ENTRY32_PREFIX + p.name
                body.append(self.declare_local(local, p.ty))
                body += [f"{local}[{i}] = {self.from32(p.ty.elem, f'{pname}[{i}]')};" for i in range(p.ty.size)]
                args.append(local)
            else:
                args.append(self.from32(p.ty, pname))
        sig = full.signature(ir.Function(name, [], f.ret, [], f.loc), ", ".join(params))
        call = self.to32(f.ret, f"{self.ident(f.name)}({', '.join(args)})")
        lines = [sig] + [INDENT + b for b in body] + [f"{INDENT}return {call};", "}", ""]
        return Emitted(emitted.text + "\n".join(lines) + "\n", list(emitted.line_map)), name

    def declare_local(self, name: str, t: Type) -> str:
        """A local variable without an initializer (written element by element after)."""
        return f"{self.var_decl(name, t)};"

    def full(self) -> "CLikeTarget":
        """The fp32 target of this language (spells the 32-bit side of every conversion)."""
        from .. import get_target
        return get_target(self.name)

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

    def declare_texture(self, name: str, set: int, binding: int, dim: str = "2d", compare: bool = False) -> str:
        """A global texture resource NAME ("2d", "cube", "2d_array", "cube_array") and its sampler at bindings
        B and B+1 of set S (compare: a 2D depth texture or array of them and a comparison sampler)."""
        raise NotImplementedError

    def image_type(self, dim: str, compare: bool = False) -> str:
        """The spelling of a texture of dimension `dim` ("2d", "cube", "2d_array", "cube_array"; compare: a 2D
        depth texture or an array of them)."""
        if compare:
            return {"2d": self.TEXTURE_SHADOW, "2d_array": self.TEXTURE_ARRAY_SHADOW}[dim]
        return {"2d": self.TEXTURE, "cube": self.TEXTURE_CUBE, "2d_array": self.TEXTURE_ARRAY,
                "cube_array": self.TEXTURE_CUBE_ARRAY}[dim]

    def sampler_type(self, compare: bool = False) -> str:
        """The sampler that travels with a texture (compare: a comparison sampler)."""
        return self.SAMPLER_COMPARE if compare else self.SAMPLER

    def type_name(self, t: Type) -> str:
        if t.kind == "scalar":
            return self.SCALARS[t.scalar]
        if t.kind == "vector":
            return self.VECTORS[t.scalar].format(n=t.size)
        if t.kind == "matrix":
            return self.MATRIX.format(n=t.size)
        if t.kind == "texture":
            return self.image_type(t.dim, t.compare)
        if t.kind == "struct":
            return self.ident(t.name)
        if t.kind == "array":
            return self.array_type(t)
        raise AssertionError(f"no {self.name} spelling for type {t}")

    def emit(self, structs: list[Type], functions: list[ir.Function], globals: list[ir.Global] = (),
             records: FunctionRecords | None = None) -> Emitted:
        """Structs, then the declarations of `globals` (buffers, textures), then functions.

        `records`: the caller's store of what C-like emitters emitted for each linked function (records.py),
        keyed by emitter class and writer state; a function met again is replayed from it, and what is walked is
        recorded there. One store serves every emitter, so a dialect emitter made per program replays what an
        earlier one of its class emitted. Without one, every function is walked."""
        w = Writer(self.line_directives)
        for s in structs:
            self.struct_decl(w, s)
            w.line("")
        if self.half:  # buffers keep 32-bit elements: declare their twins (read through buffer_element)
            seen = set()
            for g in globals:
                if g.ty.kind == "buffer" and g.ty.elem.name not in seen:
                    seen.add(g.ty.elem.name)
                    self.mirror_decl(w, g.ty.elem)
        for g in globals:
            for text in self.declare_global(g).splitlines():
                w.line(text)
            w.line("")
        for f in functions:
            if records is None:
                self.function(w, f)
            else:
                self._function_cached(w, f, records)
            w.line("")
        return Emitted(w.text(), w.line_map)

    def _function_cached(self, w: Writer, f: ir.Function, records: FunctionRecords) -> None:
        """self.function(w, f), replayed from the record of `f` an emitter of this class made from the same writer
        state (linked brick functions are shared by every program of a library, and never change:
        link/program.py); the bytes are the same, the walk is skipped."""
        key = (type(self), w.directives, w._next, w.depth)
        memo = records.of(f)
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
            out.append(self.sampler_decl(self.sampler_name(p.name), p.ty.compare))
        return out

    def sampler_decl(self, name: str, compare: bool = False) -> str:
        """A sampler parameter `name` (compare: a comparison sampler)."""
        return f"{self.sampler_type(compare)} {name}"

    def var_decl(self, name: str, t: Type) -> str:
        """`T name`; `T name[N]` for arrays."""
        if t.kind == "array":
            return f"{self.type_name(t.elem)} {name}[{t.size}]"
        return f"{self.type_name(t)} {name}"

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
            if self.half:  # past the half range a literal saturates to ±65504 (FP16_MAX), never inf;
                # and it is written as the half it rounds to (to nearest, even): glslang converts a
                # literal to half by truncation (0.3183098861837907hf became 0.318115234375, not
                # 0.318359375), naga rounds; an exact half is the same number to both
                v = struct.unpack("<e", struct.pack("<e", max(-HALF_MAX, min(HALF_MAX, float(v)))))[0]
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
        if e.args and e.args[0].ty.dim not in ("", "2d"):
            fmt = self.INTRINSICS.get(f"{e.name}@{e.args[0].ty.dim}")
            assert fmt or not e.args[0].ty.arrayed, f"{self.name}: no spelling of {e.name} on a {e.args[0].ty}"
        fmt = fmt or self.INTRINSICS.get(e.name)
        if fmt is None:
            return f"{e.name}({', '.join(self.expr(a) for a in e.args)})"
        args = [self.expr(a) for a in e.args]
        smp = self.sampler_name(e.args[0].name) if e.args[0].ty.kind == "texture" else ""
        if self.half and e.name in SAMPLING:  # textures are 32-bit: coordinates, references and texels convert
            args = [args[0]] + [self.to32(a.ty, x) for a, x in zip(e.args[1:], args[1:])]
            return self.from32(e.ty, fmt.format(*args, smp=smp))
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
            if self.half:  # a 32-bit element (its MIRROR_PREFIX twin), converted by its LOAD_PREFIX function
                return f"{LOAD_PREFIX}{e.base.ty.elem.name}({self.buffer_element(e.base, self.expr(e.index))})"
            return self.buffer_element(e.base, self.expr(e.index))
        return f"{self.expr(e.base)}[{self.expr(e.index)}]"

    def expr_select(self, e: ir.Select) -> str:
        return self.select(self.expr(e.cond), self.expr(e.if_true), self.expr(e.if_false))

    def select(self, cond: str, if_true: str, if_false: str) -> str:
        return f"({cond} ? {if_true} : {if_false})"


def _has_float(t: Type) -> bool:
    """Whether t holds floats that change width with the precision (scalars, vectors, matrices of float)."""
    return t.kind in ("scalar", "vector", "matrix") and t.scalar == "float"
