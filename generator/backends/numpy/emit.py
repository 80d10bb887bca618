"""NumPy target: runs brick functions on the CPU, vectorized over N samples, in float16/32/64.

Data layout: a scalar is an array of shape (N,) (or 0-d for constants), a vecK (N, K), a matK
(N, K, K) with m[..., :, j] column j (GLSL semantics), ints int32, uints uint32, bools bool.
Structs are small slotted classes (one per struct, exported by load()). Every float literal is
created as F(...), the working dtype, so float16 runs compute in float16.

Control flow is vectorized: both branches of an `if` run under masks, assignments to variables
declared outside the branch become `x = _sel(mask, new, x, rank)`, and a `return` inside a branch
records its value for the masked lanes (`_ret`, `_done`). Switches and loops with a runtime bound
run the same way (control.py). The generated code never mutates an array in place
(component assignment builds a new array), so parameters keep copy semantics.
The helpers the emitted code calls (_sel, _setc, _dot, ...) live in runtime.py; those for
arrays, buffers and textures, and the representation of those values, in resources.py.

Textures are passed as arguments (arrays of texel values, sampled bilinearly with clamp to
edge at mip level 0); global resources (buffers, and textures a program reads as globals)
are given to load(..., resources={name: value}); unpack_buffer() turns a GPU buffer's bytes
into a buffer value.
"""
from __future__ import annotations

import functools

import numpy as np

from ...lang import ir
from ...lang.intrinsics import CONSTANTS
from ...lang.types import Type
from ..base import Emitted, Target
from .control import ControlEmitter, returns_under_mask
from .resources import RESOURCE_RUNTIME, unpack_buffer, value_rank
from .runtime import RUNTIME, _coerce, _struct

_SIMPLE = {"abs": "np.abs", "sign": "np.sign", "floor": "np.floor", "sqrt": "np.sqrt", "exp": "np.exp",
           "exp2": "np.exp2", "log": "np.log", "log2": "np.log2", "sin": "np.sin", "cos": "np.cos",
           "tan": "np.tan", "asin": "np.arcsin", "acos": "np.arccos", "atan": "np.arctan",
           "atan2": "np.arctan2", "pow": "np.power", "min": "np.fmin", "max": "np.fmax", "dot": "_dot",
           "length": "_length", "cross": "np.cross", "normalize": "_normalize", "reflect": "_reflect",
           "clamp": "_clamp", "smoothstep": "_smoothstep"}
_DTYPES = {"float": "F", "int": "np.int32", "uint": "np.uint32", "bool": "np.bool_"}


_rank = value_rank  # the runtime shape descriptor of a type: trailing dims, or ((field, desc), ...)


def _spec(t: Type):
    """How a caller's argument of type t is converted on entry (see _coerce)."""
    if t.kind == "struct":
        return tuple((f, _spec(ft)) for f, ft in t.fields)
    if t.kind in ("array", "buffer"):
        return _spec(t.elem)
    return t.scalar if t.kind in ("scalar", "vector", "matrix") else None


def _comment(text: str) -> str:
    line = (text.splitlines() or [""])[0]
    return "".join(ch for ch in line if ch.isprintable()).strip()


def _float_lit(v: float) -> str:
    if v != v:
        return "F(np.nan)"
    if v in (float("inf"), float("-inf")):
        return "F(np.inf)" if v > 0 else "F(-np.inf)"
    return f"F({float(v)!r})"


# the resources.py helper that samples a texture of each dimension (level 0)
_SAMPLERS = {"2d": "_tex2d", "cube": "_texcube", "2d_array": "_tex2d_array", "cube_array": "_texcube_array"}

