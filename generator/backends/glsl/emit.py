"""GLSL 4.50 for Vulkan (glslang): column-major matrices as in the IR; separate images and samplers.

Textures are a `texture2D` (or `textureCube`) and a `sampler` (Vulkan GLSL), joined
at the call as `sampler2D(t, s)` (`samplerCube(t, s)`), so the descriptor layout is the
same as HLSL's and WGSL's: image at binding B, sampler at B+1. A texture2d_shadow is a
`texture2D` and a `samplerShadow`, joined as `sampler2DShadow(t, s)`; arrays are `texture2DArray`
(`sampler2DArray`, `sampler2DArrayShadow`) and `textureCubeArray` (`samplerCubeArray`, the
SampledCubeArray capability: Vulkan's imageCubeArray feature), their int layer converted to the float
last coordinate, which is exact (generator/lang/sampling.py). Buffers are interface
blocks with one member `data` (clike/resources.py).
"""
from __future__ import annotations

from ...lang import ir
from ...lang.types import Type
from ..clike.walk import CLikeTarget


class GlslTarget(CLikeTarget):
    name = "glsl"
    ext = "glsl"

    SCALARS = {"float": "float", "int": "int", "uint": "uint", "bool": "bool"}
    VECTORS = {"float": "vec{n}", "int": "ivec{n}", "uint": "uvec{n}", "bool": "bvec{n}"}
    MATRIX = "mat{n}"
    TEXTURE = "texture2D"
    TEXTURE_CUBE = "textureCube"
    TEXTURE_SHADOW = "texture2D"  # a depth texture; joined with a samplerShadow as sampler2DShadow
    TEXTURE_ARRAY = "texture2DArray"
    TEXTURE_CUBE_ARRAY = "textureCubeArray"
    TEXTURE_ARRAY_SHADOW = "texture2DArray"  # joined with a samplerShadow as sampler2DArrayShadow
    SAMPLER = "sampler"
    SAMPLER_COMPARE = "samplerShadow"
    INTRINSICS = {
        "rsqrt": "inversesqrt({0})",
        "saturate": "clamp({0}, 0.0, 1.0)",  # GLSL clamp takes float bounds for any genFType
        "atan2": "atan({0}, {1})",
        "sample": "texture(sampler2D({0}, {smp}), {1})",
        "sample_level": "textureLod(sampler2D({0}, {smp}), {1}, {2})",
        "sample@cube": "texture(samplerCube({0}, {smp}), {1})",
        "sample_level@cube": "textureLod(samplerCube({0}, {smp}), {1}, {2})",
        # GLSL 4.50 has textureLod for sampler2DShadow (not for the cube and array shadow samplers):
        # level 0 explicitly, valid in non-uniform control flow; the reference is P's third component
        "sample_compare": "textureLod(sampler2DShadow({0}, {smp}), vec3({1}, {2}), 0.0)",
        "sample@2d_array": "texture(sampler2DArray({0}, {smp}), vec3({1}, float({2})))",
        "sample_level@2d_array": "textureLod(sampler2DArray({0}, {smp}), vec3({1}, float({2})), {3})",
        "sample@cube_array": "texture(samplerCubeArray({0}, {smp}), vec4({1}, float({2})))",
        "sample_level@cube_array": "textureLod(samplerCubeArray({0}, {smp}), vec4({1}, float({2})), {3})",
        # no textureLod on sampler2DArrayShadow (without GL_EXT_texture_shadow_lod): zero gradients select
        # level 0 as explicitly, also valid in non-uniform flow; P is (uv, layer, ref)
        "sample_compare@2d_array": "textureGrad(sampler2DArrayShadow({0}, {smp}), vec4({1}, float({2}), {3}), "
                                   "vec2(0.0), vec2(0.0))",
    }

    def header(self) -> str:
        """`#line N "path"` with a file name needs this extension in glslang."""
        return "#extension GL_GOOGLE_cpp_style_line_directive : require"

    def declare_spec_constant(self, name: str, ty: Type, constant_id: int) -> str:
        return f"layout(constant_id = {int(constant_id)}) const {self.type_name(ty)} {self.ident(name)} = 0;"

    def declare_texture(self, name: str, set: int, binding: int, dim: str = "2d", compare: bool = False) -> str:
        """texture2D (textureCube, texture2DArray, textureCubeArray) NAME at binding B and sampler (compare: samplerShadow) _smp_NAME at B+1 of
        set S (as HLSL and WGSL)."""
        s, b = int(set), int(binding)
        image = self.image_type(dim, compare)
        return (f"layout(set = {s}, binding = {b}) uniform {image} {self.ident(name)};\n"
                f"layout(set = {s}, binding = {b + 1}) uniform {self.sampler_type(compare)} "
                f"{self.sampler_name(name)};")

    def buffer_decl(self, name: str, elem: str, set: int, binding: int, kind: str, capacity: int) -> str:
        if kind == "storage":
            return (f"layout(set = {set}, binding = {binding}, std430) readonly buffer {self.block_name(name)} "
                    f"{{ {elem} data[]; }} {name};")
        return (f"layout(set = {set}, binding = {binding}, std140) uniform {self.block_name(name)} "
                f"{{ {elem} data[{capacity}]; }} {name};")

    def buffer_element(self, buf: ir.Var, index: str) -> str:
        return f"{self.ident(buf.name)}.data[{index}]"

    def storage_length(self, name: str) -> str:
        return f"uint({name}.data.length())"

    def expr_select(self, e: ir.Select) -> str:
        return self.typed_select(e.ty, self.expr(e.cond), self.expr(e.if_true), self.expr(e.if_false))

    def expr_intrinsic(self, e: ir.Intrinsic) -> str:
        if e.name == "select":
            return self.typed_select(e.ty, *(self.expr(a) for a in e.args))
        return super().expr_intrinsic(e)

    def typed_select(self, ty: Type, cond: str, if_true: str, if_false: str) -> str:
        """mix() with a bool selector: glslang emits OpSelect, as HLSL's ?: and WGSL's select()
        do; a GLSL ?: with a non-trivial operand becomes a branch. Both operands are evaluated,
        which is harmless: brick expressions are pure."""
        sel = cond if ty.kind == "scalar" else f"bvec{ty.size}({cond})"
        return f"mix({if_false}, {if_true}, {sel})"


class GlslHalfTarget(GlslTarget):
    """GLSL at fp16: `float16_t`, `f16vecN`, `f16matN` and `hf` literals
    (GL_EXT_shader_explicit_arithmetic_types_float16: SPIR-V Float16, real half arithmetic on a
    device with shaderFloat16). Interface values stay 32-bit and convert where brick code reads
    them (clike.from32/to32); textures take vec2/vec3 coordinates and give vec4 texels."""

    precision = "fp16"
    SCALARS = {**GlslTarget.SCALARS, "float": "float16_t"}
    VECTORS = {**GlslTarget.VECTORS, "float": "f16vec{n}"}
    MATRIX = "f16mat{n}"
    FLOAT_SUFFIX = "hf"
    INTRINSICS = {**GlslTarget.INTRINSICS, "saturate": "clamp({0}, 0.0hf, 1.0hf)"}
    EXTENSION = "#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require"

    def header(self) -> str:
        return super().header() + "\n" + self.EXTENSION
