"""The link stage: resolved brick nodes → one IR program plus its typed Interface.

Three glue builders over one program (link/glue.py): the eval kernel of one BRDF
(`eval_program`), the eval kernel of several BRDFs behind a switch on an id
(`switch_program`), and the fragment shading of a permutation (`link_permutation`).
Function names are keyed by canonical node (link/program.py), so any set of bricks
links into one program, deterministically.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

from ..lang.types import Type
from ..library.bricks import Library
from ..spec.params import Params
from ..spec.permutation import Node, Permutation
from ..spec.resolve import Resolved, ResolvedBrdf, resolve, resolve_brdf
from ..spec.where import KeyProblem, spec_where, within
from .faces import buffer_params, face_params
from .tiles import TILES_BLOCK
from .glue import BrdfGlue, ShadeGlue, brdf_glue, brdf_switch, shade_glue, switch_params, switch_textures
from .interface import (FRAME_BLOCK, OBJECT_BLOCK, Block, Interface, Location, Slot, Texture, assign_bindings, layout,
                        vec4_array_block)
from .program import Program, function_name

__all__ = ["EvalProgram", "LinkedPermutation", "SHADE_KERNEL", "Program", "Interface", "Slot", "Block", "Texture", "layout",
           "eval_program", "switch_program", "link_permutation", "function_name"]

EVAL_INFO = {"name": "info", "type": "uvec4", "offset": 0, "size": 16}


@dataclass
class EvalProgram:
    """The linked program of an eval kernel: brick functions, the brdf glue, and its interface."""

    spec: str  # canonical spec ('|'-joined for a switch over several BRDFs)
    nodes: list[Node]
    program: Program
    specs: Params  # the one parameter policy's group (spec/params.py)
    signature: list[tuple[str, Type]]  # the entry's parameters
    slots: list[Slot]  # params in the vec4 parameter array, packed (interface.layout)
    param_vec4s: int
    tangent: bool  # the entry reads T and B
    interface: Interface
    entry: str = "brdf"
    textures: tuple = ()  # (name, type, declaration) of textures the BRDF reads
    specs_of: tuple = ()  # for a switch: the canonical spec of each id
    own: tuple = ()  # for a switch: per id, the names of its BRDF's parameters

    @property
    def params(self) -> dict[str, Type]:
        return {k: p.ty for k, p in self.specs.items()}

    @property
    def hash(self) -> str:
        return hashlib.sha256(("eval:" + self.spec).encode()).hexdigest()[:12]

    def defaults(self) -> dict[str, object]:
        return {k: p.default for k, p in self.specs.items()}

    def ranges(self) -> dict[str, tuple | None]:
        return {k: p.range for k, p in self.specs.items()}


def _eval_interface(specs: Params, reads: list[str], textures,
                    brdfs: list[ResolvedBrdf]) -> tuple[list[Slot], int, Interface]:
    slots, count = layout([(n, k, e, ty, p, None) for n, k, e, ty, p in specs.flat])
    params = vec4_array_block("Params", 0, 2, slots, max(count, 1), header=[EVAL_INFO])
    samples = Block("Samples", 0, 0, "storage", [{"name": "data", "type": "vec4[]", "offset": 0, "size": 0,
                                                  "array_stride": 16}])
    result = Block("Result", 0, 1, "storage", [{"name": "data", "type": "vec4[]", "offset": 0, "size": 0,
                                                "array_stride": 16}], readonly=False)
    shadow = [n for n, ty, _ in textures if ty.compare]
    if shadow:  # the eval kernel binds every texture with the bilinear sampler (runtime/eval_kernel.py)
        raise _declaring(brdfs, shadow[0]).error(
            f"the BRDF reads '{shadow[0]}' as a texture2d_shadow, a depth texture that only a comparison sampler "
            "reads, and an eval kernel binds colour textures", "declare it texture2d: texture2d_shadow is for shadow "
            "filters")
    texs = [Texture(n, n, "material", bool(d.get("srgb")), ty.dim) for n, ty, d in textures]
    assign_bindings(texs, {"material": 3})
    for t in texs:
        t.set = 0
    iface = Interface({"comp": "main"}, reads, [], [samples, result, params], texs, [],
                      params={"material": specs})
    return slots, count, iface


def _declaring(brdfs: list[ResolvedBrdf], texture: str):
    """Where an error about a BRDF's texture points: the scene key that asked for the BRDF, else the column of the
    brick declaring it in the spec string."""
    for rb in brdfs:
        for top in rb.nodes:
            for x in top.tree:
                if texture in x.brick.textures:
                    return rb.where or spec_where(rb.text, x.col or top.col or 1)
    return rb.where or spec_where(rb.text)


def eval_program(spec: str | ResolvedBrdf, lib: Library) -> EvalProgram:
    """Link a BRDF spec (or a resolved one) into the program its eval kernel runs (every target emits this IR)."""
    rb = spec if isinstance(spec, ResolvedBrdf) else resolve_brdf(spec, lib)
    nodes = list(rb.nodes)
    prog = Program(lib_memo=lib.memo)
    g: BrdfGlue = brdf_glue(prog, nodes, rb.params)
    slots, count, iface = _eval_interface(g.params, g.reads, g.textures, [rb])
    return EvalProgram(rb.key, nodes, prog, g.params, g.signature, slots, count, g.tangent, iface,
                       textures=tuple(g.textures))


def switch_program(specs: list[str], lib: Library) -> EvalProgram:
    """Several BRDFs in one program behind `brdf_switch(id, ...)`: id k evaluates specs[k]."""
    brdfs = [s if isinstance(s, ResolvedBrdf) else resolve_brdf(s, lib) for s in specs]
    canon = [rb.key for rb in brdfs]
    prog = Program(lib_memo=lib.memo)
    f, glues = brdf_switch(prog, brdfs)
    union = switch_params(glues)
    tangent = any(g.tangent for g in glues)
    reads = list(dict.fromkeys(r for g in glues for r in g.reads))
    textures = switch_textures(glues)
    slots, count, iface = _eval_interface(union, reads, textures, brdfs)
    sig = [(p.name, p.ty) for p in f.params]
    return EvalProgram("|".join(canon), [n for rb in brdfs for n in rb.nodes], prog, union, sig, slots, count,
                       tangent, iface, entry="brdf_switch", textures=tuple(textures), specs_of=tuple(canon),
                       own=tuple(tuple(g.params) for g in glues))


@dataclass
class LinkedPermutation:
    """A permutation's program (brick functions + shade glue) and its interface."""

    perm: Permutation
    resolved: Resolved
    program: Program
    glue: ShadeGlue
    interface: Interface
    material: list[Slot]
    lights: list[list[Slot]]
    environment: list[Slot] = field(default_factory=list)  # the environment's values, after the lights' (Lights)


