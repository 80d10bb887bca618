"""Typing of expressions: literals, names, operators, swizzles, constructors, calls, intrinsics.

The expression half of the checker (generator/lang/typecheck.py holds the
statements). No implicit conversions: WGSL has none, so `2 * x` with a float
x is an error that asks for `2.0 * x`. Scalar/vector mixing in arithmetic is
allowed (every target has it); scalar arguments to vector intrinsics are
splatted explicitly in the IR.
"""
from __future__ import annotations

import ast

from . import ir
from .intrinsics import CONSTANTS, INTRINSICS
from .sampling import SAMPLING_SIGS, SamplingError, sample_call
from .types import BOOL, BUILTIN_TYPES, FLOAT, INT, UINT, Type, vector

ARITH = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Mod: "%"}
_CMP = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
F32_MAX = 3.4028234663852886e38
_SWZ = {"x": "x", "y": "y", "z": "z", "w": "w", "r": "x", "g": "y", "b": "z", "a": "w"}


class ExprChecker:
    """Expression lowering; the subclass provides scopes (lookup), structs, constants, sigs, loc and err."""

    def expr(self, n) -> ir.Expr:
        loc = self.loc(n)
        if isinstance(n, ast.Constant):
            v = n.value
            if type(v) is bool:
                return ir.Const(BOOL, loc, v)
            if type(v) is int:
                if not -2**31 <= v < 2**31:
                    raise self.err(n, f"int literal {v} does not fit in 32 bits", "use a smaller value or a float")
                return ir.Const(INT, loc, v)
            if type(v) is float:
                if not abs(v) <= F32_MAX:
                    raise self.err(n, f"float literal {v!r} is outside the fp32 range", "use a value below 3.4e38")
                return ir.Const(FLOAT, loc, v)
            raise self.err(n, f"literal {v!r} is not allowed", "bricks use numbers and True/False only")
        if isinstance(n, ast.Name):
            return self.name(n)
        if isinstance(n, ast.UnaryOp):
            v = self.expr(n.operand)
            if isinstance(n.op, ast.UAdd):
                return v
            if isinstance(n.op, ast.USub):
                if not v.ty.is_numeric or v.ty.scalar == "uint":
                    raise self.err(n, f"cannot negate {v.ty}", "negate a float or int value")
                if isinstance(v, ir.Const):
                    return ir.Const(v.ty, loc, -v.value)
                return ir.Unary(v.ty, loc, "-", v)
            if isinstance(n.op, ast.Not):
                if v.ty != BOOL:
                    raise self.err(n, f"'not' needs a bool, got {v.ty}", "compare first, e.g. not (x > 0.0)")
                return ir.Unary(BOOL, loc, "not", v)
            raise self.err(n, "bitwise operators are not allowed", "use arithmetic")
        if isinstance(n, ast.BinOp):
            op = ARITH.get(type(n.op))
            if op is None:
                hint = "use pow(x, y)" if isinstance(n.op, ast.Pow) else "use + - * / (and % on ints)"
                raise self.err(n, f"operator '{type(n.op).__name__}' is not allowed", hint)
            a, b = self.expr(n.left), self.expr(n.right)
            return ir.Binary(self.binary_type(n, op, a.ty, b.ty), loc, op, a, b)
        if isinstance(n, ast.BoolOp):
            op = "and" if isinstance(n.op, ast.And) else "or"
            vals = [self.condition(v) for v in n.values]
            out = vals[0]
            for v in vals[1:]:
                out = ir.Binary(BOOL, loc, op, out, v)
            return out
        if isinstance(n, ast.Compare):
            if len(n.ops) != 1:
                raise self.err(n, "chained comparisons are not allowed", "write (a < b) and (b < c)")
            op = _CMP.get(type(n.ops[0]))
            if op is None:
                raise self.err(n, "only < <= > >= == != compare values", "use one of them")
            a, b = self.expr(n.left), self.expr(n.comparators[0])
            if not (a.ty.kind == "scalar" and a.ty == b.ty):
                raise self.err(n, f"cannot compare {a.ty} with {b.ty}",
                               "compare scalars of one type (write 0.0 for a float zero; compare vector components one by one)")
            if a.ty == BOOL and op not in ("==", "!="):
                raise self.err(n, "bools compare only with == and !=", "use and/or/not")
            return ir.Binary(BOOL, loc, op, a, b)
        if isinstance(n, ast.IfExp):
            c = self.condition(n.test)
            a, b = self.expr(n.body), self.expr(n.orelse)
            if a.ty != b.ty:
                raise self.err(n, f"the two sides of a conditional expression differ: {a.ty} and {b.ty}",
                               "make both sides the same type")
            if a.ty.kind not in ("scalar", "vector"):
                raise self.err(n, f"a conditional expression cannot choose between {a.ty} values (WGSL select)",
                               "use an if/else statement that assigns a local")
            return ir.Select(a.ty, loc, c, a, b)
        if isinstance(n, ast.Call):
            return self.call(n)
        if isinstance(n, ast.Attribute):
            base = self.expr(n.value)
            if base.ty.kind == "vector":
                comps = n.attr
                if not comps or len(comps) > 4 or any(c not in _SWZ for c in comps):
                    raise self.err(n, f"'{comps}' is not a swizzle", "use up to 4 of x y z w (or r g b a)")
                mapped = "".join(_SWZ[c] for c in comps)
                if any("xyzw".index(c) >= base.ty.size for c in mapped):
                    raise self.err(n, f"swizzle '.{comps}' reads past a {base.ty}", f"{base.ty} has {base.ty.size} components")
                return ir.Swizzle(vector(base.ty.scalar, len(mapped)), loc, base, mapped)
            if base.ty.kind == "struct":
                ft = base.ty.field(n.attr)
                if ft is None:
                    raise self.err(n, f"struct {base.ty} has no field '{n.attr}'",
                                   f"fields: {', '.join(f for f, _ in base.ty.fields)}")
                return ir.Member(ft, loc, base, n.attr)
            raise self.err(n, f"{base.ty} has no attribute '{n.attr}'", "swizzle vectors (v.xy), read struct fields (s.f)")
        if isinstance(n, ast.Subscript):
            return self.subscript(n)
        kinds = {"List": "lists", "Tuple": "tuples", "Dict": "dicts", "Lambda": "lambdas",
                 "ListComp": "comprehensions", "JoinedStr": "strings"}
        kind = type(n).__name__
        raise self.err(n, f"{kinds.get(kind, kind)} are not allowed in a brick expression",
                       "use arithmetic, comparisons, calls, swizzles and `a if c else b`")

    def subscript(self, n: ast.Subscript) -> ir.Expr:
        loc = self.loc(n)
        base = self.expr(n.value)
        idx = self.expr(n.slice)
        if idx.ty not in (INT, UINT):
            raise self.err(n.slice, f"index must be int or uint, got {idx.ty}", "use an int expression")
        size = {"vector": base.ty.size, "array": base.ty.size}.get(base.ty.kind, 0)
        if base.ty.kind == "buffer" and base.ty.space == "uniform":
            size = base.ty.size
        if size and isinstance(idx, ir.Const) and not 0 <= idx.value < size:
            raise self.err(n.slice, f"index {idx.value} is out of range for {base.ty}", f"use 0..{size - 1}")
        if base.ty.kind == "vector":
            return ir.Index(vector(base.ty.scalar, 1), loc, base, idx)
        if base.ty.kind == "matrix":
            return ir.Index(vector("float", base.ty.size), loc, base, idx)
        if base.ty.kind in ("array", "buffer"):
            return ir.Index(base.ty.elem, loc, base, idx)
        raise self.err(n, f"cannot index {base.ty}", "index vectors, matrices, arrays and buffers")

    def name(self, n: ast.Name) -> ir.Expr:
        loc = self.loc(n)
        found = self.lookup(n.id)
        if found is not None:
            ty, scope = found
            return ir.Var(ty, loc, n.id, "local" if scope == "loopvar" else scope)
        resources = getattr(self, "globals", None) or {}
        if n.id in resources:
            return ir.Var(resources[n.id].ty, loc, n.id, "global")
        if n.id in self.constants:
            c = self.constants[n.id]
            return ir.Const(c.ty, loc, c.value)
        if n.id in CONSTANTS:
            return ir.Var(FLOAT, loc, n.id, "const")
        if n.id in ("True", "False"):
            return ir.Const(BOOL, loc, n.id == "True")
        raise self.err(n, f"unknown name '{n.id}'", "declare it first, or pass it as a parameter")

    def binary_type(self, node, op, a: Type, b: Type) -> Type:
        if not (a.is_numeric and b.is_numeric):
            raise self.err(node, f"'{op}' needs numbers, got {a} and {b}", "use arithmetic on float/int values")
        if a.scalar != b.scalar:
            hint = "write float literals with a decimal point (2.0), or convert with float(i)"
            raise self.err(node, f"cannot combine {a} and {b} with '{op}' (no implicit conversions)", hint)
        if op == "%" and a.scalar == "float":
            raise self.err(node, "'%' on floats differs between GLSL, HLSL and WGSL", "use x - y * floor(x / y)")
        if a == b:
            if a.kind == "matrix" and op not in ("*", "+", "-"):
                raise self.err(node, f"'{op}' on matrices is not allowed", "use * + -")
            return a
        if a.kind == "scalar" and b.kind == "vector":
            return b
        if a.kind == "vector" and b.kind == "scalar":
            return a
        if op == "*" and a.kind == "matrix" and b.kind == "vector" and a.size == b.size:
            return b
        if op == "*" and a.kind == "vector" and b.kind == "matrix" and a.size == b.size:
            return a
        if op == "*" and {a.kind, b.kind} == {"matrix", "scalar"}:
            return a if a.kind == "matrix" else b
        raise self.err(node, f"cannot combine {a} and {b} with '{op}'", "operands must have matching shapes")

    # ------------------------------------------------------------ calls
    def call(self, n: ast.Call) -> ir.Expr:
        loc = self.loc(n)
        if not isinstance(n.func, ast.Name):
            raise self.err(n, "only plain function names can be called", "call an intrinsic, a type or a brick function")
        if n.keywords:
            raise self.err(n.keywords[0], "keyword arguments are not allowed", "pass arguments by position")
        fname = n.func.id
        args = [self.expr(a) for a in n.args]
        if fname in BUILTIN_TYPES:
            return self.construct(n, BUILTIN_TYPES[fname], args)
        if fname in self.structs:
            st = self.structs[fname]
            want = [t for _, t in st.fields]
            if [a.ty for a in args] != want:
                raise self.err(n, f"{fname}(...) takes ({', '.join(map(str, want))}), got ({', '.join(str(a.ty) for a in args)})",
                               "pass every field in declaration order")
            return ir.Construct(st, loc, args)
        if fname in INTRINSICS:
            return self.intrinsic(n, fname, args)
        if fname in self.sigs:
            sig = self.sigs[fname]
            want = [t for _, t in sig.params]
            got = [a.ty for a in args]
            if got != want:
                params = ", ".join(f"{p}: {t}" for p, t in sig.params)
                raise self.err(n, f"{fname}({', '.join(map(str, got))}) does not match {fname}({params})",
                               "pass arguments of exactly these types")
            self.calls.append(fname)
            return ir.Call(sig.ret, loc, fname, args)
        if fname == "range":
            raise self.err(n, "range() is only allowed in a for loop", "write for i in range(N)")
        raise self.err(n, f"unknown function '{fname}'",
                       "call an intrinsic (docs/reference/language.md), a type constructor, or a function of "
                       "this brick or its slots")

    def construct(self, n, ty: Type, args) -> ir.Expr:
        loc = self.loc(n)
        if ty.kind == "texture":
            raise self.err(n, "textures cannot be constructed", f"declare a {ty} parameter")
        if ty.kind == "scalar":
            if len(args) != 1 or args[0].ty.kind != "scalar":
                raise self.err(n, f"{ty}(...) converts one scalar", f"write {ty}(x)")
            if args[0].ty == ty:
                return args[0]
            if isinstance(args[0], ir.Const) and ty != BOOL and args[0].ty != BOOL:
                value = float(args[0].value) if ty == FLOAT else int(args[0].value)
                lo, hi = {"int": (-2**31, 2**31 - 1), "uint": (0, 2**32 - 1), "float": (-F32_MAX, F32_MAX)}[ty.name]
                if not lo <= value <= hi:
                    raise self.err(n, f"{ty}({args[0].value!r}) is outside the range of {ty}", "use a value that fits")
                return ir.Const(ty, loc, value)
            return ir.Construct(ty, loc, args)
        if ty.kind == "vector":
            if len(args) == 1 and args[0].ty.kind == "scalar":
                if args[0].ty.scalar != ty.scalar:
                    raise self.err(n, f"{ty}({args[0].ty}) mixes element types", "convert the scalar first")
                return ir.Construct(ty, loc, args)
            total = 0
            for a in args:
                if a.ty.kind not in ("scalar", "vector") or a.ty.scalar != ty.scalar:
                    raise self.err(n, f"{ty}(...) cannot take {a.ty}", f"pass {ty.scalar} scalars or vectors")
                total += a.ty.size
            if total != ty.size:
                raise self.err(n, f"{ty}(...) got {total} components, needs {ty.size}", "pass exactly enough components")
            return ir.Construct(ty, loc, args)
        if ty.kind == "matrix":
            col = vector("float", ty.size)
            if len(args) == ty.size and all(a.ty == col for a in args):
                return ir.Construct(ty, loc, args)
            raise self.err(n, f"{ty}(...) takes {ty.size} {col} columns", f"write {ty}(c0, c1, ...)")
        raise self.err(n, f"cannot construct {ty}", "")

    def splat(self, e: ir.Expr, ty: Type) -> ir.Expr:
        if e.ty == ty or ty.kind != "vector" or e.ty.kind != "scalar" or e.ty.scalar != ty.scalar:
            return e
        return ir.Construct(ty, e.loc, [e])

    def intrinsic(self, n, name, args) -> ir.Expr:
        loc = self.loc(n)
        sig = INTRINSICS[name]["sig"]
        if sig in SAMPLING_SIGS:
            return self.sampling(n, name, args)
        arity = {"gen": 1, "gen2": 2, "gen3": 3, "mix": 3, "minmax": 2, "absign": 1, "dot": 2, "length": 1,
                 "cross": 2, "normalize": 1, "reflect": 2, "step": 2, "select": 3, "buffer_length": 1}[sig]
        if len(args) != arity:
            raise self.err(n, f"{name} takes {arity} argument{'s' if arity != 1 else ''}, got {len(args)}",
                           "see the intrinsics table in generator/lang/intrinsics.py")
        types = [a.ty for a in args]

        def fail(want):
            return self.err(n, f"{name}({', '.join(map(str, types))}) is not defined", f"{name} takes {want}")

        def floatish(t):
            return t.kind in ("scalar", "vector") and t.scalar == "float"

        if sig in ("gen", "gen2", "gen3", "mix", "step"):
            shape = next((t for t in types if t.kind == "vector"), types[0])
            if sig == "mix":
                shape = types[0]
            if not all(floatish(t) for t in types):
                raise fail("float scalars or vectors")
            args = [self.splat(a, shape) for a in args]
            if any(a.ty != shape for a in args):
                raise fail("arguments of one shape (or float scalars, which are splatted)")
            return ir.Intrinsic(shape, loc, name, args)
        if sig in ("minmax", "absign"):
            shape = next((t for t in types if t.kind == "vector"), types[0])
            if not all(t.kind in ("scalar", "vector") and t.scalar in ("float", "int") for t in types):
                raise fail("float or int scalars or vectors")
            args = [self.splat(a, shape) for a in args]
            if any(a.ty != shape for a in args):
                raise fail("arguments of one type")
            return ir.Intrinsic(shape, loc, name, args)
        if sig in ("dot", "reflect"):
            if not (types[0].kind == "vector" and floatish(types[0]) and types[0] == types[1]):
                raise fail("two float vectors of one size")
            return ir.Intrinsic(FLOAT if sig == "dot" else types[0], loc, name, args)
        if sig in ("length", "normalize"):
            if not (types[0].kind == "vector" and floatish(types[0])):
                raise fail("a float vector")
            return ir.Intrinsic(FLOAT if sig == "length" else types[0], loc, name, args)
        if sig == "cross":
            if types != [vector("float", 3)] * 2:
                raise fail("two vec3")
            return ir.Intrinsic(types[0], loc, name, args)
        if sig == "select":
            if types[0] != BOOL or types[1] != types[2] or types[1].kind not in ("scalar", "vector"):
                raise fail("(bool, T, T) with T a scalar or vector (WGSL select)")
            return ir.Intrinsic(types[1], loc, name, args)
        if sig == "buffer_length":
            if types[0].kind != "buffer":
                raise fail("a buffer declared at the top level of the brick")
            return ir.Intrinsic(UINT, loc, name, args)
        raise AssertionError(sig)

    def sampling(self, n, name, args) -> ir.Expr:
        """sample, sample_level, sample_compare (generator/lang/sampling.py); the texture is a parameter."""
        if not args or args[0].ty.kind != "texture" or len(args) < 2:
            shown = ", ".join(str(a.ty) for a in args)
            raise self.err(n, f"{name}({shown}) is not defined", f"{name} takes a texture parameter and a coordinate "
                           "(see the intrinsics table in generator/lang/intrinsics.py)")
        try:
            call = sample_call(name, self.loc(n), *args)
        except SamplingError as e:
            raise self.err(n, e.message, e.hint) from None
        if not isinstance(args[0], ir.Var) or args[0].scope != "param":
            raise self.err(n, f"{name}() takes a texture parameter", "pass the texture as a function parameter")
        return call
