"""HLSL through glslang's HLSL front end (glslc -x hlsl) and, in spirit, DXC.

IR matrices are column-major like GLSL and their HLSL values are the same
mathematical matrices: a column list becomes transpose(floatNxN(rows...)),
products become mul(), and column i of m is read as transpose(m)[i] (written
component by component, m[r][i]). Structs get a `_make_S(...)` constructor
function, since HLSL has no struct constructor expression; an array value is an
initializer list `{a, b, c}`, valid only where the IR puts it (a declaration).
Buffers: StructuredBuffer (t register) and cbuffer (b register), clike/resources.py.
"""
from __future__ import annotations

from ...lang import ir
from ...lang.types import Type
from ..clike import reserved
from ..clike.walk import SAMPLING, CLikeTarget, Writer

_COMPONENT = {"x": 0, "y": 1, "z": 2, "w": 3}


class HlslTarget(CLikeTarget):
    name = "hlsl"
    ext = "hlsl"

    SCALARS = {"float": "float", "int": "int", "uint": "uint", "bool": "bool"}
    VECTORS = {"float": "float{n}", "int": "int{n}", "uint": "uint{n}", "bool": "bool{n}"}
    MATRIX = "float{n}x{n}"
    TEXTURE = "Texture2D"
    TEXTURE_CUBE = "TextureCube"
    TEXTURE_SHADOW = "Texture2D"  # a depth texture is a Texture2D; its sampler makes the compare
    TEXTURE_ARRAY = "Texture2DArray"
    TEXTURE_CUBE_ARRAY = "TextureCubeArray"
    TEXTURE_ARRAY_SHADOW = "Texture2DArray"
    SAMPLER = "SamplerState"
    SAMPLER_COMPARE = "SamplerComparisonState"
    INTRINSICS = {
        "fract": "frac({0})",
        "mix": "lerp({0}, {1}, {2})",
        "select": "({0} ? {1} : {2})",
        "sample": "{0}.Sample({smp}, {1})",
        "sample_level": "{0}.SampleLevel({smp}, {1}, {2})",
        # level 0 (valid in non-uniform control flow, unlike SampleCmp's implicit LOD)
        "sample_compare": "{0}.SampleCmpLevelZero({smp}, {1}, {2})",
        # an array's layer is the last coordinate, a float (exact for an int layer: generator/lang/sampling.py)
        "sample@2d_array": "{0}.Sample({smp}, float3({1}, float({2})))",
        "sample_level@2d_array": "{0}.SampleLevel({smp}, float3({1}, float({2})), {3})",
        "sample@cube_array": "{0}.Sample({smp}, float4({1}, float({2})))",
        "sample_level@cube_array": "{0}.SampleLevel({smp}, float4({1}, float({2})), {3})",
        "sample_compare@2d_array": "{0}.SampleCmpLevelZero({smp}, float3({1}, float({2})), {3})",
    }

    def declare_spec_constant(self, name: str, ty: Type, constant_id: int) -> str:
        return f"[[vk::constant_id({int(constant_id)})]] const {self.type_name(ty)} {self.ident(name)} = 0;"

    def declare_texture(self, name: str, set: int, binding: int, dim: str = "2d", compare: bool = False) -> str:
        """Texture2D (TextureCube, Texture2DArray, TextureCubeArray) NAME at binding B and SamplerState (compare: SamplerComparisonState)
        _smp_NAME at B+1 of set S (t/s registers alike)."""
        s, b = int(set), int(binding)
        image = self.image_type(dim, compare)
        return (f"[[vk::binding({b}, {s})]] {image} {self.ident(name)} : register(t{b}, space{s});\n"
                f"[[vk::binding({b + 1}, {s})]] {self.sampler_type(compare)} {self.sampler_name(name)} : "
                f"register(s{b + 1}, space{s});")

    def buffer_decl(self, name: str, elem: str, set: int, binding: int, kind: str, capacity: int) -> str:
        head = f"[[vk::binding({binding}, {set})]]"
        if kind == "storage":
            length = reserved.LENGTH_PREFIX + name
            return (f"{head} StructuredBuffer<{elem}> {name} : register(t{binding}, space{set});\n"
                    f"uint {length}() {{ uint n, stride; {name}.GetDimensions(n, stride); return n; }}")
        return (f"{head} cbuffer {self.block_name(name)} : register(b{binding}, space{set}) "
                f"{{ {elem} {name}[{capacity}]; }};")

    def storage_length(self, name: str) -> str:
        return f"{reserved.LENGTH_PREFIX}{name}()"

    def initializer(self, e: ir.Expr) -> str:
        if isinstance(e, ir.Construct) and e.ty.kind == "array":
            return f"{{{', '.join(self.expr(a) for a in e.args)}}}"
        return super().initializer(e)

    def array_value(self, t: Type, elems: list[str]) -> str:
        raise ValueError(f"HLSL has no array expression ({t}): build an array only as the value of a "
                         "Decl (ir.Decl(loc, name, array_type, ir.Construct(array_type, loc, elements)))")

    # ------------------------------------------------------------ structs
    def struct_decl(self, w: Writer, s: Type) -> None:
        super().struct_decl(w, s)
        name = self.ident(s.name)
        fields = [self.ident(f) for f, _ in s.fields]
        params = ", ".join(self.var_decl(f, t) for f, (_, t) in zip(fields, s.fields))
        w.line(f"{name} {self.maker(s)}({params}) {{")
        w.depth += 1
        w.line(f"{name} _s;")
        for f in fields:
            w.line(f"_s.{f} = {f};")
        w.line("return _s;")
        w.depth -= 1
        w.line("}")

    def maker(self, s: Type) -> str:
        return "_make_" + self.ident(s.name)

    def struct_value(self, t: Type, args: list[str]) -> str:
        return f"{self.maker(t)}({', '.join(args)})"

    # ------------------------------------------------------------ matrices
    def splat(self, t: Type, x: str) -> str:
        return f"(({self.type_name(t)})({x}))"  # HLSL has no one-scalar vector constructor

    def matrix(self, t: Type, columns: list[str]) -> str:
        return f"transpose({self.type_name(t)}({', '.join(columns)}))"

    def expr_binary(self, e: ir.Binary) -> str:
        if e.op == "*" and _is_product(e.lhs.ty, e.rhs.ty):
            return f"mul({self.expr(e.lhs)}, {self.expr(e.rhs)})"
        return super().expr_binary(e)

    def expr_index(self, e: ir.Index) -> str:
        col = _column(e.base)
        if col is not None:  # m[i][j]: row j, column i
            return f"{self.expr(col.base)}[{self.expr(e.index)}][{self.expr(col.index)}]"
        if e.base.ty.kind == "matrix":
            return f"transpose({self.expr(e.base)})[{self.expr(e.index)}]"
        return super().expr_index(e)

    def expr_swizzle(self, e: ir.Swizzle) -> str:
        col = _column(e.base)
        if col is not None and len(e.components) == 1:  # m[i].y: row 1, column i
            return f"{self.expr(col.base)}[{_COMPONENT[e.components]}][{self.expr(col.index)}]"
        return super().expr_swizzle(e)

    def expr_intrinsic(self, e: ir.Intrinsic) -> str:
        if e.name == "sign" and e.ty.scalar == "float":  # HLSL sign() returns int
            return f"{self.type_name(e.ty)}(sign({self.expr(e.args[0])}))"
        return super().expr_intrinsic(e)

    # ------------------------------------------------------------ assignment
    def assign(self, w: Writer, s: ir.Assign) -> None:
        col = _column(s.target)
        if col is not None:  # m[i] = v: write column i one row at a time, on one line for #line
            m, i, op = self.expr(col.base), self.expr(col.index), s.op or ""
            scalar = s.value.ty.kind == "scalar"
            rows = " ".join(f"{m}[{r}][{i}] {op}= {'_c' if scalar else '_c.' + 'xyzw'[r]};"
                            for r in range(col.ty.size))
            w.line(f"{{ {self.type_name(s.value.ty)} _c = {self.expr(s.value)}; {rows} }}", s.loc)
            return
        if s.op == "*" and _is_product(s.target.ty, s.value.ty):  # HLSL *= is component-wise
            t = self.expr(s.target)
            w.line(f"{t} = mul({t}, {self.expr(s.value)});", s.loc)
            return
        super().assign(w, s)


