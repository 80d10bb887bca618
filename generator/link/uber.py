"""The ubershader: every material variant and light type of a set of permutations in one program.

Hoffman & Baker 2006, "Shader Combinatorics": "Ubershader — build one monolithic shader with
all options"; the hybrid uses it as the fallback of the shader matrix. It is linked from the
same bricks and the same glue pieces as the matrix (link/glue.py), so every permutation it
stands in for computes the same code; `coverage()` proves every axis value reachable.

Data (documented in docs/design/link.md, "The ubershader's data"; the manifest lists the tables):
- `material_buffer`: MaterialEntry { ids: ivec4; data: vec4[M] } per material. ids.x is the
  material *variant* — a (BRDF, packing, output) combination of the table `variants`; ids.y the
  material's alpha mode (ALPHA_IDS: 0 opaque, 1 mask, 2 blend), ids.z its emission (EMISSIVE_IDS: 0 none,
  1 factor, 2 texture); ids.w is reserved (0).
  `data` holds the bricks' part of the variant's specialized Material block (the same bytes as the
  specialized permutation's `uploads`, less the surface state's vec4s at its end), M the largest
  of them; where a permutation is masked or blended, data[surface_at] (= that M, and M grows by
  one) holds (base_alpha, alpha_cutoff, 0, 0) and, where a permutation emits, data[surface_at + 1]
  (emissive, 0): the surface state's values at one place for every variant (a specialized block
  packs them after its bricks' part, where each variant's ends).
- Surface state (spec/surface.py), as the specialized shader does it: a variant used by a masked
  or blended permutation computes the same coverage (base_alpha · the packing's base colour
  texture's A) after its output brick and returns it as alpha (BLEND) or 1 / 0 against the cutoff
  (MASK), and the fragment main discards alpha below 0.5 where ids.y says mask (it reads ids.y
  through `surface_alpha_mode(material)`); with a double-sided permutation the main reverses N, T
  and B on back faces, which reach it only where the pipeline culls nothing (a single-sided
  object's pipeline culls them). Blending, culling and depth writes are pipeline state: an object
  is drawn with the ubershader under its permutation's render_state (runtime/pipeline_state.py),
  one pipeline per distinct state. Emission is added to the radiance before the output brick as the
  specialized glue adds it (· the emissive_map's RGB for "texture"). Vertex colours are not in the
  ubershader.
- `light_buffer`: LightEntry { ids: ivec4; data: vec4[K] } per light, looped over with a
  runtime count. ids.x indexes `light_types`, ids.y `shadows`, ids.z the shadow map the
  light's filter samples (0 … shadow_maps-1). data[0 …) holds the light brick's parameters,
  data[A …) the shadow filter's (A = the most vec4s any light type needs), each packed as a
  Lights block packs a light (interface.layout).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from ..lang import ir
from ..lang.types import FLOAT, INT, MAT4, UINT, VEC3, VEC4, Type, array, arrayed_texture, storage_buffer, struct, vector
from ..library.inputs import SURFACE
from ..spec.permutation import Permutation
from ..spec.resolve import Resolved, resolve
from ..spec.where import KeyProblem, within
from .faces import CUBE_TYPES, FACE_MATRICES, FACES, SHADOW_LAYER, arrayed_entry, face_select, faced
from .glue import _Binder, brdf_glue, has_tangent, read_slot, shading_tangent
from .interface import FRAME_BLOCK, OBJECT_BLOCK, Block, Interface, Location, Slot, Texture, layout
from .irgen import Builder
from .program import Program
from .glue import UV_LOCAL  # the ubershader's variants share the specialized glue's uv local
from .uber_surface import ALPHA_IDS, ALPHA_MODE_FUNCTION, EMISSIVE_IDS, emission, surface_alpha  # noqa: F401

IVEC4 = vector("int", 4)


@dataclass
class Variant:
    """One material variant: its bricks and the layout of its MaterialEntry.data (its Material block)."""

    brdf: str
    packing: str
    output: str
    slots: list[Slot]

    @property
    def key(self) -> tuple[str, str, str]:
        return (self.brdf, self.packing, self.output)


@dataclass
class Uber:
    """The linked ubershader: program, tables of reachable values, entry layouts."""

    program: Program
    variants: list[Variant]
    light_types: list[str]
    shadows: list[str]
    shadow_maps: int  # textures the shadow filters sample, per light (one set per light slot)
    material_vec4s: int
    light_split: int  # A: where the shadow filter's parameters start in LightEntry.data
    light_vec4s: int
    light_layouts: dict = field(default_factory=dict)  # (light, shadow) -> {param: Slot in LightEntry.data}
    textures: list[Texture] = field(default_factory=list)
    signature: list[tuple[str, Type]] = field(default_factory=list)
    surface: list[str] = field(default_factory=list)
    reads: list[str] = field(default_factory=list)
    surface_at: int | None = None  # the vec4 of MaterialEntry.data holding (base_alpha, alpha_cutoff, 0, 0)
    alpha_modes: list[str] = field(default_factory=list)  # the permutations' alpha modes, in ALPHA_IDS order
    double_sided: bool = False  # a permutation is double-sided: the main reverses N, T, B on back faces
    emissive: list[str] = field(default_factory=list)  # the permutations' emission modes, in EMISSIVE_IDS order
    faced_shadows: list[str] = field(default_factory=list)  # filters whose maps are 2D arrays (link/faces.py)

    def interface(self, kernel: bool = False) -> Interface:
        """The ubershader's Interface: its buffers, the Draw block, textures, inputs and outputs."""
        def entry(name, vec4s):
            members = [{"name": "ids", "type": "ivec4", "offset": 0, "size": 16},
                       {"name": "data", "type": f"vec4[{vec4s}]", "offset": 16, "size": 16 * vec4s, "array_stride": 16}]
            return [{"name": "data", "type": f"{name}[]", "offset": 0, "size": 0, "array_stride": 16 * (1 + vec4s),
                     "members": members}]
        where = UBER_KERNEL if kernel else UBER_FRAGMENT
        blocks = [] if kernel else [Block("Frame", 0, 0, "uniform", list(FRAME_BLOCK)), Block("Object", 2, 0, "uniform", list(OBJECT_BLOCK)),
                                    Block("Draw", *where["Draw"], "uniform",
                                          [{"name": "material", "type": "ivec4", "offset": 0, "size": 16}])]
        if self.light_types:
            blocks.append(Block("LightBuffer", *where["light_buffer"], "storage",
                                entry("LightEntry", self.light_vec4s)))
        blocks.append(Block("MaterialBuffer", *where["material_buffer"], "storage",
                            entry("MaterialEntry", self.material_vec4s)))
        stages = {"comp": "main"} if kernel else {"vert": "main", "frag": "main"}
        return Interface(stages, self.reads, self.surface, blocks, self.textures, [Location(0, "out_color", "vec4")])

    def tables(self) -> dict:
        return {"variants": [{"id": k, "brdf": v.brdf, "packing": v.packing, "output": v.output,
                              "parameters": [s.as_dict() for s in v.slots]} for k, v in enumerate(self.variants)],
                "light_types": self.light_types, "shadows": self.shadows, "shadow_maps": self.shadow_maps,
                "render_state": "an object's permutation's render_state (cull, blend, depth write): one pipeline per "
                                "distinct state; its material's alpha mode in the entry's ids.y",
                "material_entry": {"ids": "ivec4 (variant, alpha mode, emission, 0)", "data_vec4s": self.material_vec4s,
                                   "alpha_modes": dict(ALPHA_IDS), "emissive_modes": dict(EMISSIVE_IDS),
                                   **({"surface_at": self.surface_at} if self.surface_at is not None else {})},
                "light_entry": {"ids": "ivec4 (light type, shadow, shadow map, 0)", "data_vec4s": self.light_vec4s,
                                "shadow_parameters_at": self.light_split, **self._faces()}}

    def _faces(self) -> dict:
        """What a light entry of a point light's six faces holds (only when some filter reads them)."""
        if not self.faced_shadows:
            return {}
        return {"ids": "ivec4 (light type, shadow, shadow map, faces + 2 x first layer: faces 1 for a point light's "
                       "six, first its first layer in the map's array; 0 for a static light's one map)",
                "faced_shadows": list(self.faced_shadows),
                "faces": "a faced filter's shadow maps are 2D arrays: a point light's six faces (shadow_matrix face "
                         "0's, shadow_matrix_1 ... _5 in its entry as light_layouts say), a dynamic set's pair's "
                         "lights each its layers of one array (one shadow map slot), any other light's one map "
                         "as layer 0"}


