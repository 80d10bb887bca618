"""WGSL as naga accepts it: typed literals, immutable parameters, select() for conditionals.

Switches always carry a default clause (WGSL requires one) and never fall through;
arrays are array<T, N> values; buffers are var<storage, read> / var<uniform> arrays
(clike/resources.py).
"""
from __future__ import annotations

from ...lang import ir
from ...lang.types import Type
from ..clike.walk import CLikeTarget, Writer

PARAM_COPY_PREFIX = "_in_"


class WgslTarget(CLikeTarget):
    name = "wgsl"
    ext = "wgsl"
    line_directives = False  # WGSL has no #line; toolchain maps naga's lines through line_map

    SCALARS = {"float": "f32", "int": "i32", "uint": "u32", "bool": "bool"}
    VECTORS = {"float": "vec{n}<f32>", "int": "vec{n}<i32>", "uint": "vec{n}<u32>", "bool": "vec{n}<bool>"}
    MATRIX = "mat{n}x{n}<f32>"
    TEXTURE = "texture_2d<f32>"
    TEXTURE_CUBE = "texture_cube<f32>"
    TEXTURE_SHADOW = "texture_depth_2d"
    TEXTURE_ARRAY = "texture_2d_array<f32>"
    TEXTURE_CUBE_ARRAY = "texture_cube_array<f32>"
    TEXTURE_ARRAY_SHADOW = "texture_depth_2d_array"
    SAMPLER = "sampler"
    SAMPLER_COMPARE = "sampler_comparison"
    DEFAULT_REQUIRED = True
    CASE_BREAK = False
    # Typed literals keep constant folding in f32/i32, as GLSL and HLSL do (abstract numbers fold in f64).
    SIGNED_MOD_BY_DIVISION = False  # WGSL's % on i32 already truncates
    FLOAT_SUFFIX = "f"
    INT_SUFFIX = "i"
    INTRINSICS = {
        "rsqrt": "inverseSqrt({0})",
        "select": "select({2}, {1}, {0})",  # WGSL: select(if_false, if_true, cond)
        "sample": "textureSample({0}, {smp}, {1})",
        "sample_level": "textureSampleLevel({0}, {smp}, {1}, {2})",
        # level 0: valid in non-uniform control flow, unlike textureSampleCompare
        "sample_compare": "textureSampleCompareLevel({0}, {smp}, {1}, {2})",
        # an array's layer is WGSL's integer array_index (i32 or u32), after the coordinate
        "sample@2d_array": "textureSample({0}, {smp}, {1}, {2})",
        "sample_level@2d_array": "textureSampleLevel({0}, {smp}, {1}, {2}, {3})",
        "sample@cube_array": "textureSample({0}, {smp}, {1}, {2})",
        "sample_level@cube_array": "textureSampleLevel({0}, {smp}, {1}, {2}, {3})",
        "sample_compare@2d_array": "textureSampleCompareLevel({0}, {smp}, {1}, {2}, {3})",
    }

    def declare_spec_constant(self, name: str, ty: Type, constant_id: int) -> str:
        zero = "0i" if ty.scalar == "int" else "0u"
        return f"@id({int(constant_id)}) override {self.ident(name)}: {self.type_name(ty)} = {zero};"

    def declare_texture(self, name: str, set: int, binding: int, dim: str = "2d", compare: bool = False) -> str:
        """texture_2d<f32> (texture_cube<f32>, texture_2d_array<f32>, texture_cube_array<f32>; compare:
        texture_depth_2d, texture_depth_2d_array) NAME at binding B and sampler
        (compare: sampler_comparison) _smp_NAME at B+1 of group S."""
        s, b = int(set), int(binding)
        return (f"@group({s}) @binding({b}) var {self.ident(name)}: {self.image_type(dim, compare)};\n"
                f"@group({s}) @binding({b + 1}) var {self.sampler_name(name)}: {self.sampler_type(compare)};")

    def buffer_decl(self, name: str, elem: str, set: int, binding: int, kind: str, capacity: int) -> str:
        if kind == "storage":
            return f"@group({set}) @binding({binding}) var<storage, read> {name}: array<{elem}>;"
        return f"@group({set}) @binding({binding}) var<uniform> {name}: array<{elem}, {capacity}>;"

    def storage_length(self, name: str) -> str:
        return f"arrayLength(&{name})"

    def array_type(self, t: Type) -> str:
        return f"array<{self.type_name(t.elem)}, {t.size}>"

    def var_decl(self, name: str, t: Type) -> str:
        return f"{name}: {self.type_name(t)}"

    def sampler_decl(self, name: str, compare: bool = False) -> str:
        return f"{name}: {self.sampler_type(compare)}"

    def declare_local(self, name: str, t: Type) -> str:
        return f"var {self.var_decl(name, t)};"

    def switch_head(self, selector: str) -> str:
        return f"switch {selector} {{"

    def case_labels(self, t: Type, values: tuple[int, ...] | None) -> list[str]:
        if values is None:
            return ["default: {"]
        return [f"case {', '.join(self.case_label_value(t, v) for v in values)}: {{"]

    def for_bound_head(self, var: str, t: Type, bound: str) -> str:
        return f"for (var {var}: {self.type_name(t)} = {self.literal(t, 0)}; {var} < {bound}; {var}++) {{"

    def struct_decl(self, w: Writer, s: Type) -> None:
        w.line(f"struct {self.ident(s.name)} {{")
        w.depth += 1
        for f, t in s.fields:
            w.line(f"{self.var_decl(self.ident(f), t)},")
        w.depth -= 1
        w.line("}")

    # ------------------------------------------------------------ functions
    def param_list(self, f: ir.Function) -> list[str]:
        copies = _param_copies(f)
        out = []
        for p in f.params:
            out += [self.var_decl(copies[p.name], p.ty)] if p.name in copies else self.params(p)
        return out

    def signature(self, f: ir.Function, params: str) -> str:
        return f"fn {self.ident(f.name)}({params}) -> {self.type_name(f.ret)} {{"

    def prologue(self, w: Writer, f: ir.Function) -> None:
        """WGSL parameters are immutable: an assigned one is copied into a var of its name."""
        copies = _param_copies(f)
        for p in f.params:
            if p.name in copies:
                w.line(self.decl(self.ident(p.name), p.ty, copies[p.name]), f.loc)

    # ------------------------------------------------------------ statements
    def decl(self, name: str, t: Type, value: str) -> str:
        return f"var {self.var_decl(name, t)} = {value};"

    def for_head(self, var: str, count: int) -> str:
        return (f"for (var {var}: i32 = {self.int_literal(0)}; {var} < {self.int_literal(count)}; "
                f"{var}++) {{")

    def if_head(self, cond: str) -> str:
        return f"if {cond} {{"

    # ------------------------------------------------------------ expressions
    def expr_unary(self, e: ir.Unary) -> str:
        if e.op == "-" and e.ty.kind == "matrix":  # WGSL has no matrix negation
            return f"({self.literal(e.ty, -1.0)} * {self.expr(e.operand)})"
        return super().expr_unary(e)

    def select(self, cond: str, if_true: str, if_false: str) -> str:
        return f"select({if_false}, {if_true}, {cond})"


def _param_copies(f: ir.Function) -> dict[str, str]:
    """Signature names for assigned parameters: '_in_' + the brick name (brick names never start with '_')."""
    return {p.name: PARAM_COPY_PREFIX + p.name for p in f.params if p.assigned}


class WgslHalfTarget(WgslTarget):
    """WGSL at fp16: `enable f16;`, `f16`, `vecN<f16>`, `matNxN<f16>` and `h` literals (naga's SPIR-V
    back end declares Float16 and the 16-bit storage capabilities; the eval kernel's runtime drops
    StorageInputOutput16, which a compute shader never uses: runtime/eval_kernel.py). Interface values
    stay f32 and convert where brick code reads them (clike.from32/to32)."""

    precision = "fp16"
    SCALARS = {**WgslTarget.SCALARS, "float": "f16"}
    VECTORS = {**WgslTarget.VECTORS, "float": "vec{n}<f16>"}
    MATRIX = "mat{n}x{n}<f16>"
    FLOAT_SUFFIX = "h"

    def header(self) -> str:
        return "enable f16;"