class _FunctionEmitter(ControlEmitter):
    def __init__(self, target: "NumpyTarget", fn: ir.Function):
        self.t, self.fn = target, fn
        self.lines: list[tuple[str, ir.Loc | None]] = []
        self.depth = 1
        self.level = 0
        self.mask: str | None = None
        self.tmp = 0
        self.scopes: list[dict[str, int]] = [{p.name: 0 for p in fn.params}]
        self.ret_state = returns_under_mask(fn.body)
        self.resources: dict[str, Type] = {}  # global resources read: name -> type

    def line(self, text: str, loc: ir.Loc | None) -> None:
        self.lines.append(("    " * self.depth + text, loc))

    def fresh(self, prefix: str) -> str:
        self.tmp += 1
        return f"_{prefix}{self.tmp}"

    def emit(self) -> list[tuple[str, ir.Loc | None]]:
        fn, t = self.fn, self.t
        params = ", ".join(t.ident(p.name) for p in fn.params)
        sig = ", ".join(f"{p.name}: {t.type_name(p.ty)}" for p in fn.params)
        self.lines.append((f"def {t.ident(fn.name)}({params}):  # ({sig}) -> {t.type_name(fn.ret)}", fn.loc))
        if fn.doc:
            self.line(f"# {_comment(fn.doc)}", None)
        if self.ret_state:
            self.line("_ret, _done = None, np.False_", None)
        self.block(fn.body)
        if not (fn.body and isinstance(fn.body[-1], ir.Return)):
            self.line("return _ret", None)  # the checker guarantees every lane has returned here
        specs = tuple(_spec(p.ty) for p in fn.params)
        self.lines.append((f"_FUNCTIONS[{fn.name!r}] = ({t.ident(fn.name)}, {specs!r})", None))
        return self.lines

    # ------------------------------------------------------------ statements
    def block(self, stmts, scope=None) -> None:
        self.scopes.append(scope or {})
        start = len(self.lines)
        for s in stmts:
            self.stmt(s)
        if len(self.lines) == start:
            self.line("pass", None)
        self.scopes.pop()

    def declared_level(self, name: str) -> int:
        for scope in reversed(self.scopes):
            if name in scope:
                return scope[name]
        return 0

    def stmt(self, s) -> None:
        if isinstance(s, ir.Decl):
            self.line(f"{self.t.ident(s.name)} = {self.expr(s.value)}", s.loc)
            self.scopes[-1][s.name] = self.level
        elif isinstance(s, ir.Assign):
            value = s.value if s.op is None else ir.Binary(s.target.ty, s.loc, s.op, s.target, s.value)
            root, new = self.store(s.target, self.expr(value))
            name = self.t.ident(root.name)
            if self.mask is None or self.declared_level(root.name) == self.level:
                self.line(f"{name} = {new}", s.loc)
            else:
                self.line(f"{name} = _sel({self.mask}, {new}, {name}, {_rank(root.ty)!r})", s.loc)
        elif isinstance(s, ir.If):
            self.if_stmt(s)
        elif isinstance(s, ir.Switch):
            self.switch_stmt(s)
        elif isinstance(s, ir.For) and s.bound is not None:
            self.runtime_for(s)
        elif isinstance(s, ir.For):
            self.line(f"for {self.t.ident(s.var)} in _range({int(s.count)}):", s.loc)
            self.depth += 1
            self.block(s.body, {s.var: self.level})
            self.depth -= 1
        elif isinstance(s, ir.Return):
            v, k = self.expr(s.value), _rank(s.value.ty)
            if self.mask is None:
                self.line(f"return _fin(_done, _ret, {v}, {k!r})" if self.ret_state else f"return {v}", s.loc)
            else:
                self.line(f"_ret = _retu(_ret, _done, {self.mask}, {v}, {k!r})", s.loc)
                self.line(f"_done = _done | {self.mask}", s.loc)
        else:
            raise NotImplementedError(f"{s.loc}: the numpy target cannot emit {type(s).__name__}")

    def if_stmt(self, s: ir.If) -> None:
        c = self.fresh("c")
        self.line(f"{c} = {self.expr(s.cond)}", s.loc)
        parent = self.mask
        m_then = c if parent is None else self.fresh("m")
        if parent is not None:
            self.line(f"{m_then} = {parent} & {c}", s.loc)
        m_else = None
        if s.orelse:
            m_else = self.fresh("m")
            self.line(f"{m_else} = ~{c}" if parent is None else f"{m_else} = {parent} & ~{c}", s.loc)
        self.level += 1
        for mask, body in ((m_then, s.then), (m_else, s.orelse)):
            if mask is not None and body:
                self.mask = mask
                self.scopes.append({})  # a branch's locals live at the branch level
                for st in body:
                    self.stmt(st)
                self.scopes.pop()
        self.level -= 1
        self.mask = parent

    def store(self, target, value: str):
        """(root variable, code for its new whole value) after storing `value` into `target`."""
        if isinstance(target, ir.Var):
            if target.scope not in ("local", "param"):
                raise NotImplementedError(f"{target.loc}: cannot assign to {target.scope} '{target.name}'")
            return target, value
        if isinstance(target, ir.Swizzle):
            return self.store(target.base, f"_setc({self.expr(target.base)}, {'xyzw'.index(target.components)}, {value})")
        if isinstance(target, ir.Member):
            return self.store(target.base, f"_setf({self.expr(target.base)}, {target.field!r}, {value})")
        if isinstance(target, ir.Index) and target.base.ty.kind == "array":
            k = _rank(target.base.ty.elem)
            return self.store(target.base, f"_aset({self.expr(target.base)}, {self.expr(target.index)}, {value}, {k!r})")
        if isinstance(target, ir.Index):
            fn = "_setcol" if target.base.ty.kind == "matrix" else "_setc"
            return self.store(target.base, f"{fn}({self.expr(target.base)}, {self.expr(target.index)}, {value})")
        raise NotImplementedError(f"{target.loc}: cannot assign to {type(target).__name__}")

    # ------------------------------------------------------------ expressions
    def expr(self, e) -> str:
        if isinstance(e, ir.Const):
            return self.const(e)
        if isinstance(e, ir.Var):
            if e.scope == "const":
                return _float_lit(CONSTANTS[e.name])
            if e.scope == "global":
                self.resources[e.name] = e.ty
                return f"_res({e.name!r})"
            return self.t.ident(e.name)
        if isinstance(e, ir.Unary):
            return f"(~{self.expr(e.operand)})" if e.op == "not" else f"(-{self.expr(e.operand)})"
        if isinstance(e, ir.Binary):
            return self.binary(e)
        if isinstance(e, ir.Call):
            return f"{self.t.ident(e.func)}({', '.join(self.expr(a) for a in e.args)})"
        if isinstance(e, ir.Intrinsic):
            return self.intrinsic(e)
        if isinstance(e, ir.Construct):
            return self.construct(e)
        if isinstance(e, ir.Swizzle):
            idx = ["xyzw".index(c) for c in e.components]
            return f"{self.expr(e.base)}[..., {idx[0] if len(idx) == 1 else idx}]"
        if isinstance(e, ir.Member):
            return f"{self.expr(e.base)}.{e.field}"
        if isinstance(e, ir.Index) and e.base.ty.kind in ("array", "buffer"):
            return f"_aidx({self.expr(e.base)}, {self.expr(e.index)}, {_rank(e.base.ty.elem)!r})"
        if isinstance(e, ir.Index):
            base, matrix = self.expr(e.base), e.base.ty.kind == "matrix"
            if isinstance(e.index, ir.Const):
                return f"{base}[..., :, {int(e.index.value)}]" if matrix else f"{base}[..., {int(e.index.value)}]"
            return f"{'_col' if matrix else '_idx'}({base}, {self.expr(e.index)})"
        if isinstance(e, ir.Select):
            return f"_sel({self.expr(e.cond)}, {self.expr(e.if_true)}, {self.expr(e.if_false)}, {_rank(e.ty)!r})"
        raise NotImplementedError(f"{e.loc}: the numpy target cannot emit {type(e).__name__}")

    def const(self, e: ir.Const) -> str:
        s = e.ty.scalar
        if s == "bool":
            return "np.True_" if e.value else "np.False_"
        if s == "float":
            return _float_lit(e.value)
        return f"{_DTYPES[s]}({int(e.value)})"

    def binary(self, e: ir.Binary) -> str:
        a, b = self.expr(e.lhs), self.expr(e.rhs)
        if e.op in ("and", "or"):
            return f"({a} {'&' if e.op == 'and' else '|'} {b})"
        if e.op in ("<", "<=", ">", ">=", "==", "!="):
            return f"({a} {e.op} {b})"
        lk, rk = e.lhs.ty.kind, e.rhs.ty.kind
        if e.op == "*" and lk == "matrix" and rk in ("vector", "matrix"):
            return f"{'_mv' if rk == 'vector' else '_mm'}({a}, {b})"
        if e.op == "*" and lk == "vector" and rk == "matrix":
            return f"_vm({a}, {b})"
        ra, rb = _rank(e.lhs.ty), _rank(e.rhs.ty)
        if ra == 0 and rb > 0 and not _static(e.lhs):
            a += "[..., None" + ", None" * (rb - 1) + "]"
        if rb == 0 and ra > 0 and not _static(e.rhs):
            b += "[..., None" + ", None" * (ra - 1) + "]"
        if e.ty.scalar in ("int", "uint") and e.op in ("/", "%"):
            return f"_idiv({a}, {b})" if e.op == "/" else f"np.fmod({a}, {b})"
        return f"({a} {e.op} {b})"

    def intrinsic(self, e: ir.Intrinsic) -> str:
        args = [self.expr(a) for a in e.args]
        n = e.name
        if n in ("sample", "sample_level"):  # level 0, or (sample_level of a mip chain: resources._lod) its lod
            dim = e.args[0].ty.dim
            if n == "sample_level" and not e.args[0].ty.arrayed:
                return f"_lod({_SAMPLERS[dim]}, {args[0]}, {args[1]}, {args[2]})"
            layer = f", {args[2]}" if e.args[0].ty.arrayed else ""
            return f"{_SAMPLERS[dim]}({args[0]}, {args[1]}{layer})"
        if n == "sample_compare":
            if e.args[0].ty.arrayed:
                return f"_tex2d_array_compare({args[0]}, {args[1]}, {args[2]}, {args[3]})"
            return f"_tex2d_compare({args[0]}, {args[1]}, {args[2]})"
        if n == "buffer_length":
            buf = e.args[0].ty
            return f"np.uint32({buf.size})" if buf.space == "uniform" else f"_blen({args[0]})"
        if n in _SIMPLE:
            return f"{_SIMPLE[n]}({', '.join(args)})"
        if n == "fract":
            return f"_fract({args[0]})"
        if n == "rsqrt":
            return f"(F(1.0) / np.sqrt({args[0]}))"
        if n == "saturate":
            return f"_clamp({args[0]}, F(0.0), F(1.0))"
        if n == "step":
            return f"np.where({args[1]} < {args[0]}, F(0.0), F(1.0))"
        if n == "mix":
            return f"_mix({args[0]}, {args[1]}, {args[2]})"
        if n == "select":
            return f"_sel({args[0]}, {args[1]}, {args[2]}, {_rank(e.ty)!r})"
        raise NotImplementedError(f"{e.loc}: the numpy target has no intrinsic '{n}'")

    def construct(self, e: ir.Construct) -> str:
        t, args = e.ty, [self.expr(a) for a in e.args]
        if t.kind == "struct":
            return f"_S_{t.name}({', '.join(args)})"
        if t.kind == "array":
            return f"_arr({_rank(t.elem)!r}, {', '.join(args)})"
        if t.kind == "scalar":
            return f"_cvt({args[0]}, {_DTYPES[t.scalar]})"
        if t.kind == "matrix":
            return f"_mat({', '.join(args)})"
        if len(args) == 1 and e.args[0].ty.kind == "scalar":
            return f"_splat({args[0]}, {t.size})"
        ranks = tuple(_rank(a.ty) for a in e.args)
        return f"_vec({ranks!r}, {', '.join(args)})"