SHADE_KERNEL = {"Info": 2, "Lights": 3, "Material": 4, "buffers": 5}  # set 0 bindings of a shade kernel


def link_permutation(perm: Permutation | Resolved, lib: Library, kernel: bool = False) -> LinkedPermutation:
    """Link the bricks of a permutation (resolved, or resolved here) and lay out what its fragment shader reads.

    kernel: lay it out for a shade kernel instead (compose.compose_shade_kernel): shade() in a
    compute shader, every block in set 0 (SHADE_KERNEL), no textures and no Frame.
    Errors about the key are located where the permutation was asked for (spec/where.py).
    """
    r = perm if isinstance(perm, Resolved) else resolve(perm, lib)
    with within(r.origin, r.key):
        return _link(r, lib, kernel)


def _pack_values(g: ShadeGlue, surface: int) -> tuple[list[Slot], int, list[Slot], int]:
    """The Material block's slots and vec4s, then the Lights block's: packed per group, each group from a new
    vec4 — the material's brick parameters, then its last `surface` values (the surface state's), then each
    light. So the ubershader's MaterialEntry.data, the bricks' part, is a prefix of every specialized Material
    block of its variant, and one light's values are whole vec4s an engine may rewrite alone."""
    cut = len(g.material) - surface
    mat, bricks_end = layout([(n, p, e, t, s, None) for n, p, e, t, s in g.material[:cut]])
    more, mat_count = layout([(n, p, e, t, s, None) for n, p, e, t, s in g.material[cut:]], bricks_end)
    light_slots, light_count = [], 0
    for i, vals in enumerate(g.lights):
        slots, light_count = layout([(n, p, e, t, s, i) for n, p, e, t, s in vals], light_count)
        light_slots += slots
    if g.environment:  # the light set's environment: the Lights block's last group, from a new vec4
        env, light_count = layout([(n, p, e, t, s, None) for n, p, e, t, s in g.environment], light_count)
        for x in env:
            x.environment = True
        light_slots += env
    return mat + more, mat_count, light_slots, light_count


