"""The depth passes' programs and interfaces: what a shadowed light's depth pipeline reads (compose/depth.py
renders them; runtime/shadow_pass.py states the contract an engine draws them by).

Four kinds of unit, each a vertex and a fragment stage in every language:

- ``depth``: the vertex stage every opaque caster is drawn with (position only: Frame.view_proj × Object.model,
  the material shaders' blocks at their bindings), and the moments fragment stage of a variance shadow map,
  writing (d, d², 0, 1) with d the fragment's depth;
- ``<permutation>.mask``: a masked ("mask" alpha) material's caster: the vertex stage adds the uv and COLOR_0
  the coverage reads, the fragment stage discards below the cutoff (:func:`mask_program`);
- ``<permutation>.mask_moments``: the same coverage test, then the moments (a masked caster of a VSM light);
- ``blur``: one axis of the moments' box filter as a fullscreen pass (a triangle over the target), run twice.

The mask is the glue's own coverage expression (link/glue.py `coverage`: m_base_alpha · the packing's base
colour texture's A at uv · COLOR_0's A, against m_alpha_cutoff) built into a program of its own, so the depth
pass and the colour pass cannot disagree about which texels are cut out. It reads the permutation's Material
block and coverage texture at the bindings the material's colour pass declares: an engine binds the same
descriptor set 1 for both.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..lang.types import FLOAT, VEC4
from ..library.inputs import SURFACE
from .glue import VERTEX_COLOR, _Binder, coverage, coverage_alpha, uv_transform
from .interface import FRAME_BLOCK, OBJECT_BLOCK, INTERPOLANTS, Block, Interface, Location, Texture
from .irgen import Builder
from .program import Program

DEPTH, BLUR = "depth", "blur"  # the units every scene with a shadowed light shares
MASK, MASK_MOMENTS = "mask", "mask_moments"  # per masked permutation: "<hash>.mask", "<hash>.mask_moments"
MASK_ENTRY = "depth_mask"  # the mask program's function: 1 where the fragment is kept, 0 where it is cut
MOMENTS_OUT = Location(0, "out_moments", "vec4")
# The blur's source (the moments of the depth pass, or the first axis' result) and its parameters.
BLUR_SOURCE = Texture("t_moments", "moments", "light", False, "2d", set=0, binding=0)
BLUR_BLOCK = Block("Blur", 0, 2, "uniform", [{"name": "axis_radius", "type": "ivec4", "offset": 0, "size": 16}])


def mask_unit(h: str, moments: bool) -> str:
    """The name of permutation `h`'s masked caster unit (with the moments output, for a VSM light)."""
    return f"{h}.{MASK_MOMENTS if moments else MASK}"


@dataclass
class DepthInterface(Interface):
    """An Interface whose interpolants are what the depth stages pass (none, or uv / COLOR_0 for a mask) rather
    than a material's, reflected without the material's vertex-stage blocks where it has none (the blur)."""

    varyings: list[Location] = field(default_factory=list)

    @property
    def interpolants(self) -> list[Location]:
        return list(self.varyings)

    def as_dict(self) -> dict:
        vert_blocks = [b.as_dict() for b in self.blocks if b.name in ("Frame", "Object")]
        frag_blocks = [b.as_dict() for b in self.blocks if b.name not in ("Frame", "Object")]
        return {"vert": {"entry_point": "main", "uniform_blocks": vert_blocks,
                         "inputs": [x.as_dict() for x in self.vertex_inputs],
                         "outputs": [x.as_dict() for x in self.varyings]},
                "frag": {"entry_point": "main", "uniform_blocks": frag_blocks,
                         "textures": [t.as_dict() for t in self.textures],
                         "inputs": [x.as_dict() for x in self.varyings],
                         "outputs": [x.as_dict() for x in self.outputs]}}


def _frame_object() -> list[Block]:
    return [Block("Frame", 0, 0, "uniform", list(FRAME_BLOCK)), Block("Object", 2, 0, "uniform", list(OBJECT_BLOCK))]


def depth_interface(moments: bool) -> DepthInterface:
    """The shared caster unit: a_position in; the moments out (when a VSM light needs them)."""
    return DepthInterface({"vert": "main", "frag": "main"}, [], ["P"], _frame_object(), [],
                          [MOMENTS_OUT] if moments else [])


def blur_interface() -> DepthInterface:
    """The blur: a fullscreen triangle's a_position in, the moments texture and the Blur block, moments out."""
    return DepthInterface({"vert": "main", "frag": "main"}, [], ["P"], [BLUR_BLOCK], [BLUR_SOURCE], [MOMENTS_OUT])


@dataclass
class MaskProgram:
    """A masked permutation's coverage test: the program holding `depth_mask`, the interface its stages read,
    and how the fragment stage passes each of depth_mask's parameters (compose.compose's call_args shape)."""

    program: Program
    interface: DepthInterface
    call_args: list[dict]


def mask_program(lp, moments: bool = False, lib_memo: dict | None = None) -> MaskProgram:
    """The coverage test of linked permutation `lp` (a LinkedPermutation whose surface alpha is "mask");
    lib_memo: its library's memo (Library.memo), where linked brick functions are shared."""
    r = lp.resolved
    if r.surface.alpha != "mask":
        raise ValueError(f"{r.key}: alpha is {r.surface.alpha!r}, not \"mask\": its casters need no coverage test")
    b = Builder()
    bind = _Binder(b)
    prog = Program(lib_memo=lib_memo)

    def body():
        stmts = []
        uv_node = dict(r.packing.fillers).get("uv")
        if uv_node is not None:  # the packing's uv filler (KHR_texture_transform): the colour pass's uv, read alike
            prog.link(uv_node)
            stmts += uv_transform(prog, b, bind, r.packing)
        cov = coverage(b, bind, r)
        return stmts + [b.decl("coverage", cov), b.ret(coverage_alpha(b, r.surface))]

    stmts = body()  # first: it decides which inputs, parameters and textures depth_mask takes
    surface = [x for x in ("uv",) if x in bind.surface] + (["color"] if r.surface.vertex_color else [])
    sig = [(x, SURFACE[x]) for x in surface if x == "uv"] + ([(VERTEX_COLOR, VEC4)] if "color" in surface else [])
    sig += [(n, t) for n, t in bind.params.items()]  # the uv filler's (offset, scale, rotation)
    sig += [("m_base_alpha", FLOAT), ("m_alpha_cutoff", FLOAT)] + [(t.name, t.ty) for t in bind.textures]
    prog.add(b.function(MASK_ENTRY, sig, FLOAT, lambda: stmts))
    slots = {s.name: s for s in lp.material}
    placed = {t.name: t for t in lp.interface.textures}  # the colour pass's bindings
    textures = [placed[t.name] for t in bind.textures]
    call_args = []
    for name, ty in sig:
        if ty.kind == "texture":
            call_args.append({"kind": "texture", "name": name})
        elif name in slots:
            call_args.append({"kind": "material", "name": name, "slot": slots[name]})
        else:
            call_args.append({"kind": "local", "name": name})
    blocks = _frame_object() + [lp.interface.block("Material")]
    iface = DepthInterface({"vert": "main", "frag": "main"}, [], ["P", *surface], blocks, textures,
                           [MOMENTS_OUT] if moments else [], varyings=[INTERPOLANTS[x] for x in surface])
    return MaskProgram(prog, iface, call_args)