def _zero(b: Builder, ty: Type) -> ir.Expr:
    return b.const(0.0) if ty == FLOAT else b.construct(ty, b.const(0.0))


def _switch(b: Builder, selector: ir.Expr, cases: list[list[ir.Stmt]]) -> ir.Switch:
    return ir.Switch(b.loc(), selector, [((k,), body) for k, body in enumerate(cases)], [])


UBER_FRAGMENT = {"light_buffer": (0, 1), "shadow_maps": (0, 2), "Draw": (1, 0), "material_buffer": (1, 1),
                 "material_textures": (1, 2)}
UBER_KERNEL = {"light_buffer": (0, 3), "material_buffer": (0, 4)}  # after samples 0, result 1, Info 2


SPEC_VARIANT = 0  # SpecId of the material variant in the specialization-constant ubershader


def link_ubershader(perms: list[Permutation | Resolved], lib, kernel: bool = False,
                    specialized: bool = False) -> Uber:
    """One program whose shade(P, Ng, V[, T, B][, uv], material, textures...) stands in for every permutation
    (resolved, or resolved here).

    Bindings: UBER_FRAGMENT for the fragment ubershader (set 0: Frame 0, light buffer 1, shadow maps 2+;
    set 1: Draw 0 (ivec4: x the material index), material buffer 1, material textures 2+), UBER_KERNEL
    for the compute stand-in the tests run (no textures).
    """
    from . import link_permutation

    variants: list[Variant] = []
    resolved: list[Resolved] = []  # per variant: its material without lights, as the matrix links it
    light_types: list[str] = []
    shadows: list[str] = []
    lights, shadow_of = {}, {}  # light type -> its LightPart's params; shadow spec -> the filter's node, params
    shadowed = 0
    faced_shadows: set[str] = set()  # the filters whose maps are 2D arrays: six faces, or a buffer pair's lights
    cube_shadows: set[str] = set()  # those some point light reads six faces with (link/faces.py)
    alpha_variants: set[int] = set()  # the variants a masked or blended permutation uses
    modes, double_sided, emits = {"opaque"}, False, {"none"}
    for r in [p if isinstance(p, Resolved) else resolve(p, lib) for p in perms]:
        p = r.perm
        if p.environment:  # located at the environment that lights it (the scene's [environments.NAME])
            with within(p.origin, p.canonical()):
                raise KeyProblem("environment", "the ubershader does not draw environments yet (image-based "
                                 f"lighting: {p.canonical()})", "set [scene] ubershader = false and render with "
                                 "--mode specialized, or light this set without an environment")
        if (p.brdf, p.packing, p.output) not in [v.key for v in variants]:
            probe = resolve(Permutation(p.brdf, (), p.packing, p.output, p.precision, origin=p.origin), lib)
            variants.append(Variant(p.brdf, p.packing, p.output, link_permutation(probe, lib).material))
            resolved.append(probe)
        if p.surface.alpha != "opaque":
            alpha_variants.add([v.key for v in variants].index((p.brdf, p.packing, p.output)))
        modes.add(p.surface.alpha)
        double_sided = double_sided or p.surface.double_sided
        emits.add(p.surface.emissive)
        for lk, lt in zip(p.lights, r.lights):
            if lk.light not in light_types:
                light_types.append(lk.light)
                lights[lk.light] = (lt.node, lt.light_params)
            if lk.shadow not in shadows:
                shadows.append(lk.shadow)
                shadow_of[lk.shadow] = (lt.shadow, lt.shadow_params)
            if faced(lk.light, lt.textures):  # its filter's maps are arrays: a point light's six faces
                faced_shadows.add(lk.shadow)
                cube_shadows.add(lk.shadow)
            if lk.dynamic and lt.textures:  # or a buffer pair's lights, each its layers of one array
                faced_shadows.add(lk.shadow)
        shadowed = max(shadowed, sum(1 for lt in r.lights if lt.textures))
    prog, b = Program(lib_memo=lib.memo), Builder()
    bind = _Binder(b)
    M = max([1] + [max([1] + [s.index + s.width for s in v.slots]) for v in variants])
    surface_at = M if alpha_variants or len(emits) > 1 else None  # alpha values there, the emission after
    M += 0 if surface_at is None else 1 + (len(emits) > 1)
    lnodes = {t: lights[t][0] for t in light_types}
    snodes = {s: shadow_of[s][0] for s in shadows}
    A = max([1] + [_vec4s(lights[t][1]) for t in light_types])
    S = max([0] + [_vec4s(shadow_of[s][1]) for s in shadows])
    F = 4 * (FACES - 1) if cube_shadows else 0  # the faces' matrices 1 … 5 after every filter's parameters
    K = A + max(S, 1) + F
    mat_data, light_data = array(VEC4, M), array(VEC4, K)
    MaterialEntry = struct("MaterialEntry", (("ids", IVEC4), ("data", mat_data)))
    LightEntry = struct("LightEntry", (("ids", IVEC4), ("data", light_data)))
    mbuf = ir.Global("material_buffer", storage_buffer(MaterialEntry))
    lbuf = ir.Global("light_buffer", storage_buffer(LightEntry))
    prog.structs += [MaterialEntry, LightEntry]
    prog.globals += [mbuf] + ([lbuf] if lnodes else [])  # no lights: nothing reads a light buffer

    glues, packings, outputs = [], [], []
    for k, v in enumerate(resolved):
        glues.append(brdf_glue(prog, v.brdf, v.brdf_params, suffix=f"_{k}", guarded=False, b=b))
        prog.link(v.packing)
        packings.append(v.packing)
        prog.link(v.output_node)
        outputs.append(v.output_node)
    for n in list(lnodes.values()) + list(snodes.values()):
        prog.link(n)
    layouts = {}
    for t in lnodes:
        for s in snodes:
            own = _packed(lights[t][1]) + _packed(shadow_of[s][1], A)
            if t in CUBE_TYPES and s in cube_shadows:
                own += _face_slots(shadow_of[s][1], A + max(S, 1))
            layouts[(t, s)] = {x.name: x for x in own}

    me = b.var("me", MaterialEntry)
    if specialized:
        spec = ir.Global("material_variant", INT, 0, SPEC_VARIANT)
        prog.globals.append(spec)
        variant = ir.Var(INT, b.here(), spec.name, "global")
    else:
        variant = ir.Swizzle(INT, b.here(), ir.Member(IVEC4, b.here(), b.copy(me), "ids"), "x")
    provided: dict[str, Type] = {}
    for pk in packings:
        for f in pk.brick.entries:
            provided[f.name[len("get_"):]] = f.ret

    twisted = any(g.tangent and has_tangent(dict(pk.fillers)["normal"]) for g, pk in zip(glues, packings))

    def material_args(k) -> dict[str, ir.Expr]:
        """Variant k's parameters read from the entry, by the name an entry binds (alpha, lobes_0, ev)."""
        return {s.name[2:]: read_slot(b, me, mat_data, s) for s in variants[k].slots}

    def body():
        stmts = [b.decl("me", ir.Index(MaterialEntry, b.here(), ir.Var(mbuf.ty, b.here(), mbuf.name, "global"),
                                       b.var("material", INT, "param")))]
        for name, ty in provided.items():
            stmts.append(b.decl(f"p_{name}", _zero(b, ty)))
        stmts.append(b.decl("N", b.construct(VEC3, b.const(0.0))))
        if twisted:  # the BRDFs' frame: the interpolated T, B unless the variant's normal filler gives T'
            stmts += [b.decl("Ts", b.var("T", VEC3, "param")), b.decl("Bs", b.var("B", VEC3, "param"))]
        uvs = [dict(pk.fillers).get("uv") for pk in packings]  # the variants' uv fillers (glue.uv_transform)
        if any(uvs):  # uv_t: the interpolated uv, or in a variant with a filler what the filler returns
            bind.surface.add("uv")
            stmts.append(b.decl(UV_LOCAL, b.var("uv", SURFACE["uv"], "param")))
        cases = []
        for k, pk in enumerate(packings):
            args = material_args(k)
            case = []
            if uvs[k] is not None:
                case.append(b.assign(b.var(UV_LOCAL, SURFACE["uv"]),
                                     bind.call(prog, uvs[k], "map_uv", "m_", "material", None, {}, args)))
                args = {**args, "uv": b.var(UV_LOCAL, SURFACE["uv"])}
            case += [b.assign(b.var(f"p_{f.name[len('get_'):]}", f.ret),
                              bind.call(prog, pk, f.name, "m_", "material", None, {}, args)) for f in pk.brick.entries]
            normal = dict(pk.fillers)["normal"]
            case.append(b.assign(b.var("N", VEC3), bind.call(prog, normal, normal.brick.entries[0].name, "m_",
                                                            "material", None, {}, args)))
            case += [b.assign(b.var(n, VEC3), e) for n, e in shading_tangent(prog, b, bind, normal, glues[k].tangent,
                                                                             args)]
            cases.append(case)
        stmts.append(_switch(b, b.copy(variant), cases))
        stmts.append(b.decl("Lo", b.construct(VEC3, b.const(0.0))))
        if lnodes:  # a scene without lights shades black: no loop, the light buffer is still bound
            stmts.append(_light_loop(b, prog, bind, lbuf, LightEntry, light_data, lnodes, snodes, layouts, glues,
                                     packings, provided, material_args, variant, shadowed, twisted, faced_shadows))
        if len(emits) > 1:
            stmts += emission(b, bind, me, mat_data, surface_at + 1, "texture" in emits, bool(any(uvs)))
        stmts.append(b.decl("color", b.construct(VEC4, b.const(0.0))))
        outs = [[b.assign(b.var("color", VEC4), bind.call(prog, on, "output", "o_", "material", None, {},
                                                          {**material_args(k), "color": b.var("Lo", VEC3)}))]
                + (surface_alpha(b, bind, me, mat_data, surface_at, packings[k], bool(uvs[k]))
                   if k in alpha_variants else [])
                for k, on in enumerate(outputs)]
        stmts.append(_switch(b, b.copy(variant), outs))
        stmts.append(b.ret(b.var("color", VEC4)))
        return stmts

    stmts = body()
    if "mask" in modes and not kernel:  # the fragment main discards by the entry's alpha mode
        prog.add(b.function(ALPHA_MODE_FUNCTION, [("material", INT)], INT, lambda: [b.ret(ir.Swizzle(
            INT, b.here(), ir.Member(IVEC4, b.here(), ir.Index(MaterialEntry, b.here(), ir.Var(
                mbuf.ty, b.here(), mbuf.name, "global"), b.var("material", INT, "param")), "ids"), "y"))]))
    leftover = [n for n in bind.params]
    if leftover:
        with within(resolved[0].origin, resolved[0].key):  # where the scene asks for its first material
            raise KeyProblem("brdf", f"the ubershader cannot bind {', '.join(leftover)}",
                             "every parameter comes from the material or light entry")
    tangent = any(g.tangent for g in glues)
    surface = ["P", "N"] + (["T", "B"] if tangent or bind.surface & {"T", "B"} else []) \
        + (["uv"] if "uv" in bind.surface else [])
    sig = [("P", VEC3), ("Ng", VEC3), ("V", VEC3)] + [(x, SURFACE[x]) for x in surface if x in ("T", "B", "uv")]
    sig += [("material", INT)] + [(t.name, t.ty) for t in bind.textures]
    prog.add(b.function("shade", sig, VEC4, lambda: stmts))
    reads = list(dict.fromkeys(r for g in glues for r in g.reads))
    where = UBER_KERNEL if kernel else UBER_FRAGMENT
    mbuf.set, mbuf.binding = where["material_buffer"]
    lbuf.set, lbuf.binding = where["light_buffer"]
    if kernel and bind.textures:
        name = bind.textures[0].param
        v = next((v for v in resolved if name in v.textures), resolved[0])  # the material whose bricks sample it
        with within(v.origin, v.key):
            raise KeyProblem("brdf" if any(name in n.textures for n in v.brdf) else "packing",
                             f"an ubershader kernel binds no textures, and its bricks sample '{name}'",
                             "run texture-sampling materials in the fragment ubershader")
    nxt = {"light": where.get("shadow_maps", (0, 0))[1], "material": where.get("material_textures", (1, 0))[1]}
    for tex in bind.textures:
        tex.set = 0 if tex.group == "light" else 1
        tex.binding = nxt[tex.group]
        nxt[tex.group] += 2
    return Uber(prog, variants, light_types, shadows, shadowed, M, A, K, layouts, bind.textures, sig, surface, reads,
                surface_at, [m for m in ALPHA_IDS if m in modes], double_sided, [m for m in EMISSIVE_IDS if m in emits],
                sorted(faced_shadows))