def _static(e) -> bool:
    """A compile-time constant: a numpy scalar that broadcasts without expansion."""
    return isinstance(e, ir.Const) or (isinstance(e, ir.Var) and e.scope == "const")


class NumpyTarget(Target):
    name = "numpy"
    ext = "py"
    reserved = frozenset({"np", "F"})

    def type_name(self, t: Type) -> str:
        return t.name

    def emit(self, structs: list[Type], functions: list[ir.Function], globals: list[ir.Global] = ()) -> Emitted:
        """Structs, functions, and a table of the global resources read (given to load())."""
        rows: list[tuple[str, ir.Loc | None]] = [
            ("# Generated by shadermatrix (numpy target). Run through NumpyTarget.load(): needs np, F (float dtype).", None)]
        for st in structs:
            fields = tuple(f for f, _ in st.fields)
            rows.append((f"_S_{st.name} = _STRUCTS[{st.name!r}] = _struct({st.name!r}, {fields!r})", None))
        resources = {g.name: g.ty for g in globals}
        for fn in functions:
            rows.append(("", None))
            fe = _FunctionEmitter(self, fn)
            rows.extend(fe.emit())
            resources.update(fe.resources)
        if resources:
            rows.append(("", None))
        for name, ty in resources.items():
            rows.append((f"_RESOURCES[{name!r}] = ({ty.name!r}, {_spec(ty)!r})", None))
        text = "\n".join(r for r, _ in rows) + "\n"
        line_map = [(i + 1, loc.path, loc.line) for i, (_, loc) in enumerate(rows) if loc is not None]
        return Emitted(text, line_map)

    def load(self, emitted: Emitted | str, dtype, resources: dict | None = None) -> dict:
        """Execute emitted code with np and F = dtype; returns {brick name: function or struct class}.

        A loaded function takes arrays (or anything np.asarray accepts: floats, lists), converts
        them to the brick's types (floats to `dtype`, ints to int32, ...) and runs under
        np.errstate(all="ignore"), since masked-out lanes may divide by zero. Texture arguments
        are arrays of texel values (resources.py).

        resources: the global resources the functions read, by name: a buffer is an object (or
        dict) with the element struct's fields, each an array whose first axis is the element
        index (unpack_buffer() makes one from GPU bytes); a texture is an array as for texture
        arguments. They are converted like arguments, once, here.
        """
        text = emitted.text if isinstance(emitted, Emitted) else str(emitted)
        f = np.dtype(dtype).type
        ns = {"__builtins__": {}, "np": np, "F": f, "_FUNCTIONS": {}, "_STRUCTS": {}, "_RESOURCES": {}}
        ns.update(RUNTIME)
        ns.update(RESOURCE_RUNTIME)
        exec(compile(text, "<shadermatrix numpy target>", "exec"), ns)
        bound = {}
        for name, value in (resources or {}).items():
            ty, spec = ns["_RESOURCES"].get(name, ("", None))
            bound[name] = _coerce(_as_struct(value), spec, f) if spec is not None else value
        ns["_res"] = _reader(bound, ns["_RESOURCES"])
        out: dict = dict(ns["_STRUCTS"])
        for name, (fn, specs) in ns["_FUNCTIONS"].items():
            out[name] = _entry(fn, specs, f)
        return out


    @staticmethod
    def unpack_buffer(elem: Type, data):
        """A buffer value of `elem` structs from the bytes of its GPU buffer (resources.py)."""
        return unpack_buffer(elem, data, _struct)


def _as_struct(value):
    """Dicts (as buffers may be given) become attribute holders, recursively."""
    if isinstance(value, dict):
        return _struct("buffer", tuple(value))(*(_as_struct(v) for v in value.values()))
    return value


def _reader(bound: dict, declared: dict):
    def _res(name):
        try:
            return bound[name]
        except KeyError:
            ty = declared.get(name, ("resource",))[0]
            raise LookupError(f"the program reads global {ty} '{name}': pass it to "
                              f"NumpyTarget.load(..., resources={{'{name}': ...}})") from None
    return _res


def _entry(fn, specs, f):
    @functools.wraps(fn)
    def call(*args):
        if len(args) != len(specs):
            raise TypeError(f"{fn.__name__}() takes {len(specs)} arguments, got {len(args)}")
        with np.errstate(all="ignore"):
            return fn(*(_coerce(a, s, f) for a, s in zip(args, specs)))
    return call
