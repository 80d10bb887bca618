"""OpenGL GLSL: 4.50 core and ES 3.10, the `gl` platform's dialects of the GLSL target.

The same IR walk as Vulkan GLSL (glsl/emit.py: this is a subclass, no text is rewritten), spelled for
OpenGL's binding model (GLSL 4.50 spec §4.4.5 "Uniform and Shader Storage Block Layout Qualifiers",
§4.4.6 "Opaque-Uniform Layout Qualifiers"; ESSL 3.10 §4.4.5-4.4.6):

- **Combined samplers.** OpenGL has no separate `texture2D`/`sampler` objects (those are
  GL_KHR_vulkan_glsl): a texture is one `sampler2D` (`samplerCube`, `sampler2DShadow` for a compare)
  bound to a texture unit, passed to brick functions alone, sampled as `texture(t, uv)`; arrays are
  `sampler2DArray`, `sampler2DArrayShadow` and (desktop GL 4.00+ only) `samplerCubeArray`.
- **No descriptor sets.** `layout(binding = N)` only. Uniform blocks, texture units and shader
  storage blocks are three separate binding namespaces; Vulkan's (set, binding) pairs are
  flattened per namespace in (set, binding) order (:func:`gl_bindings`): Frame is always uniform
  block 0, a permutation's first texture unit 0. The manifest's ``gl`` reflection is that map.
- **No Vulkan-only features.** No `#extension GL_GOOGLE_cpp_style_line_directive` (no `#line` at
  all: glslangValidator's messages are mapped back through the line map instead), no
  `constant_id` specialization constants (GLSL for OpenGL has none without GL_ARB_gl_spirv).
- **ES 3.10** (`EsslTarget`): `#version 310 es` and default precision qualifiers — `highp`, or
  `mediump` in the fragment stage of a permutation whose key says fp16 (ESSL's way of allowing half
  precision; ESSL 3.10 §4.7.2: mediump has at least 16-bit float range and 10-bit mantissa). The
  array samplers have no default precision (§4.7.4) and are spelled `highp sampler2DArray` where
  declared, so the precision statements of shaders without them stay as they were; ES 3.10 has no
  `samplerCubeArray` (ES 3.20 and OES_texture_cube_map_array do): a brick that takes a
  texturecube_array is refused at its parameter for the essl dialect.

Desktop GL at fp16 is emitted at 32-bit floats: GL has no portable half arithmetic (the float16
extension is the Vulkan path's).
"""
from __future__ import annotations

from ...lang import ir
from ...lang.errors import at
from ...lang.types import Type
from ..glsl.emit import GlslTarget


def gl_bindings(blocks, textures) -> dict[str, dict[tuple[int, int], int]]:
    """Vulkan (set, binding) -> OpenGL binding, per namespace: {"uniform": …, "storage": …, "texture": …}.

    blocks: objects with .set, .binding, .kind ("uniform" | "storage"); textures: with .set, .binding.
    Each namespace is numbered from 0 in (set, binding) order, so the map is a function of the
    Interface alone and both stages of a program agree on it."""
    out: dict[str, dict[tuple[int, int], int]] = {"uniform": {}, "storage": {}, "texture": {}}
    for kind in ("uniform", "storage"):
        for i, b in enumerate(sorted((b.set, b.binding) for b in blocks if b.kind == kind)):
            out[kind][b] = i
    for i, t in enumerate(sorted((t.set, t.binding) for t in textures)):
        out["texture"][t] = i
    return out