def _face_slots(shadow_params, start: int) -> list[Slot]:
    """Faces 1 … 5's matrices (FACE_MATRICES) packed from vec4 `start`, each like the filter's shadow_matrix."""
    base = shadow_params["shadow_matrix"]
    return layout([(n, n, None, base.ty, dataclasses.replace(base, name=n), None) for n in FACE_MATRICES[1:]],
                  start)[0]


def _faced_case(b, prog, bind, sn, sel, le, light_data, slots, args, call) -> list:
    """The statements of filter `sn`'s case for arrays: ids.w = faces + 2 × first (faces 1 for a point light's six,
    first its first layer: a buffer pair's lights share one array); layer first + face, face 0 and `shadow_matrix`,
    or with faces the face of -L and its matrix from the entry (`slots`: faces 1 … 5's, None where no point light
    reads this filter); then `call(fn, targs)` (link/faces.py)."""
    two = ir.Const(INT, b.here(), 2)
    first = ir.Binary(INT, b.here(), "/", sel("w"), two)
    if slots is None:
        return [call(arrayed_entry(prog, sn), {**args, SHADOW_LAYER: first})]
    m = b.var("shadow_m", MAT4)
    pick = face_select(b, ir.Unary(VEC3, b.here(), "-", b.var("L", VEC3)), "cube_face")
    pick.append(b.assign(b.var("face", INT), b.var("cube_face", INT)))
    for k, n in enumerate(FACE_MATRICES[1:], 1):
        pick.append(b.if_(b.compare("==", b.var("face", INT), ir.Const(INT, b.here(), k)),
                          [b.assign(b.copy(m), read_slot(b, le, light_data, slots[n]))]))
    faces = ir.Binary(INT, b.here(), "%", sel("w"), b.copy(two))
    return [b.decl("face", ir.Const(INT, b.here(), 0)), b.decl("shadow_m", b.copy(args["shadow_matrix"])),
            b.if_(b.compare("==", faces, ir.Const(INT, b.here(), 1)), pick),
            call(arrayed_entry(prog, sn), {**args, "shadow_matrix": b.var("shadow_m", MAT4),
                                           SHADOW_LAYER: ir.Binary(INT, b.here(), "+", b.copy(first),
                                                                   b.var("face", INT))})]


