"""Reflection read from a SPIR-V binary: what an engine's pipeline layout and manifest must match.

``reflect(spirv) -> Reflection`` reads the module's words (no disassembler, no
SPIRV-Cross) and reports, per entry point, the descriptor resources it uses,
its push constants, its stage inputs and outputs (by Location) and the
built-ins it reads or writes. ``Reflection.as_dict()`` is plain JSON;
``Reflection.comparable()`` is the part that must agree across languages.

What is reflected
-----------------
- Resources: every module-scope variable with DescriptorSet and Binding. ``kind`` is
  ``uniform_buffer``, ``storage_buffer`` (``Uniform`` + BufferBlock or ``StorageBuffer``),
  ``sampled_image``, ``storage_image``, ``sampler``, ``combined_image_sampler``,
  ``uniform_texel_buffer``, ``storage_texel_buffer``, ``input_attachment`` or
  ``acceleration_structure``. ``count`` is 1, N for an array of descriptors, 0 for a
  runtime-sized one. Images carry ``dim`` (``1d 2d 3d cube rect buffer subpass``),
  ``arrayed``, ``depth`` (None when SPIR-V says "unknown"), ``multisampled``,
  ``sampled_type`` and ``format`` (storage images); ``texture_dim`` is ``dim`` with ``_array`` when
  arrayed, the manifest's texture ``dimension``. Buffers and storage images carry
  ``readonly`` (NonWritable on the variable or on every member) and ``writeonly``
  (NonReadable likewise). Blocks carry ``size`` and ``members``.
- Members, recursively: ``offset`` (Offset), ``type`` as GLSL spells it (``float vec3
  uvec4 mat4 mat3x4`` = 3 columns of 4 rows, ``Light`` for a struct, ``vec4[4]``,
  ``float[2][3]`` outer length first, ``Light[]`` runtime array, ``struct`` for a struct
  without OpName), ``size``, ``array_stride``, ``matrix_stride``, ``matrix_layout``
  (``column_major``/``row_major``, SPIR-V's sense), ``members`` of a struct or array of
  structs. Sizes: scalars and vectors exactly (vec3 = 12); a matrix is its stride times
  its columns (row_major: rows); an array is length x ArrayStride, a runtime array 0; a
  struct ends at its last member's end, unpadded. A block's ``size`` is therefore the
  minimum buffer range it needs (a trailing runtime array counts from its offset).
- Static use: an entry point's resources, push constants and gl_PerVertex-style
  built-in members are those its call tree references (loads, stores, access chains,
  atomics, calls, ...), as Vulkan's static-use rule defines. ``Reflection.resources``
  lists every declared one, used or not. Inputs and outputs are the entry point's
  interface list (SPIR-V 1.3 lists only Input/Output there; 1.4+ lists every global,
  which the storage class sorts out), built-ins apart; an interface block's members
  take their own Location or count on from the block's (a matrix one per column).

What compares across GLSL (glslc), HLSL (glslc -x hlsl) and WGSL (naga)
-----------------------------------------------------------------------
The build writes ``spirv-opt -O`` output. That keeps OpName and OpMemberName
(``-O`` has no strip-debug pass), but removes a resource that no entry point
uses, so a resource a template declares but no brick reads disappears. Found on
the example scene's shaders (see tests/analysis/test_reflect.py):

- Reliable, equal in all three: set, binding, kind, count, image dim, arrayed,
  depth, multisampled, sampled type; block sizes; member offsets, type strings of
  non-struct members, array and matrix strides; stage input/output locations,
  components and types; the built-ins used (Position, FragCoord, ...).
  ``comparable()`` keeps exactly these, with each block's members flattened into
  byte-layout leaves so that struct nesting and names drop out.
- Names are not: naga (without ``-g``, as the build runs it) emits no OpName or
  OpMemberName at all, so every name is None and every struct type ``struct``.
  glslc's HLSL front end names the cbuffer's type after it (``Frame``) but
  leaves the variable nameless (``""`` -> None), names members after their HLSL
  globals (``material_data`` where GLSL says ``data``) and stage variables
  ``i.v_uv`` / ``@entryPointOutput.v_uv``.
- Nesting is not: naga wraps every uniform/storage variable's type in a fresh
  one-member Block struct (``{ Frame @0 }``, ``{ vec4[] @0 }``), where glslc
  decorates the declared struct itself.
- Matrix layout is not: a GLSL or WGSL ``mat4`` is ``column_major``, an HLSL
  ``float4x4`` ``row_major`` in SPIR-V's terms (glslang maps HLSL rows to SPIR-V
  columns), both MatrixStride 16: the same 64 bytes are the same matrix to GLSL's
  ``M * v`` and HLSL's ``mul(M, v)``.
- ``writeonly`` is not: WGSL has no write-only storage buffer (``read_write``) and an
  HLSL ``RWStructuredBuffer`` is never NonReadable.
- Equal only when the sources say the same thing, so ``comparable()`` keeps them
  (a difference is a template bug): ``readonly`` (GLSL ``readonly``, HLSL
  ``StructuredBuffer``, WGSL ``read``), a storage image's ``format`` (an HLSL
  ``RWTexture2D<float4>`` gets ``rgba32f`` from its element type unless glslang's
  ``[[spv::format_rgba8]]`` says otherwise; it ignores DXC's ``[[vk::image_format]]``), ``depth`` (WGSL ``texture_depth_2d``,
  an HLSL texture used with ``SampleCmp`` and a GLSL ``texture2D`` used with a
  ``samplerShadow`` are depth images; the same textures sampled plainly are not).
- Built-in blocks: GLSL writes gl_Position through the gl_PerVertex block (only
  accessed members are reported), HLSL and WGSL through a plain variable; the
  reported built-ins agree.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

from .spirv_enums import (MODELS, EXECUTION_MODES, SC_INPUT, SC_OUTPUT, SC_PUSH_CONSTANT,
    SC_STORAGE_BUFFER, D_BUFFER_BLOCK, D_ROW_MAJOR, D_COL_MAJOR, D_ARRAY_STRIDE,
    D_MATRIX_STRIDE, D_BUILTIN, D_NON_WRITABLE, D_NON_READABLE, D_LOCATION, D_COMPONENT, D_BINDING,
    D_SET, D_OFFSET, INTERPOLATION, BUILTINS, DIMS, FORMATS, OP_ACCELERATION_STRUCTURE, POINTER_OPERANDS)
from .spirv import Instruction, Module, SpirvError, _string, _string_words, instructions, read

__all__ = ["Reflection", "EntryPoint", "Resource", "PushConstants", "Member", "StageVariable",
           "BuiltinVariable", "reflect", "flatten_layout", "SpirvError"]

# ------------------------------------------------------------------ the result

@dataclass
class Member:
    name: str | None           # OpMemberName (None when absent or empty)
    offset: int | None         # Offset decoration (None outside explicitly laid-out blocks)
    type: str                  # "vec4", "mat4", "Light[]", ...
    size: int                  # bytes (see the module docstring)
    array_stride: int | None = None
    matrix_stride: int | None = None
    matrix_layout: str | None = None   # "column_major" | "row_major" for matrices and arrays of them
    members: list["Member"] = field(default_factory=list)  # of a struct, or of an array's struct element


@dataclass
class Resource:
    set: int
    binding: int
    kind: str
    name: str | None           # OpName of the variable
    type_name: str | None      # OpName of its type (the block name), descriptor arrays unwrapped
    count: int = 1             # descriptors: 1, N for an array, 0 runtime-sized
    dim: str | None = None     # images only
    arrayed: bool | None = None
    depth: bool | None = None
    multisampled: bool | None = None
    sampled_type: str | None = None
    format: str | None = None  # storage images with a declared format
    readonly: bool | None = None   # buffers and storage images
    writeonly: bool | None = None
    size: int | None = None    # blocks
    members: list[Member] = field(default_factory=list)

    @property
    def texture_dim(self) -> str | None:
        """An image's dimension as the manifest's textures spell it: ``2d``, ``cube``, ``2d_array``,
        ``cube_array`` (``dim`` with ``_array`` when arrayed); None for other resources."""
        if self.dim is None:
            return None
        return f"{self.dim}_array" if self.arrayed else self.dim


@dataclass
class PushConstants:
    name: str | None
    type_name: str | None
    size: int
    members: list[Member] = field(default_factory=list)


@dataclass
class StageVariable:
    location: int
    component: int | None
    name: str | None
    type: str
    interpolation: list[str] = field(default_factory=list)   # "flat", "noperspective", "centroid", ...


@dataclass
class BuiltinVariable:
    direction: str             # "input" | "output"
    builtin: str               # "Position", "FragCoord", ...
    type: str


@dataclass
class EntryPoint:
    name: str
    execution_model: str       # "Vertex", "Fragment", "GLCompute", ...
    stage: str                 # "vert", "frag", "comp", ...
    resources: list[Resource] = field(default_factory=list)        # statically used, by (set, binding)
    push_constants: list[PushConstants] = field(default_factory=list)
    inputs: list[StageVariable] = field(default_factory=list)      # by location, component
    outputs: list[StageVariable] = field(default_factory=list)
    builtins: list[BuiltinVariable] = field(default_factory=list)  # by direction, builtin
    execution_modes: list[str] = field(default_factory=list)
    local_size: list[int] | None = None                            # compute-like stages


@dataclass
class Reflection:
    version: str                                                   # SPIR-V "1.3"
    entry_points: list[EntryPoint] = field(default_factory=list)
    resources: list[Resource] = field(default_factory=list)        # every declared one

    def as_dict(self) -> dict:
        return asdict(self)

    def entry(self, name_or_stage: str | None = None) -> EntryPoint:
        """The entry point with that name or stage ("frag"); the only one when None."""
        found = [e for e in self.entry_points if name_or_stage in (None, e.name, e.stage)]
        if len(found) != 1:
            raise KeyError(f"{len(found)} entry points match {name_or_stage!r} "
                           f"({', '.join(f'{e.name}:{e.stage}' for e in self.entry_points) or 'none'})")
        return found[0]

    def comparable(self) -> dict:
        """The facts that agree across GLSL, HLSL and WGSL builds of one shader (no names, flat layouts)."""
        def res(r: Resource) -> dict:
            d = {k: getattr(r, k) for k in ("set", "binding", "kind", "count", "dim", "arrayed", "depth",
                                             "multisampled", "sampled_type", "format", "readonly", "size")}
            d["layout"] = flatten_layout(r.members)
            return d
        return {"entry_points": [{
            "stage": e.stage,
            "resources": [res(r) for r in e.resources],
            "push_constants": [{"size": p.size, "layout": flatten_layout(p.members)} for p in e.push_constants],
            "inputs": [{"location": v.location, "component": v.component, "type": v.type,
                        "interpolation": v.interpolation} for v in e.inputs],
            "outputs": [{"location": v.location, "component": v.component, "type": v.type,
                         "interpolation": v.interpolation} for v in e.outputs],
            "builtins": [asdict(b) for b in e.builtins],
            "local_size": e.local_size,
        } for e in sorted(self.entry_points, key=lambda e: e.stage)]}


def flatten_layout(members: list[Member], base: int = 0) -> list[str]:
    """Byte layout as leaves ``"<offset>:<type>[ s<array stride>][ m<matrix stride>]"``.

    Struct members are flattened into their fields (offsets added), so nesting and
    struct names drop out; an array of structs stays one leaf whose type spells its
    element's layout: ``"16:{0:vec3,12:float,16:vec4}[] s32"``.
    """
    out = []
    for m in members:
        off = base + (m.offset or 0)
        if m.members and m.array_stride is None:
            out += flatten_layout(m.members, off)
            continue
        ty = m.type
        if m.members:
            ty = "{" + ",".join(flatten_layout(m.members)) + "}" + ty[ty.index("["):]
        leaf = f"{off}:{ty}"
        if m.array_stride is not None:
            leaf += f" s{m.array_stride}"
        if m.matrix_stride is not None:
            leaf += f" m{m.matrix_stride}"
        out.append(leaf)
    return out


# ------------------------------------------------------------------ reading

class _Decorations:
    def __init__(self):
        self.ids: dict[int, dict[int, list]] = {}                 # id -> decoration -> operands
        self.members: dict[tuple[int, int], dict[int, list]] = {}  # (struct, member) -> decoration -> operands
        self.member_names: dict[tuple[int, int], str] = {}

    def get(self, id_: int, dec: int, default=None):
        ops = self.ids.get(id_, {}).get(dec)
        return default if ops is None else (ops[0] if ops else True)

    def member(self, struct: int, index: int, dec: int, default=None):
        ops = self.members.get((struct, index), {}).get(dec)
        return default if ops is None else (ops[0] if ops else True)


class _Reader:
    def __init__(self, data: bytes):
        self.mod: Module = read(data)
        self.dec = _Decorations()
        self.eps: list[tuple[int, int, str, tuple]] = []      # (model, function, name, interface ids)
        self.modes: dict[int, list[tuple[int, tuple]]] = {}
        self.accel: set[int] = set()
        pending = []
        for opcode, w in instructions(data):
            if opcode == 71:      # OpDecorate
                self.dec.ids.setdefault(w[0], {})[w[1]] = list(w[2:])
            elif opcode == 72:    # OpMemberDecorate
                self.dec.members.setdefault((w[0], w[1]), {})[w[2]] = list(w[3:])
            elif opcode == 6:     # OpMemberName
                self.dec.member_names[(w[0], w[1])] = _string(w[2:])
            elif opcode == 15:    # OpEntryPoint
                n = _string_words(w[2:])
                self.eps.append((w[0], w[1], _string(w[2:2 + n]), tuple(w[2 + n:])))
            elif opcode in (16, 331):  # OpExecutionMode(Id)
                self.modes.setdefault(w[0], []).append((w[1], tuple(w[2:])))
            elif opcode == OP_ACCELERATION_STRUCTURE:
                self.accel.add(w[0])
            elif opcode in (74, 75):  # OpGroup(Member)Decorate: the group id carries the decorations
                pending.append((opcode, w))
        for opcode, w in pending:
            src = self.dec.ids.get(w[0], {})
            if opcode == 74:
                for target in w[1:]:
                    self.dec.ids.setdefault(target, {}).update(src)
            else:
                for target, index in zip(w[1::2], w[2::2]):
                    self.dec.members.setdefault((target, index), {}).update(src)

    # -------------------------------------------------------------- names and types

    def name(self, id_: int) -> str | None:
        return self.mod.names.get(id_) or None

    def const_value(self, id_: int) -> int | None:
        c = self.mod.constants.get(id_)
        if c is None or c.name not in ("Constant", "SpecConstant") or not c.operands:
            return None
        ops = c.operands
        return ops[0] | (ops[1] << 32 if len(ops) > 1 else 0)

    def scalar(self, t) -> tuple[str, str, int]:
        """(GLSL name, vector/matrix prefix, byte size) of a scalar type: ("uint", "u", 4), ("double", "d", 8)."""
        if t.op == "TypeBool":
            return "bool", "b", 4
        bits = t.args[0]
        if t.op == "TypeFloat":
            return {32: ("float", ""), 64: ("double", "d")}.get(bits, (f"float{bits}_t", f"f{bits}")) + (bits // 8,)
        u = "" if t.args[1] else "u"
        if bits == 32:
            return f"{u}int", u or "i", 4
        return f"{u}int{bits}_t", f"{u or 'i'}{bits}", bits // 8

    def type_str(self, tid: int) -> str:
        t = self.mod.types.get(tid)
        if t is None:
            return "accelerationStructure" if tid in self.accel else "?"
        if t.op in ("TypeFloat", "TypeInt", "TypeBool"):
            return self.scalar(t)[0]
        if t.op == "TypeVector":
            return f"{self.scalar(self.mod.types[t.args[0]])[1]}vec{t.args[1]}"
        if t.op == "TypeMatrix":
            col = self.mod.types[t.args[0]]
            prefix = self.scalar(self.mod.types[col.args[0]])[1]
            cols, rows = t.args[1], col.args[1]
            return f"{prefix}mat{cols}" if cols == rows else f"{prefix}mat{cols}x{rows}"
        if t.op in ("TypeArray", "TypeRuntimeArray"):
            dims, elem = [], tid
            while (e := self.mod.types.get(elem)) is not None and e.op in ("TypeArray", "TypeRuntimeArray"):
                n = self.const_value(e.args[1]) if e.op == "TypeArray" else ""
                dims.append("?" if n is None else n)
                elem = e.args[0]
            return self.type_str(elem) + "".join(f"[{n}]" for n in dims)
        if t.op == "TypeStruct":
            return self.name(tid) or "struct"
        if t.op == "TypePointer":
            return "ptr"
        return t.op[4:].lower()  # image, sampler, sampledimage

    def size(self, tid: int, matrix_stride: int | None = None, row_major: bool = False) -> int:
        t = self.mod.types.get(tid)
        if t is None:
            return 0
        if t.op in ("TypeFloat", "TypeInt", "TypeBool"):
            return self.scalar(t)[2]
        if t.op == "TypeVector":
            return self.size(t.args[0]) * t.args[1]
        if t.op == "TypeMatrix":
            col = self.mod.types[t.args[0]]
            if matrix_stride is None:
                return self.size(t.args[0]) * t.args[1]
            return matrix_stride * (col.args[1] if row_major else t.args[1])
        if t.op == "TypeArray":
            n = self.const_value(t.args[1]) or 0
            stride = self.dec.get(tid, D_ARRAY_STRIDE)
            return n * (stride if stride is not None else self.size(t.args[0], matrix_stride, row_major))
        if t.op == "TypeStruct":
            end = 0
            for i, m in enumerate(t.args):
                off = self.dec.member(tid, i, D_OFFSET)
                ms = self.dec.member(tid, i, D_MATRIX_STRIDE)
                rm = self.dec.member(tid, i, D_ROW_MAJOR, False)
                sz = self.size(m, ms, rm)
                end = max(end, off + sz) if off is not None else end + sz
            return end
        return 0

    def members(self, struct: int) -> list[Member]:
        out = []
        for i, mt in enumerate(self.mod.types[struct].args):
            ms = self.dec.member(struct, i, D_MATRIX_STRIDE)
            rm = bool(self.dec.member(struct, i, D_ROW_MAJOR, False))
            layout = None
            elem = mt
            stride = None
            while (e := self.mod.types.get(elem)) is not None and e.op in ("TypeArray", "TypeRuntimeArray"):
                stride = stride if stride is not None else self.dec.get(elem, D_ARRAY_STRIDE)
                elem = e.args[0]
            e = self.mod.types.get(elem)
            if e is not None and e.op == "TypeMatrix":
                layout = "row_major" if rm else ("column_major" if self.dec.member(struct, i, D_COL_MAJOR) else None)
            out.append(Member(
                name=self.dec.member_names.get((struct, i)) or None,
                offset=self.dec.member(struct, i, D_OFFSET),
                type=self.type_str(mt), size=self.size(mt, ms, rm), array_stride=stride,
                matrix_stride=ms, matrix_layout=layout,
                members=self.members(elem) if e is not None and e.op == "TypeStruct" else []))
        return out

    # -------------------------------------------------------------- variables

    def pointee(self, var: Instruction) -> tuple[int, int]:
        """(storage class, pointee type) of a module-scope variable."""
        ptr = self.mod.types[var.type_id]
        return ptr.args[0], ptr.args[1]

    def resource(self, vid: int) -> Resource:
        storage, tid = self.pointee(self.mod.globals[vid])
        count = 1
        t = self.mod.types.get(tid)
        if t is not None and t.op in ("TypeArray", "TypeRuntimeArray") and storage != SC_PUSH_CONSTANT:
            count = (self.const_value(t.args[1]) or 0) if t.op == "TypeArray" else 0
            tid = t.args[0]
            t = self.mod.types.get(tid)
        r = Resource(set=self.dec.get(vid, D_SET, 0), binding=self.dec.get(vid, D_BINDING, 0), kind="unknown",
                     name=self.name(vid), type_name=self.name(tid), count=count)
        if t is not None and t.op == "TypeStruct":
            block = storage == SC_STORAGE_BUFFER or self.dec.get(tid, D_BUFFER_BLOCK, False)
            r.kind = "storage_buffer" if block else "uniform_buffer"
            r.size, r.members = self.size(tid), self.members(tid)
            if r.kind == "storage_buffer":
                r.readonly, r.writeonly = (self._access(vid, tid, D_NON_WRITABLE),
                                           self._access(vid, tid, D_NON_READABLE))
            return r
        image = t
        if t is not None and t.op == "TypeSampledImage":
            r.kind, image = "combined_image_sampler", self.mod.types[t.args[0]]
        elif t is not None and t.op == "TypeSampler":
            r.kind = "sampler"
        elif tid in self.accel:
            r.kind = "acceleration_structure"
        if image is not None and image.op == "TypeImage":
            sampled_t, dim, depth, arrayed, ms, sampled, fmt = image.args[:7]
            r.dim, r.arrayed, r.multisampled = DIMS.get(dim, f"dim{dim}"), bool(arrayed), bool(ms)
            r.depth = None if depth == 2 else bool(depth)
            r.sampled_type = self.type_str(sampled_t)
            r.format = None if fmt == 0 else FORMATS.get(fmt, f"format{fmt}")
            if r.kind != "combined_image_sampler":
                r.kind = ("input_attachment" if r.dim == "subpass" else
                          {1: "uniform_texel_buffer", 2: "storage_texel_buffer"}.get(sampled, "image")
                          if r.dim == "buffer" else {1: "sampled_image", 2: "storage_image"}.get(sampled, "image"))
            if sampled == 2:
                r.readonly = bool(self.dec.get(vid, D_NON_WRITABLE, False))
                r.writeonly = bool(self.dec.get(vid, D_NON_READABLE, False))
        return r

    def _access(self, vid: int, struct: int, dec: int) -> bool:
        n = len(self.mod.types[struct].args)
        return bool(self.dec.get(vid, dec, False)) or (
            n > 0 and all(self.dec.member(struct, i, dec, False) for i in range(n)))

    def push_constants(self, vid: int) -> PushConstants:
        _, tid = self.pointee(self.mod.globals[vid])
        return PushConstants(self.name(vid), self.name(tid), self.size(tid), self.members(tid))

    # -------------------------------------------------------------- static use

    def references(self, fid: int) -> tuple[set[int], dict[int, set[int]]]:
        """Globals referenced by a function's call tree; per global, the constant first indices of its access chains
        (-1 in the set: the whole variable was used)."""
        used: set[int] = set()
        first: dict[int, set[int]] = {}
        seen, todo = set(), [fid]
        while todo:
            f = todo.pop()
            if f in seen or f not in self.mod.functions:
                continue
            seen.add(f)
            for block in self.mod.functions[f].blocks:
                for ins in block.body:
                    ops = ins.operands
                    if ins.name == "FunctionCall":
                        todo.append(ops[0])
                        positions = range(1, len(ops))
                    elif ins.name.startswith("Atomic") and ins.name != "AtomicStore":
                        positions = (0,)
                    elif ins.name == "ExtInst":
                        positions = range(2, len(ops))
                    elif ins.name == "Phi":
                        positions = range(0, len(ops), 2)
                    elif ins.name.startswith("Op"):  # unknown opcode
                        positions = range(len(ops))
                    else:
                        positions = POINTER_OPERANDS.get(ins.name, ())
                    for p in positions:
                        g = ops[p] if p < len(ops) else None
                        if g not in self.mod.globals:
                            continue
                        used.add(g)
                        if ins.name.endswith("AccessChain") and p == 0 and len(ops) > 1:
                            idx = self.const_value(ops[2] if "Ptr" in ins.name and len(ops) > 2 else ops[1])
                            first.setdefault(g, set()).add(-1 if idx is None else idx)
                        else:
                            first.setdefault(g, set()).add(-1)
        return used, first

    # -------------------------------------------------------------- entry points

    def locations(self, tid: int) -> int:
        """Locations a stage variable of this type takes (a dvec3/dvec4 two, a matrix one per column)."""
        t = self.mod.types[tid]
        if t.op == "TypeArray":
            return (self.const_value(t.args[1]) or 1) * self.locations(t.args[0])
        if t.op == "TypeMatrix":
            return t.args[1] * self.locations(t.args[0])
        if t.op == "TypeStruct":
            return sum(self.locations(m) for m in t.args)
        if t.op == "TypeVector" and t.args[1] > 2:
            return 1 + (self.scalar(self.mod.types[t.args[0]])[2] == 8)
        return 1

    def stage_vars(self, vid: int, first: dict[int, set[int]]):
        """(StageVariable list, BuiltinVariable list) of one Input/Output interface variable."""
        storage, tid = self.pointee(self.mod.globals[vid])
        direction = "input" if storage == SC_INPUT else "output"
        builtin = self.dec.get(vid, D_BUILTIN)
        if builtin is not None:
            return [], [BuiltinVariable(direction, BUILTINS.get(builtin, f"BuiltIn{builtin}"), self.type_str(tid))]
        base = tid  # gl_in[] / gl_out[] and per-vertex arrays: the block is the element
        while self.mod.types[base].op in ("TypeArray", "TypeRuntimeArray"):
            base = self.mod.types[base].args[0]
        t = self.mod.types[base]
        if t.op == "TypeStruct" and any(D_BUILTIN in self.dec.members.get((base, i), {}) for i in range(len(t.args))):
            used = first.get(vid, set())
            every = -1 in used or (base != tid and vid in first)  # an arrayed block's first index is the vertex
            return [], [BuiltinVariable(direction, BUILTINS.get(b, f"BuiltIn{b}"), self.type_str(m))
                        for i, m in enumerate(t.args)
                        if (b := self.dec.member(base, i, D_BUILTIN)) is not None and (every or i in used)]
        loc = self.dec.get(vid, D_LOCATION)
        interp = [v for d, v in INTERPOLATION.items() if self.dec.get(vid, d)]
        if t.op != "TypeStruct" or base != tid:
            if loc is None:
                return [], []
            return [StageVariable(loc, self.dec.get(vid, D_COMPONENT), self.name(vid), self.type_str(tid), interp)], []
        out = []  # an interface block: members at their own Location, or on from the block's
        for i, m in enumerate(t.args):
            loc = self.dec.member(base, i, D_LOCATION, loc)
            if loc is None:
                continue
            minterp = interp + [v for d, v in INTERPOLATION.items() if self.dec.member(base, i, d) and v not in interp]
            out.append(StageVariable(loc, self.dec.member(base, i, D_COMPONENT),
                                     self.dec.member_names.get((base, i)) or None, self.type_str(m), minterp))
            loc += self.locations(m)
        return out, []

    def entry_point(self, model: int, fid: int, name: str, interface: tuple) -> EntryPoint:
        em, stage = MODELS.get(model, (f"Model{model}", f"model{model}"))
        ep = EntryPoint(name, em, stage)
        used, first = self.references(fid)
        for vid in sorted(used):
            storage, _ = self.pointee(self.mod.globals[vid])
            if storage == SC_PUSH_CONSTANT:
                ep.push_constants.append(self.push_constants(vid))
            elif D_SET in self.dec.ids.get(vid, {}) or D_BINDING in self.dec.ids.get(vid, {}):
                ep.resources.append(self.resource(vid))
        ep.resources.sort(key=lambda r: (r.set, r.binding))
        for vid in dict.fromkeys(interface):
            var = self.mod.globals.get(vid)
            if var is None or self.pointee(var)[0] not in (SC_INPUT, SC_OUTPUT):
                continue
            vars_, builtins = self.stage_vars(vid, first)
            (ep.inputs if self.pointee(var)[0] == SC_INPUT else ep.outputs).extend(vars_)
            ep.builtins.extend(builtins)
        ep.inputs.sort(key=lambda v: (v.location, v.component or 0))
        ep.outputs.sort(key=lambda v: (v.location, v.component or 0))
        ep.builtins.sort(key=lambda b: (b.direction, b.builtin))
        for mode, ops in self.modes.get(fid, []):
            ep.execution_modes.append(EXECUTION_MODES.get(mode, f"Mode{mode}"))
            if mode == 17:
                ep.local_size = list(ops[:3])
            elif mode == 38:
                ep.local_size = [self.const_value(i) for i in ops[:3]]
        for cid, c in self.mod.constants.items():  # a WorkgroupSize constant overrides the modes
            if self.dec.get(cid, D_BUILTIN) == 25 and c.name.endswith("Composite"):
                ep.local_size = [self.const_value(i) for i in c.operands[:3]]
        return ep


def reflect(spirv: bytes) -> Reflection:
    """Reflect a SPIR-V module (bytes of either endianness); see the module docstring."""
    r = _Reader(bytes(spirv))
    major, minor = r.mod.version
    out = Reflection(f"{major}.{minor}", [r.entry_point(*ep) for ep in r.eps])
    out.resources = sorted((r.resource(vid) for vid, var in r.mod.globals.items()
                            if D_SET in r.dec.ids.get(vid, {}) or D_BINDING in r.dec.ids.get(vid, {})),
                           key=lambda x: (x.set, x.binding))
    return out
