"""The typed Interface of a linked program: what a shader reads and where each value lives.

Everything downstream reads it: compose (templates declare it), build (the manifest's
reflection), the runtime (what to bind), measure (stand-ins). Layout (docs/design/link.md,
"Uniform layout"): material and light parameters live in arrays of vec4, packed (`layout`):
a vec3 at .xyz, a vec2 at .xy or .zw, a scalar in any free component, a vec4 whole and a
mat4 in four whole vec4s (column-major). Every value sits at its natural alignment inside
one vec4, so the bytes are the same under std140, HLSL cbuffer rules and WGSL uniforms and
one byte block serves all three languages. Set 0:
frame (b0), lights (b1), light textures (b2+); set 1: material (b0), material
textures (b1+); a texture takes two bindings, the image at B and its sampler at B+1 (a
texture2d_shadow: a depth image and a comparison sampler, reflected as such in the manifest).
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field

from ..lang import types
from ..lang.types import Type
from ..spec.params import ParamSpec

VEC4_BYTES = 16


@dataclass
class Slot:
    """One parameter in a vec4-array block: shader name, engine name, type, vec4 index and first component."""

    name: str  # the glue's name (m_alpha, l0_color)
    param: str  # the engine's name (alpha, color)
    ty: Type
    index: int
    spec: ParamSpec | None = None
    light: int | None = None  # the light it belongs to
    base: int = 0  # byte offset of the vec4 array in its block
    element: int | None = None  # the element of an array parameter
    component: int = 0  # its first component in vec4 `index` (0 = .x … 3 = .w); 0 for a vec4 or mat4
    environment: bool = False  # a value of the light set's environment (the Lights block's last group)

    @property
    def width(self) -> int:
        """vec4s it occupies."""
        return 4 if self.ty.kind == "matrix" else 1

    @property
    def offset(self) -> int:
        """Byte offset in the block."""
        return self.base + self.index * VEC4_BYTES + self.component * 4

    @property
    def swizzle(self) -> str:
        """How a shader reads it from its vec4 (`.w`, `.zw`, `.xyz`; '' for a whole vec4 or a mat4's columns)."""
        n = self.ty.components
        return "" if n % 4 == 0 else "." + "xyzw"[self.component:self.component + n]

    def words(self) -> list[int]:
        """The float32 words of the vec4 array it occupies, in the order of its value (a mat4's columns)."""
        first = 4 * self.index + self.component
        return list(range(first, first + self.ty.components))

    def as_dict(self) -> dict:
        name = self.param if self.element is None else f"{self.param}[{self.element}]"
        d = {"name": name, "type": str(self.ty), "offset": self.offset, "size": self.ty.components * 4}
        if self.light is not None:
            d["light"] = self.light
        if self.environment:
            d["environment"] = True
        if self.spec is not None:
            d["default"] = self.spec.default if self.element is None else self.spec.default[self.element]
            d["range"] = list(self.spec.range) if self.spec.range else None
        return d


# Where a value may start in a vec4, by component count: its natural alignment, so that the packed bytes are a
# valid std140 / HLSL cbuffer / WGSL layout (HLSL would put a float3 after a float at offset 4, std140 at 16).
_STARTS = {1: (0, 1, 2, 3), 2: (0, 2), 3: (0,)}


def layout(values: list[tuple], start: int = 0) -> tuple[list[Slot], int]:
    """(name, param, element, type, spec, light) in order → packed slots from vec4 `start`, and the vec4 after them.

    Deterministic first fit: vectors and matrices first, in their declared order (a vec2 into the .zw a
    vec2 left free, a vec3, vec4 or mat4 into new vec4s), then the scalars, in their declared order, each
    into the first free component — the .w after a vec3 or the holes beside a vec2 before a new vec4.
    Scalars go last so that one declared before a vec3 does not take the .x that vec3 needs.
    """
    used: list[list[bool]] = []  # per vec4 from `start`: which components are taken
    placed: dict[int, Slot] = {}
    order = sorted(range(len(values)), key=lambda k: (values[k][3].components == 1, k))
    for k in order:
        name, param, element, ty, spec, light = values[k]
        index, component = _fit(used, ty.components)
        placed[k] = Slot(name, param, ty, start + index, spec, light, element=element, component=component)
    return [placed[k] for k in range(len(values))], start + len(used)


def _fit(used: list[list[bool]], n: int) -> tuple[int, int]:
    """The first (vec4, component) where `n` components fit (n = 16: four whole vec4s), marking them taken."""
    if n % 4 == 0:  # a vec4 or a mat4: whole new vec4s
        used.extend([True] * 4 for _ in range(n // 4))
        return len(used) - n // 4, 0
    for i, taken in enumerate(used):
        for c in _STARTS[n]:
            if not any(taken[c:c + n]):
                taken[c:c + n] = [True] * n
                return i, c
    used.append([c < n for c in range(4)])
    return len(used) - 1, 0


def slot_value(slot: Slot, value) -> list[float]:
    """A value as the words `slot.words()` hold: a scalar given for a vector splats, a mat4 is its columns."""
    v = value.tolist() if hasattr(value, "tolist") else value  # a NumPy array or scalar
    flat = [float(x) for x in (_flatten(v) if isinstance(v, (list, tuple)) else [v])]
    if slot.ty.kind == "vector" and len(flat) == 1:
        flat = flat * slot.ty.size
    return flat


def _flatten(v) -> list:
    return [y for x in v for y in (_flatten(x) if isinstance(x, (list, tuple)) else [x])]


def put(words, slot: Slot, value) -> None:
    """Write `value` at `slot` into `words`, a flat float list or array over the block's vec4s."""
    for w, x in zip(slot.words(), slot_value(slot, value)):
        words[w] = x


def pack(slots: list[Slot], values: dict[str, object], count: int) -> bytes:
    """A ready-to-upload block: `values` ({slot name: number or list}) at their slots, zeros elsewhere."""
    words = [0.0] * (4 * max(count, 1))
    for s in slots:
        v = values.get(s.name)
        if v is not None:
            put(words, s, v)
    return struct.pack(f"<{len(words)}f", *words)


@dataclass
class Block:
    """A uniform or storage block: its declared members and the parameters inside them."""

    name: str
    set: int
    binding: int
    kind: str  # "uniform" | "storage"
    members: list[dict]  # [{"name", "type", "offset", "size", "array_stride"?}] as declared
    slots: list[Slot] = field(default_factory=list)
    readonly: bool = True

    @property
    def size(self) -> int:
        last = self.members[-1]
        return last["offset"] + last["size"]

    def as_dict(self) -> dict:
        d = {"name": self.name, "set": self.set, "binding": self.binding, "kind": self.kind, "size": self.size,
             "members": self.members}
        if self.slots:
            d["parameters"] = [s.as_dict() for s in self.slots]
        return d


def vec4_array_block(name: str, set_: int, binding: int, slots: list[Slot], count: int,
                     header: list[dict] | None = None) -> Block:
    """A block holding `header` members then `data: vec4[count]`."""
    members = list(header or [])
    base = members[-1]["offset"] + members[-1]["size"] if members else 0
    members.append({"name": "data", "type": f"vec4[{count}]", "offset": base, "size": count * VEC4_BYTES,
                    "array_stride": VEC4_BYTES})
    for s in slots:
        s.base = base
    return Block(name, set_, binding, "uniform", members, slots)


FRAME_BLOCK = [{"name": "view_proj", "type": "mat4", "offset": 0, "size": 64, "matrix_stride": 16},
               {"name": "camera_pos", "type": "vec4", "offset": 64, "size": 16}]
# Per draw (set 2, binding 0, read by the vertex shader): the model matrix and its inverse transpose
# (as a mat4; the upper 3x3 is used), so normals stay perpendicular under non-uniform scale.
OBJECT_BLOCK = [{"name": "model", "type": "mat4", "offset": 0, "size": 64, "matrix_stride": 16},
                {"name": "normal_matrix", "type": "mat4", "offset": 64, "size": 64, "matrix_stride": 16}]
VERTEX_ONLY = ("Object",)  # blocks the fragment shader does not declare


@dataclass
class Texture:
    """A texture and its sampler: the image at `binding`, the sampler at `binding + 1`."""

    name: str  # the glue's name (t_albedo_map)
    param: str  # the brick's texture name
    group: str  # "material" | "light"
    srgb: bool
    dim: str = "2d"  # "2d" | "cube" | "2d_array" | "cube_array" (types.TEXTURE_DIMS; the manifest's dimension)
    light: int | None = None
    set: int = 0
    binding: int = 0
    compare: bool = False  # a depth texture read through a comparison sampler (texture2d_shadow)
    # an environment brick's (library/kinds.ENVIRONMENT_TEXTURES): the light set's radiance cube (group "light",
    # no light) or the material's BRDF's AmbientBRDF table (group "material")
    environment: bool = False

    @property
    def ty(self) -> Type:
        """The brick-language type of the texture."""
        return texture_type(self.dim, self.compare)

    def as_dict(self) -> dict:
        d = {"name": self.param, "set": self.set, "binding": self.binding, "sampler_binding": self.binding + 1,
             "dimension": self.dim, "color_space": "srgb" if self.srgb else "linear"}
        if self.compare:  # a depth format image and a comparison sampler (compareOp LESS_OR_EQUAL, linear)
            d.update(format="depth", sampler="comparison", compare_op="less_or_equal")
        if self.light is not None:
            d["light"] = self.light
        if self.environment:
            d["environment"] = True
        return d


def texture_type(dim: str, compare: bool = False) -> Type:
    """The brick-language type of a texture of dimension `dim` ("2d", "cube", "2d_array", "cube_array"; compare:
    a 2D depth texture or an array of them)."""
    return types.texture_type(dim, compare)


def assign_bindings(textures: list[Texture], first: dict[str, int]) -> None:
    """Two bindings per texture (image, sampler), numbered per group from `first`."""
    nxt = dict(first)
    for t in textures:
        t.set = 0 if t.group == "light" else 1
        t.binding = nxt[t.group]
        nxt[t.group] += 2


@dataclass(frozen=True)
class Location:
    """A vertex input, an interpolant or an output: location, name, type, and the vertex format."""

    location: int
    name: str
    ty: str
    format: str = ""

    def as_dict(self) -> dict:
        d = {"location": self.location, "name": self.name, "type": self.ty}
        if self.format:
            d["format"] = self.format
        return d


# The mesh attributes and interpolants of the fragment shaders (backends/*/templates/vertex and fragment).
VERTEX_INPUTS = {"P": Location(0, "a_position", "vec3", "R32G32B32_SFLOAT"),
                 "N": Location(1, "a_normal", "vec3", "R32G32B32_SFLOAT"),
                 "T": Location(2, "a_tangent", "vec4", "R32G32B32A32_SFLOAT"),
                 "uv": Location(3, "a_uv", "vec2", "R32G32_SFLOAT"),
                 "color": Location(4, "a_color", "vec4", "R32G32B32A32_SFLOAT")}  # COLOR_0 (spec/surface.py)
INTERPOLANTS = {"P": Location(0, "v_position", "vec3"), "N": Location(1, "v_normal", "vec3"),
                "T": Location(2, "v_tangent", "vec4"), "uv": Location(3, "v_uv", "vec2"),
                "color": Location(4, "v_color", "vec4")}


@dataclass
class Interface:
    """What one linked program reads, and where every value lives."""

    stage_entries: dict[str, str]  # stage -> entry point name
    shading_inputs: list[str]  # rows of the inputs table the BRDF reads (frame rows included)
    surface: list[str]  # P, N, then T, B, uv, color where read
    blocks: list[Block]
    textures: list[Texture]
    outputs: list[Location]
    params: dict[str, dict[str, ParamSpec]] = field(default_factory=dict)  # group -> name -> spec

    @property
    def tangent(self) -> bool:
        return "T" in self.surface or "T" in self.shading_inputs

    @property
    def vertex_inputs(self) -> list[Location]:
        return [VERTEX_INPUTS[k] for k in ("P", "N", "T", "uv", "color")
                if k in self.surface or (k == "T" and self.tangent)]

    @property
    def interpolants(self) -> list[Location]:
        return [INTERPOLANTS[k] for k in ("P", "N", "T", "uv", "color")
                if k in self.surface or (k == "T" and self.tangent)]

    def block(self, name: str) -> Block | None:
        for b in self.blocks:
            if b.name == name:
                return b
        return None

    def as_dict(self) -> dict:
        """The reflection written to manifest.json (per stage: what the engine binds)."""
        frag = {"entry_point": self.stage_entries.get("frag", "main"),
                "uniform_blocks": [b.as_dict() for b in self.blocks if b.kind == "uniform"
                                   and b.name not in VERTEX_ONLY],
                "storage_blocks": [b.as_dict() for b in self.blocks if b.kind == "storage"],
                "textures": [t.as_dict() for t in self.textures],
                "inputs": [x.as_dict() for x in self.interpolants],
                "outputs": [x.as_dict() for x in self.outputs]}
        out = {"shading_inputs": self.shading_inputs, "frag": frag}
        if "vert" in self.stage_entries:
            out["vert"] = {"entry_point": self.stage_entries["vert"],
                           "uniform_blocks": [self.block("Frame").as_dict(), self.block("Object").as_dict()],
                           "inputs": [x.as_dict() for x in self.vertex_inputs],
                           "outputs": [x.as_dict() for x in self.interpolants]}
        return out