def _is_product(a: Type, b: Type) -> bool:
    """A matrix product (matrix with matrix or vector), not scaling by a scalar."""
    kinds = {a.kind, b.kind}
    return "matrix" in kinds and "scalar" not in kinds


def _column(e: ir.Expr) -> ir.Index | None:
    """e as `m[i]`, a column of a matrix, or None."""
    if isinstance(e, ir.Index) and e.base.ty.kind == "matrix":
        return e
    return None


class HlslHalfTarget(HlslTarget):
    """HLSL at fp16: `half`, `halfN` and `h` literals, compiled with 16-bit types on (glslc
    -fhlsl-16bit-types, DXC's -enable-16bit-types): real SPIR-V Float16, not min16float's
    RelaxedPrecision float. glslang's HLSL front end accepts neither `float16_t` nor 16-bit
    matrices in mul()/transpose(), so matrices stay floatNxN: a product with one runs in 32 bits
    (its vector operand converted), and a matrix element read converts back to half. glslang
    refuses implicit float -> half, so every such crossing is an explicit cast."""

    precision = "fp16"
    SCALARS = {**HlslTarget.SCALARS, "float": "half"}
    VECTORS = {**HlslTarget.VECTORS, "float": "half{n}"}
    FLOAT_SUFFIX = "h"

    def convert(self, t: Type, x: str) -> str:
        return f"(({self.type_name(t)})({x}))"

    def expr_binary(self, e: ir.Binary) -> str:
        if e.op == "*" and _is_product(e.lhs.ty, e.rhs.ty):
            lhs, rhs = (self.to32(a.ty, self.expr(a)) for a in (e.lhs, e.rhs))
            return self.from32(e.ty, f"mul({lhs}, {rhs})")
        return super().expr_binary(e)

    def expr_index(self, e: ir.Index) -> str:
        text = super().expr_index(e)
        if _column(e.base) is not None or e.base.ty.kind == "matrix":
            return self.convert(e.ty, text)
        return text

    def expr_swizzle(self, e: ir.Swizzle) -> str:
        col = _column(e.base)
        text = super().expr_swizzle(e)
        return self.convert(e.ty, text) if col is not None and len(e.components) == 1 else text

    def expr_intrinsic(self, e: ir.Intrinsic) -> str:
        """glslang's HLSL front end (glslc 2023.2, glslang 11.13) has no 16-bit overloads of the intrinsics:
        max, clamp, rsqrt, pow, ... promote their half arguments to float and return float (SPIR-V
        `OpExtInst %float Pow`), which it will not narrow implicitly. Every float-valued intrinsic is cast
        back to half: exact for min/max/clamp/abs; a transcendental runs in 32 bits and rounds once, so
        HLSL's fp16 errors are somewhat below GLSL's and WGSL's (phong_normalized: 3.5e-2 against 9.3e-2;
        DXC would keep them half). +, -, *, / and the brick's own functions are half as in GLSL."""
        text = super().expr_intrinsic(e)
        if _has_float_value(e.ty) and e.name not in SAMPLING:
            return self.convert(e.ty, text)
        return text

    def assign(self, w: Writer, s: ir.Assign) -> None:
        if s.op == "*" and _is_product(s.target.ty, s.value.ty):
            t = self.expr(s.target)
            w.line(f"{t} = {self.from32(s.target.ty, f'mul({self.to32(s.target.ty, t)}, {self.to32(s.value.ty, self.expr(s.value))})')};",
                   s.loc)
            return
        super().assign(w, s)

    def type_name(self, t: Type) -> str:
        if t.kind == "matrix":
            return HlslTarget.MATRIX.format(n=t.size)
        return super().type_name(t)


def _has_float_value(t: Type) -> bool:
    return t.kind in ("scalar", "vector") and t.scalar == "float"