def _link(r: Resolved, lib: Library, kernel: bool) -> LinkedPermutation:
    if r.problems:
        raise KeyProblem(*r.problems[0])
    prog = Program(lib_memo=lib.memo)
    g = shade_glue(prog, r)
    if kernel and g.textures:
        t0 = g.textures[0]
        raise KeyProblem("brdf" if t0.param in {t for n in r.brdf for x in n.tree for t in x.brick.textures}
                         else "packing", f"a shade kernel binds no textures, and {r.key} samples '{t0.param}'",
                         "run texture-sampling permutations as fragment shaders")
    if kernel and r.surface.vertex_color:
        raise KeyProblem("vertex_color", f"a shade kernel has no vertex colours, and {r.key} reads COLOR_0",
                         "run vertex-colour permutations as fragment shaders")
    if kernel and g.light_tiles is not None:
        raise KeyProblem("lights", f"a shade kernel has no pixel coordinate, and {r.key} reads a screen tile's lights",
                         "run tiled light sets as fragment shaders")
    assign_bindings(g.textures, {"light": 2, "material": 1})
    mat_slots, mat_count, light_slots, light_count = _pack_values(g, len(r.surface_params))
    if kernel:
        blocks = [vec4_array_block("Lights", 0, SHADE_KERNEL["Lights"], light_slots, max(light_count, 1)),
                  vec4_array_block("Material", 0, SHADE_KERNEL["Material"], mat_slots, max(mat_count, 1))]
        binding = SHADE_KERNEL["buffers"]
    else:
        blocks = [Block("Frame", 0, 0, "uniform", list(FRAME_BLOCK)), Block("Object", 2, 0, "uniform", list(OBJECT_BLOCK))]
        if light_count:
            blocks.append(vec4_array_block("Lights", 0, 1, light_slots, light_count))
        if mat_count:
            blocks.append(vec4_array_block("Material", 1, 0, mat_slots, mat_count))
        binding = max([1] + [t.binding + 1 for t in g.textures if t.set == 0]) + 1
    for gl, slots in zip(g.light_buffers, g.light_buffer_slots):  # dynamic lights: read-only storage buffers
        gl.set, gl.binding = 0, binding  # after the light textures
        binding += 1
        elem = gl.ty.elem
        # LightData<i> { vec4 data[n]; }, the light's parameters packed (layout); a switch loop's element has
        # ivec4 ids before them (glue._switch_buffer)
        fields, at = [], 0
        for fname, fty in elem.fields:
            n = fty.size if fty.kind == "array" else 1
            fields.append({"name": fname, "type": f"vec4[{n}]" if fty.kind == "array" else str(fty), "offset": at,
                           "size": 16 * n, **({"array_stride": 16} if fty.kind == "array" else {})})
            at += 16 * n
        blocks.append(Block(f"LightBuffer{elem.name[len('LightData'):]}", gl.set, gl.binding, "storage",
                            [{"name": "data", "type": f"{elem.name}[]", "offset": 0, "size": 0,
                              "array_stride": at, "members": fields}], slots))
    if g.light_tiles is not None:  # a tiled set's index lists (link/tiles.py), after its light buffers
        g.light_tiles.set, g.light_tiles.binding = 0, binding
        blocks.append(Block(TILES_BLOCK, 0, binding, "storage", [{"name": "w", "type": "uvec4[]", "offset": 0,
                                                                   "size": 0, "array_stride": 16}]))
    params = {"material": {p: s for _, p, _, _, s in g.material}}
    if g.environment:
        params["environment"] = {p: s for _, p, _, _, s in g.environment}
    for i, lt in enumerate(r.lights):
        params[f"light{i}"] = (buffer_params if lt.dynamic else face_params)(lt)  # six faces, a first layer (link/faces.py)
    stages = {"comp": "main"} if kernel else {"vert": "main", "frag": "main"}
    iface = Interface(stages, g.brdf.reads, g.surface, blocks, g.textures,
                      [Location(0, "out_color", "vec4")], params=params)
    lights = [[s for s in light_slots if s.light == i] for i in range(len(r.lights))]
    return LinkedPermutation(r.perm, r, prog, g, iface, mat_slots, lights, [s for s in light_slots if s.environment])
