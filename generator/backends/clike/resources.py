"""Global resources and arrays in the C-like targets: buffer and texture declarations, buffer reads.

Buffers hold structs whose members are all 16-byte vectors (types.buffer_layout_error),
so one byte layout serves every language:

    kind       GLSL                                   HLSL (glslang)                    WGSL
    storage    layout(set=S, binding=B, std430)       [[vk::binding(B, S)]]             @group(S) @binding(B)
               readonly buffer _blk_NAME              StructuredBuffer<T> NAME          var<storage, read> NAME:
               { T data[]; } NAME;                    : register(tB, spaceS);           array<T>;
    uniform    layout(set=S, binding=B, std140)       [[vk::binding(B, S)]] cbuffer     @group(S) @binding(B)
               uniform _blk_NAME { T data[N]; } NAME;  _blk_NAME : register(bB, spaceS)  var<uniform> NAME:
                                                      { T NAME[N]; };                   array<T, N>;
    NAME[i]    NAME.data[i]                           NAME[i]                           NAME[i]
    length     uint(NAME.data.length()) / Nu          _len_NAME() / Nu                  arrayLength(&NAME) / Nu

HLSL registers: a storage buffer is an SRV (t), a uniform block a cbuffer (b), with
register number = binding and space = set; the explicit [[vk::binding(B, S)]] is what
glslang uses for SPIR-V, so the binding is B in set S whatever the register class (the
same scheme as textures: t for the image, s for its sampler). HLSL reads a
structured buffer's length with GetDimensions, a statement, so a storage buffer's
declaration brings `uint _len_NAME()`. Generated names (_blk_, _len_) start with
'_', which brick names never do.
"""
from __future__ import annotations

from ...lang import ir
from ...lang.types import Type, buffer_layout_error
from . import reserved
from ..base import Target


class ResourceMixin(Target):
    """Buffer/global declarations and array spellings; the language classes fill in the hooks."""

    # ------------------------------------------------------------ declarations
    def declare_global(self, g: ir.Global) -> str:
        """The declaration of a global buffer or texture at its set and binding."""
        if g.set < 0 or g.binding < 0:
            raise ValueError(f"global '{g.name}' has no set/binding yet (set={g.set}, binding={g.binding}): "
                             "the link stage assigns them before emission")
        if g.ty.kind == "buffer":
            return self.declare_buffer(g.name, g.ty.elem, g.set, g.binding, g.ty.space, g.ty.size)
        if g.ty.kind == "texture":
            return self.declare_texture(g.name, g.set, g.binding, g.ty.dim, g.ty.compare)
        if g.ty.kind == "scalar" and g.ty.scalar in ("int", "uint"):
            return self.declare_spec_constant(g.name, g.ty, g.binding)
        raise ValueError(f"global '{g.name}' is {g.ty}: only buffers, textures and int specialization constants "
                         "are global resources")

    def declare_spec_constant(self, name: str, ty: Type, constant_id: int) -> str:
        """An int/uint specialization constant NAME with SpecId `constant_id`, 0 unless the pipeline sets it."""
        raise NotImplementedError

    def declare_buffer(self, name: str, elem: Type, set: int, binding: int, kind: str = "storage",
                       capacity: int = 0) -> str:
        """A read-only buffer NAME of `elem` structs at binding B of set S.

        kind "storage": a runtime-sized array (capacity ignored); "uniform": a uniform
        block holding `capacity` elements. The element struct must be declared before
        (Target.emit declares structs first) and obey types.buffer_layout_error.
        """
        why = buffer_layout_error(elem)
        if why:
            raise ValueError(f"buffer '{name}': {why} (every member must be a vec4, ivec4 or uvec4 so "
                             "std140, std430, HLSL and WGSL layouts agree)")
        if kind not in ("storage", "uniform"):
            raise ValueError(f"buffer '{name}': kind is 'storage' or 'uniform', not {kind!r}")
        if kind == "uniform" and not (type(capacity) is int and capacity >= 1):
            raise ValueError(f"uniform buffer '{name}' needs a capacity of at least 1, got {capacity!r}")
        spelled = self.type_name(elem)
        if getattr(self, "half", False):  # fp16: the buffer holds the 32-bit twin of its element struct
            from .walk import MIRROR_PREFIX
            spelled = MIRROR_PREFIX + elem.name
        return self.buffer_decl(self.ident(name), spelled, int(set), int(binding), kind, capacity)

    def buffer_decl(self, name: str, elem: str, set: int, binding: int, kind: str, capacity: int) -> str:
        raise NotImplementedError

    def block_name(self, name: str) -> str:
        """The interface block (GLSL) or cbuffer (HLSL) name of buffer `name` (already spelled)."""
        return reserved.BLOCK_PREFIX + name

    # ------------------------------------------------------------ reads
    def buffer_element(self, buf: ir.Var, index: str) -> str:
        """Element `index` of buffer `buf` (a global Var)."""
        return f"{self.ident(buf.name)}[{index}]"

    def buffer_length(self, buf: ir.Expr) -> str:
        """buffer_length(buf) as a uint: the runtime length of a storage buffer, a uniform one's capacity."""
        assert isinstance(buf, ir.Var) and buf.ty.kind == "buffer", "buffer_length takes a global buffer"
        if buf.ty.space == "uniform":
            return f"{buf.ty.size}{self.UINT_SUFFIX}"
        return self.storage_length(self.ident(buf.name))

    def storage_length(self, name: str) -> str:
        raise NotImplementedError

    # ------------------------------------------------------------ arrays
    def array_type(self, t: Type) -> str:
        """The spelling of array[T, N] where a type name is needed (constructors)."""
        return f"{self.type_name(t.elem)}[{t.size}]"

    def array_value(self, t: Type, elems: list[str]) -> str:
        """An array value from its elements (IR: only as a declaration's initializer)."""
        return f"{self.type_name(t)}({', '.join(elems)})"