def _texture_types(node) -> dict[str, Type]:
    """The type of each texture a node's bricks sample, by name (as their functions declare it)."""
    return {p.name: p.ty for n in node.tree for f in n.brick.module.functions.values() for p in f.params
            if p.ty.kind == "texture" and p.name in n.brick.textures}


def _packed(params, start: int = 0) -> list[Slot]:
    """A light's or shadow filter's parameters packed from vec4 `start` of LightEntry.data (interface.layout)."""
    return layout([(n, k, e, ty, p, None) for n, k, e, ty, p in params.flat], start)[0]


def _vec4s(params) -> int:
    """vec4s a parameter group occupies, packed."""
    return layout([(n, k, e, ty, p, None) for n, k, e, ty, p in params.flat])[1]


def _light_loop(b, prog, bind, lbuf, LightEntry, light_data, lnodes, snodes, layouts, glues, packings, provided,
                material_args, variant, shadowed, twisted=False, faced_shadows=()) -> ir.For:
    """for i in range(buffer_length(light_buffer)): switch on light type, on shadow filter, on variant."""
    le = b.var("le", LightEntry)
    ids = ir.Member(IVEC4, b.here(), b.copy(le), "ids")

    def sel(c):
        return ir.Swizzle(INT, b.here(), b.copy(ids), c)

    def light_args(t, s):
        return {name: read_slot(b, le, light_data, x) for name, x in layouts[(t, s)].items()}

    first_shadow = next(iter(snodes))
    body = [b.decl("le", ir.Index(LightEntry, b.here(), ir.Var(lbuf.ty, b.here(), lbuf.name, "global"),
                                  b.var("i", UINT))),
            b.decl("L", b.construct(VEC3, b.const(0.0)))]
    body.append(_switch(b, sel("x"), [[b.assign(b.var("L", VEC3), bind.call(
        prog, ln, "light_dir", "l_", "light", None, {"N": VEC3}, light_args(t, first_shadow)))]
        for t, ln in lnodes.items()]))
    body.append(b.decl("NdotL", b.intrinsic("dot", FLOAT, b.var("N", VEC3), b.var("L", VEC3))))
    lit = [b.decl("c", b.construct(VEC3, b.const(0.0))), b.decl("s", b.const(1.0))]
    lit.append(_switch(b, sel("x"), [[b.assign(b.var("c", VEC3), bind.call(
        prog, ln, "light_radiance", "l_", "light", None, {"N": VEC3}, light_args(t, first_shadow)))]
        for t, ln in lnodes.items()]))
    first_light = next(iter(lnodes))
    shadow_cases = []
    for s, sn in snodes.items():
        texnames = [x for n in sn.tree for x in n.brick.textures]
        textype = _texture_types(sn)
        args = light_args(first_light, s)
        if not texnames:
            shadow_cases.append([b.assign(b.var("s", FLOAT), bind.call(prog, sn, sn.brick.entries[0].name, "l_",
                                                                       "light", None, {"N": VEC3}, args))])
            continue
        per_map = []
        arrays = s in faced_shadows  # every map of this filter is a 2D array (one layer, or a point light's six)
        if arrays:
            textype = {t: arrayed_texture(ty) for t, ty in textype.items()}
            cube = next((t for t in lnodes if t in CUBE_TYPES), None)
            faces_at = layouts[(cube, s)] if cube is not None and FACE_MATRICES[1] in layouts[(cube, s)] else None
        for j in range(max(shadowed, 1)):
            targs = dict(args)
            for tex in texnames:
                # two filters may name their maps alike (pcf's and shadow_map's `shadow_map`): an array's name says
                # so, or a 2D map and a 2D array of two filters would be one declaration
                name = f"shadow{j}_{tex}" + ("_layers" if arrays else "")
                if name not in {t.name for t in bind.textures}:
                    bind.textures.append(Texture(name, tex, "light", False, textype[tex].dim, j,
                                                 compare=textype[tex].compare))
                targs[tex] = b.var(name, textype[tex], "param")
            if arrays:
                per_map.append(_faced_case(b, prog, bind, sn, sel, le, light_data, faces_at, targs, lambda fn, a: b.assign(
                    b.var("s", FLOAT), bind.call(prog, sn, "", "l_", "light", None, {"N": VEC3}, a, fn))))
            else:
                per_map.append([b.assign(b.var("s", FLOAT), bind.call(prog, sn, sn.brick.entries[0].name, "l_",
                                                                      "light", None, {"N": VEC3}, targs))])
        shadow_cases.append([_switch(b, sel("z"), per_map)])
    lit.append(_switch(b, sel("y"), shadow_cases))
    lit.append(b.decl("f", b.construct(VEC3, b.const(0.0))))
    brdf_cases = []
    for k, g in enumerate(glues):
        margs = material_args(k)
        own = {f.name[len("get_"):] for f in packings[k].brick.entries}  # what variant k's packing provides
        args = []
        for n, t in g.signature:
            if n == "L":
                args.append(b.var("L", VEC3))
            elif n == "N":
                args.append(b.var("N", VEC3))
            elif n in ("T", "B") and twisted:
                args.append(b.var(f"{n}s", t))
            elif n in ("V", "T", "B"):
                args.append(b.var(n, t, "param"))
            elif n in own:
                args.append(b.var(f"p_{n}", provided[n]))
            elif t.kind == "texture":
                tname = f"t_{n}"
                if tname not in {x.name for x in bind.textures}:
                    bind.textures.append(Texture(tname, n, "material", False, t.dim, compare=t.compare))
                args.append(b.var(tname, t, "param"))
            else:
                args.append(b.copy(margs[n]))
        brdf_cases.append([b.assign(b.var("f", VEC3), b.call(g.lit, args))])
    lit.append(_switch(b, b.copy(variant), brdf_cases))
    term = b.arith("*", b.arith("*", b.arith("*", b.named_const("PI"), b.var("f", VEC3)), b.var("c", VEC3)),
                   b.arith("*", b.var("NdotL", FLOAT), b.var("s", FLOAT)))
    lit.append(b.assign(b.var("Lo", VEC3), term, "+"))
    body.append(b.if_(b.compare(">", b.var("NdotL", FLOAT), b.const(0.0)), lit))
    bound = b.intrinsic("buffer_length", UINT, ir.Var(lbuf.ty, b.here(), lbuf.name, "global"))
    return ir.For(b.loc(), "i", 0, body, bound)


def coverage(uber: Uber, perms: list[Permutation], lib) -> list[str]:
    """Every axis value the matrix uses that the ubershader cannot reach, as one line each."""
    problems = []
    keys = {v.key for v in uber.variants}
    for r in [resolve(p, lib) for p in perms]:
        p = r.perm
        if (p.brdf, p.packing, p.output) not in keys:
            problems.append(f"material (brdf={p.brdf}, packing={p.packing}, output={p.output}) of {p.hash} "
                            "is no variant of the ubershader")
        for lk in p.lights:
            if lk.light not in uber.light_types:
                problems.append(f"light type '{lk.light}' of {p.hash} is not in the ubershader's light switch")
            if lk.shadow not in uber.shadows:
                problems.append(f"shadow filter '{lk.shadow}' of {p.hash} is not in the ubershader's shadow switch")
        need = sum(1 for lt in r.lights if lt.textures)
        if need > uber.shadow_maps:
            problems.append(f"{p.hash} samples {need} shadow maps; the ubershader binds {uber.shadow_maps}")
    return problems