class GlTarget(GlslTarget):
    """GLSL 4.50 core for OpenGL; `bindings` is gl_bindings() of the program's Interface."""

    name = "gl"
    ext = "glsl"
    version = "450 core"
    line_directives = False  # `#line N "path"` needs a Vulkan-side glslang extension; the line map does it
    TEXTURE = "sampler2D"
    TEXTURE_CUBE = "samplerCube"
    TEXTURE_SHADOW = "sampler2DShadow"
    TEXTURE_ARRAY = "sampler2DArray"
    TEXTURE_CUBE_ARRAY = "samplerCubeArray"
    TEXTURE_ARRAY_SHADOW = "sampler2DArrayShadow"
    SAMPLER = ""  # combined: a texture carries its sampler
    SAMPLER_COMPARE = ""
    INTRINSICS = {
        **GlslTarget.INTRINSICS,
        "sample": "texture({0}, {1})",
        "sample_level": "textureLod({0}, {1}, {2})",
        "sample@cube": "texture({0}, {1})",
        "sample_level@cube": "textureLod({0}, {1}, {2})",
        # textureLod on sampler2DShadow exists in GLSL 4.50 and ESSL 3.00+: level 0, valid in non-uniform flow
        "sample_compare": "textureLod({0}, vec3({1}, {2}), 0.0)",
        "sample@2d_array": "texture({0}, vec3({1}, float({2})))",
        "sample_level@2d_array": "textureLod({0}, vec3({1}, float({2})), {3})",
        "sample@cube_array": "texture({0}, vec4({1}, float({2})))",
        "sample_level@cube_array": "textureLod({0}, vec4({1}, float({2})), {3})",
        # GLSL 4.50 and ESSL 3.00+ have textureGrad, not textureLod, on sampler2DArrayShadow: zero gradients, level 0
        "sample_compare@2d_array": "textureGrad({0}, vec4({1}, float({2}), {3}), vec2(0.0), vec2(0.0))",
    }

    def __init__(self, bindings: dict | None = None, precision: str = "fp32"):
        self.bindings = bindings or {"uniform": {}, "storage": {}, "texture": {}}
        self.key_precision = precision  # the permutation's; the arithmetic stays 32-bit (module docstring)

    def header(self) -> str:
        return ""

    def version_line(self) -> str:
        return f"#version {self.version}"

    def precision_lines(self, stage: str) -> list[str]:
        """Default precision statements a stage needs (none in desktop GLSL)."""
        return []

    def binding(self, kind: str, set: int, binding: int) -> int:
        """The OpenGL binding of Vulkan (set, binding) in namespace `kind` ("uniform", "storage", "texture")."""
        try:
            return self.bindings[kind][(int(set), int(binding))]
        except KeyError:
            raise ValueError(f"no OpenGL {kind} binding for set {set}, binding {binding}: the Interface does "
                             "not declare it (gl_bindings)") from None

    def declare_spec_constant(self, name: str, ty: Type, constant_id: int) -> str:
        raise ValueError(f"specialization constant '{name}': GLSL for OpenGL has none (GL_ARB_gl_spirv only) — "
                         "the ubershader is built for the vulkan platform only")

    def declare_texture(self, name: str, set: int, binding: int, dim: str = "2d", compare: bool = False) -> str:
        """sampler2D (samplerCube, sampler2DShadow) NAME on the texture unit of Vulkan (set, binding)."""
        unit = self.binding("texture", set, binding)
        return f"layout(binding = {unit}) uniform {self.image_type(dim, compare)} {self.ident(name)};"

    def buffer_decl(self, name: str, elem: str, set: int, binding: int, kind: str, capacity: int) -> str:
        if kind == "storage":
            return (f"layout(binding = {self.binding('storage', set, binding)}, std430) readonly buffer "
                    f"{self.block_name(name)} {{ {elem} data[]; }} {name};")
        return (f"layout(binding = {self.binding('uniform', set, binding)}, std140) uniform "
                f"{self.block_name(name)} {{ {elem} data[{capacity}]; }} {name};")


class EsslTarget(GlTarget):
    """GLSL ES 3.10 (OpenGL ES 3.1): GlTarget with ES's version line and default precisions."""

    name = "essl"
    ext = "essl"
    version = "310 es"
    TEXTURE_ARRAY = "highp sampler2DArray"
    TEXTURE_CUBE_ARRAY = ""  # none in ES 3.10: refused where a brick takes one (emit)
    TEXTURE_ARRAY_SHADOW = "highp sampler2DArrayShadow"

    def emit(self, structs, functions, globals=(), records=None):
        """As GlTarget's, after refusing a texturecube_array at the brick line that takes or declares one."""
        for f in functions:
            for p in f.params:
                if p.ty.dim == "cube_array":
                    raise _no_cube_array(p.loc, f"parameter '{p.name}' of '{f.name}'")
        for g in globals:
            if g.ty.dim == "cube_array":
                raise ValueError(f"texture '{g.name}' is a texturecube_array: GLSL ES 3.10 has no samplerCubeArray "
                                 "— build the gl platform's gl dialect only, or take a texturecube per layer")
        return super().emit(structs, functions, globals, records)

    def precision_lines(self, stage: str) -> list[str]:
        """ESSL has no default float precision in fragment shaders (§4.7.4), and samplers default to lowp:
        every type the shaders use gets one. fp16 keys ask for mediump (half where the GPU has it) in the
        fragment stage only: the vertex transform stays highp, as the other languages' vertex shaders stay
        32-bit at fp16 (mediump world positions would lose about a unit in 2^11), and the Frame block both
        stages declare spells its members highp (macros.gl.j2: a uniform's precision must match across
        the stages of an ES program)."""
        p = "mediump" if self.key_precision == "fp16" and stage == "frag" else "highp"
        types = ["float", "int"] + (["sampler2D", "samplerCube", "sampler2DShadow"] if stage == "frag" else [])
        return [f"precision {p if t == 'float' else 'highp'} {t};" for t in types]


def _no_cube_array(loc: ir.Loc, what: str):
    return at(loc, f"{what} is a texturecube_array, which GLSL ES 3.10 does not have (samplerCubeArray is ES 3.20 "
              "or OES_texture_cube_map_array)", "take a texturecube per layer or a texture2d_array of faces, or "
              "build without the gl platform's essl dialect (desktop GL 4.50 has cube arrays)")


DIALECTS = {"gl": GlTarget, "essl": EsslTarget}  # the gl platform's sources, validated by glslangValidator
