"""The glue, built as IR: the BRDF from its terms, the light loop, the switch over BRDFs.

- `brdf_lit(L, V, N[, T, B], params..., textures...) -> vec3`: the shading inputs
  the terms read (from the inputs table, in its order) and the sum of the terms.
- `brdf(...)`: 0 below the horizon, else brdf_lit (the eval kernel's entry).
- `brdf_switch(id, ...)`: one `brdf_<k>` per BRDF behind a switch on an integer id.
- `shade(P, Ng, V[, T, B][, uv], material..., lights..., textures...) -> vec4`: the
  packing's material inputs, the shading normal, the unrolled light loop
  L_o += π f_r c_light (n·l) visibility (Hoffman & Baker 2006), the output brick.
Entry parameters are bound by name (library/kinds.py): shading inputs, surface
inputs, parameters and textures.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from ..lang import SourceError, ir
from ..lang.types import FLOAT, INT, MAT4, UINT, VEC3, VEC4, Type, array, storage_buffer, struct, vector
from ..library.inputs import BY_NAME, FRAME, SHADING, SURFACE, TANGENT_FRAME, closure, expression
from ..spec.params import Params
from ..spec.permutation import Node
from ..spec.resolve import LightPart, Resolved, ResolvedBrdf
from ..spec.surface import EMISSIVE_MAP
from .faces import (FACE_MATRICES, FIRST_LAYER, SHADOW_LAYER, arrayed_entry, buffer_params, face_params, faced,
                    faced_call, first_layer)
from .interface import VEC4_BYTES, Slot, Texture, layout, texture_type
from .irgen import Builder
from .program import Program
from .tiles import FRAG_COORD, VEC2, tile_record, tiled_loop, tiles_global


def _texture_decl(nodes, name: str) -> dict:
    """The declaration of texture `name` by the first of `nodes` whose bricks declare it (Node.textures)."""
    for top in nodes:
        if name in top.textures:
            return top.textures[name]
    return {}


@dataclass
class BrdfGlue:
    """brdf_lit (and brdf) of one BRDF, with the parameters they take."""

    lit: ir.Function
    guarded: ir.Function | None
    frame: list[tuple[str, Type]]  # L, V, N[, T, B]
    params: Params  # material parameters, in spec order (the resolved BRDF's)
    textures: list[tuple[str, Type, dict]]  # (name, type, declaration) of textures the terms read
    reads: list[str]  # shading inputs read (frame rows included)

    @property
    def tangent(self) -> bool:
        return any(n == "T" for n, _ in self.frame)

    @property
    def signature(self) -> list[tuple[str, Type]]:
        return self.frame + [(n, t) for n, _, _, t, _ in self.params.flat] + [(n, t) for n, t, _ in self.textures]


def brdf_glue(prog: Program, nodes, params: Params, suffix: str = "", guarded: bool = True,
              b: Builder | None = None) -> BrdfGlue:
    """Link a BRDF's terms into `prog` and add brdf_lit<suffix> (and brdf<suffix> when `guarded`); `params`
    the resolved BRDF's parameters (spec/resolve.py)."""
    b = b or Builder()
    for n in nodes:
        prog.link(n)
    entries = [prog.entry(n, n.brick.entries[0].name) for n in nodes]
    reads = sorted({p.name for f in entries for p in f.params if p.name in SHADING},
                   key=lambda k: list(BY_NAME).index(k))
    textures = []
    for f in entries:
        for p in f.params:
            if p.ty.kind == "texture" and p.name not in {t[0] for t in textures}:
                textures.append((p.name, p.ty, _texture_decl(nodes, p.name)))
    counts = {f"{a}_count": c for top in nodes for n in top.tree for a, c in n.counts}
    unknown = [p for f in entries for p in f.params
               if p.name not in SHADING and p.name not in params and p.ty.kind != "texture" and p.name not in counts]
    if unknown:
        p = unknown[0]
        raise SourceError(p.loc.path, p.loc.line, p.loc.col, f"'{p.name}' is bound by nothing in this BRDF",
                          "name a shading input, a declared parameter or a texture")
    tangent = any(BY_NAME[r].tangent for r in reads)
    frame = [(n, BY_NAME[n].ty) for n in FRAME + (TANGENT_FRAME if tangent else ())]
    sig = frame + [(n, t) for n, _, _, t, _ in params.flat] + [(n, t) for n, t, _ in textures]

    def arg(p, env):
        if p.name in counts:  # an array's element count: a constant of the permutation key
            return ir.Const(INT, b.here(), counts[p.name])
        return b.var(p.name, env[p.name])

    def lit_body():
        body = []
        for k, spec in params.items():  # array parameters arrive as elements; the terms take the array
            if spec.ty.kind == "array":
                elems = [b.var(f"{k}_{i}", spec.ty.elem) for i in range(spec.ty.size)]
                body.append(b.decl(k, b.construct(spec.ty, *elems)))
        for name in closure(reads):
            body.append(b.decl(name, b.copy(expression(name))))
        env = dict(sig) | {name: BY_NAME[name].ty for name in closure(reads)} | {k: s.ty for k, s in params.items()}
        terms = [b.call(f, [arg(p, env) for p in f.params]) for f in entries]
        total = terms[0]
        for t in terms[1:]:
            total = b.arith("+", total, t)
        body.append(b.ret(total))
        return body

    lit = prog.add(b.function(f"brdf_lit{suffix}", sig, VEC3, lit_body))
    g = None
    if guarded:
        def guarded_body():
            below = b.compare("<=", b.intrinsic("dot", FLOAT, b.var("N", VEC3), b.var("L", VEC3)), b.const(0.0))
            return [b.if_(below, [b.ret(b.construct(VEC3, b.const(0.0)))]),
                    b.ret(b.call(lit, [b.var(n, t) for n, t in sig]))]
        g = prog.add(b.function(f"brdf{suffix}", sig, VEC3, guarded_body))
    return BrdfGlue(lit, g, frame, params, textures, frame_names(frame) + [r for r in reads if r not in FRAME + TANGENT_FRAME])


def frame_names(frame) -> list[str]:
    return [n for n, _ in frame]


# ------------------------------------------------------------------ fragment shading


@dataclass
class ShadeGlue:
    """The fragment glue of a permutation and what its template must feed `shade()`."""

    signature: list[tuple[str, Type]]  # shade()'s parameters, in order
    surface: list[str]  # interpolants read: P, N, then T, B and uv where needed
    material: list[tuple]  # (glue name, param, element or None, type, spec)
    lights: list[list[tuple]]  # per light, the same
    textures: list[Texture]
    brdf: BrdfGlue
    light_buffers: list[ir.Global] = field(default_factory=list)  # per dynamic light: its storage buffer
    light_buffer_slots: list[list[Slot]] = field(default_factory=list)  # and where its element holds each value
    light_tiles: ir.Global | None = None  # a tiled dynamic set's LightTiles buffer (link/tiles.py)
    environment: list[tuple] = field(default_factory=list)  # the environment's values (e_*), as `material`


class _Binder:
    """Binds entry parameters by name to shade()'s locals, parameters and textures."""

    def __init__(self, b: Builder):
        self.b = b
        self.textures: list[Texture] = []
        self.params: dict[str, Type] = {}  # shade() parameters for values (m_*, l<i>_*, o_*)
        self.surface: set[str] = set()
        self.uv: ir.Expr | None = None  # the packing's uv filler's result (uv_transform): what a read of uv gets

    def call(self, prog: Program, node: Node, fname: str, prefix: str, group: str, light: int | None,
             locals_: dict[str, Type], args: dict[str, ir.Expr] | None = None, fn: ir.Function | None = None) -> ir.Call:
        f = fn or prog.entry(node, fname)  # fn: a linker-made variant of the entry (link/faces.py)
        out = []
        for p in f.params:
            if args and p.name in args:
                out.append(self.b.copy(args[p.name]))
            elif p.ty.kind == "texture":
                name = ("t_" if group == "material" else prefix) + p.name
                if name not in {t.name for t in self.textures}:
                    decl = _texture_decl([node], p.name)
                    self.textures.append(Texture(name, p.name, group, bool(decl.get("srgb")), p.ty.dim, light,
                                                 compare=p.ty.compare))
                out.append(self.b.var(name, p.ty, "param"))
            elif p.name == "N":
                self.surface.add("N")
                out.append(self.b.var("Ng", VEC3, "param"))  # surface bricks read the interpolated normal
            elif p.name in locals_:
                out.append(self.b.var(p.name, locals_[p.name]))
            elif p.name == "uv" and self.uv is not None:
                self.surface.add("uv")
                out.append(self.b.copy(self.uv))
            elif p.name in SURFACE:
                self.surface.add(p.name)
                out.append(self.b.var(p.name, SURFACE[p.name], "param"))
            else:
                self.params[prefix + p.name] = p.ty
                out.append(self.b.var(prefix + p.name, p.ty, "param"))
        return self.b.call(f, out)

    def param(self, name: str, ty: Type) -> ir.Var:
        """shade()'s parameter `name` (a value of the Lights or Material block), bound."""
        self.params[name] = ty
        return self.b.var(name, ty, "param")


def shade_glue(prog: Program, r: Resolved) -> ShadeGlue:
    """Link a permutation's bricks into `prog` and add the brdf_lit() and shade() glue."""
    b = Builder()
    bg = brdf_glue(prog, r.brdf, r.brdf_params, guarded=False, b=b)
    normal = r.normal
    prog.link(r.packing)
    for lt in r.lights:
        prog.link(lt.node)
        prog.link(lt.shadow)
    out_node = r.output_node
    prog.link(out_node)
    if r.environment is not None:
        prog.link(r.environment)
    bind = _Binder(b)
    dynamic_lights: list[ir.Global] = []
    buffer_slots: list[list[Slot]] = []
    provided: dict[str, ir.Expr] = {}
    lights = []
    tiled = [tiles_global(prog)] if any(k.tiles for k in r.perm.lights) else []

    def body():
        stmts = uv_transform(prog, b, bind, r.packing)
        for f in r.packing.brick.entries:
            name = f.name[len("get_"):]
            call = bind.call(prog, r.packing, f.name, "m_", "material", None, {})
            stmts.append(b.decl(f"p_{name}", call))
            provided[name] = b.var(f"p_{name}", call.ty)
        stmts.extend(surface_inputs(b, bind, r, bg, provided))
        stmts.append(b.decl("N", bind.call(prog, normal, normal.brick.entries[0].name, "m_", "material", None, {})))
        stmts.extend(b.decl(n, e) for n, e in shading_tangent(prog, b, bind, normal, bg.tangent))
        stmts.append(b.decl("Lo", b.construct(VEC3, b.const(0.0))))
        locals_ = {"N": VEC3}
        for n, k, _, ty, _ in bg.params.flat:
            if k not in provided:
                bind.params[f"m_{n}"] = ty
        def f_r(Li):  # the BRDF for light direction Li
            brdf_args = []
            for n, t in bg.signature:
                if n == "L":
                    brdf_args.append(b.var(Li, VEC3))
                elif n == "N":
                    brdf_args.append(b.var("N", VEC3))
                elif n in ("T", "B") and has_tangent(normal):
                    brdf_args.append(b.var(f"{n}s", t))
                elif n in ("V", "T", "B"):
                    brdf_args.append(b.var(n, t, "param"))
                elif n in provided:
                    brdf_args.append(b.copy(provided[n]))
                elif t.kind == "texture":
                    brdf_args.append(bind_texture(bind, n, t, r.brdf))
                else:
                    brdf_args.append(b.var(f"m_{n}", t, "param"))
            return b.call(bg.lit, brdf_args)

        def term(j):  # Lo += π f_r c (n·l) visibility, for light (or switch loop) j's locals
            t = b.arith("*", b.arith("*", b.arith("*", b.named_const("PI"), f_r(f"L{j}")), b.var(f"c{j}", VEC3)),
                        b.arith("*", b.var(f"NdotL{j}", FLOAT), b.var(f"s{j}", FLOAT)))
            return b.assign(b.var("Lo", VEC3), t, "+")

        def lit_if(j, stmts_):  # if (NdotL<j> > 0) { stmts_; Lo += ... }
            return b.if_(b.compare(">", b.var(f"NdotL{j}", FLOAT), b.const(0.0)), stmts_ + [term(j)])

        def ndotl(j):
            return b.decl(f"NdotL{j}", b.intrinsic("dot", FLOAT, b.var("N", VEC3), b.var(f"L{j}", VEC3)))

        def loop(j, body_j):  # for k<j> in range(the buffer's length)
            g = dynamic_lights[-1]
            bound = b.intrinsic("buffer_length", UINT, ir.Var(g.ty, b.here(), g.name, "global"))
            return ir.For(b.loc(), f"k{j}", 0, body_j, bound)

        def switch_loop(j, pairs):
            """One loop over one buffer of every light of `pairs` ((light index, LightPart)), switching on the
            pair: L first, then (lit) the radiance and visibility; one BRDF evaluation per light."""
            entry, values = _switch_buffer(prog, b, j, pairs, dynamic_lights, buffer_slots)

            def cases(make):  # switch (le<j>.ids.x) { case i: make(i) }
                sel = ir.Swizzle(INT, b.here(), ir.Member(IVEC4, b.here(), b.var(f"le{j}", entry.ty), "ids"), "x")
                return ir.Switch(b.loc(), sel, [((i,), make(i, lt)) for i, lt in pairs], [])

            def call(i, node, fname):
                return bind.call(prog, node, fname, f"l{i}_", "light", i, locals_, values[i])
            body_j = [b.decl(f"le{j}", entry), b.decl(f"L{j}", b.construct(VEC3, b.const(0.0))),
                      cases(lambda i, lt: [b.assign(b.var(f"L{j}", VEC3), call(i, lt.node, "light_dir"))]),
                      ndotl(j)]
            lit = [b.decl(f"c{j}", b.construct(VEC3, b.const(0.0))), b.decl(f"s{j}", b.const(1.0)),
                   cases(lambda i, lt: [b.assign(b.var(f"c{j}", VEC3), call(i, lt.node, "light_radiance")),
                                        b.assign(b.var(f"s{j}", FLOAT),
                                                 call(i, lt.shadow, lt.shadow.brick.entries[0].name))])]
            body_j.append(lit_if(j, lit))
            return loop(j, body_j)

        switched = [(i, lt) for i, lt in enumerate(r.lights) if r.perm.lights[i].switch]
        if tiled:  # the fragment's tile, once for every pair's loop
            stmts.extend(tile_record(b, tiled[0], len(r.lights)))
        for i, lt in enumerate(r.lights):
            pre = f"l{i}_"
            lights.append(pre)
            if switched and i == switched[0][0]:
                stmts.append(switch_loop(i, switched))
            if r.perm.lights[i].switch:
                continue
            ln, sh, dyn = lt.node, lt.shadow, lt.dynamic
            values = _light_buffer(prog, b, i, lt, dynamic_lights, buffer_slots) if dyn else None
            body_i = [b.decl(f"L{i}", bind.call(prog, ln, "light_dir", pre, "light", i, locals_, values)), ndotl(i)]
            c = b.decl(f"c{i}", bind.call(prog, ln, "light_radiance", pre, "light", i, locals_, values))
            # a buffer light's layer in its pair's array starts at its element's first layer (link/faces.py)
            first = first_layer(b, values[FIRST_LAYER]) if dyn and lt.textures else None
            if faced(lt.brick.id, lt.textures):  # six faces: the face's matrix and layer (link/faces.py)
                mats = [values[n] if values else bind.param(pre + n, MAT4) for n in FACE_MATRICES]
                s = faced_call(b, bind, prog, sh, i, b.var(f"L{i}", VEC3), mats, lambda fn, a, sh=sh, pre=pre, i=i, v=values:
                               bind.call(prog, sh, "", pre, "light", i, locals_, {**(v or {}), **a}, fn), first)
            elif first is not None:  # a buffer spot or directional light: its one layer
                s = [b.decl(f"s{i}", bind.call(prog, sh, "", pre, "light", i, locals_, {**values, SHADOW_LAYER: first},
                                               arrayed_entry(prog, sh)))]
            else:
                s = [b.decl(f"s{i}", bind.call(prog, sh, sh.brick.entries[0].name, pre, "light", i, locals_, values))]
            body_i.append(lit_if(i, [c, *s]))
            if r.perm.lights[i].tiles:
                stmts.extend(tiled_loop(b, tiled[0], i, body_i))
            else:
                stmts.extend([loop(i, body_i)] if dyn else body_i)

        stmts.extend(ambient(prog, b, bind, r, provided))
        stmts.extend(emission(b, bind, r.surface))
        shaded = bind.call(prog, out_node, "output", "o_", "material", None, {}, args={"color": b.var("Lo", VEC3)})
        stmts.extend(surface_output(b, bind, r, shaded))
        return stmts

    # The body is built first: it decides which parameters shade() takes.
    stmts = body()
    surface = ["P", "N"] + (["T", "B"] if bg.tangent or bind.surface & {"T", "B"} else []) \
        + (["uv"] if "uv" in bind.surface else []) + (["color"] if r.surface.vertex_color else []) \
        + ([FRAG_COORD] if tiled else [])
    sig = [("P", VEC3), ("Ng", VEC3), ("V", VEC3)] + [(x, SURFACE[x]) for x in surface if x in ("T", "B", "uv")] \
        + ([(VERTEX_COLOR, VEC4)] if r.surface.vertex_color else []) + ([(FRAG_COORD, VEC2)] if tiled else [])
    material = [(f"m_{n}", k, e, ty, p) for n, k, e, ty, p in bg.params.flat
                if k not in provided or f"m_{n}" in bind.params]
    material += [(f"m_{n}", k, e, ty, p) for n, k, e, ty, p in r.packing_params.flat]
    material += [(f"o_{n}", k, e, ty, p) for n, k, e, ty, p in r.output_params.flat]
    # the surface state's names never clash with the bricks' (a verdict of spec/resolve.py, raised by link)
    material += [(f"m_{n}", n, None, sp.ty, sp) for n, sp in r.surface_params.items()]
    light_values = []
    for i, lt in enumerate(r.lights):
        light_values.append([] if lt.dynamic else [(f"l{i}_{n}", k, e, ty, p) for n, k, e, ty, p in face_params(lt).flat])
    env_values = [(f"e_{n}", k, e, ty, p) for n, k, e, ty, p in r.environment_params.flat]
    values = [(n, t) for n, _, _, t, _ in material] + [(n, t) for vals in light_values for n, _, _, t, _ in vals] \
        + [(n, t) for n, _, _, t, _ in env_values]
    missing = [n for n in bind.params if n not in dict(values)]
    assert not missing, f"shade() binds {missing}, which no brick declares"
    sig += values + [(t.name, t.ty) for t in bind.textures]

    def shade_body():
        return stmts
    prog.add(b.function("shade", sig, VEC4, shade_body))
    prog.globals.extend(dynamic_lights + tiled)
    return ShadeGlue(sig, surface, material, light_values, bind.textures, bg, dynamic_lights, buffer_slots,
                     tiled[0] if tiled else None, env_values)


IVEC4 = vector("int", 4)
VERTEX_COLOR = "vertex_color"  # shade()'s parameter: COLOR_0, interpolated (the templates' local of that name)
UV_LOCAL = "uv_t"  # shade()'s local: the texture coordinates after the packing's uv filler


def uv_transform(prog: Program, b: Builder, bind: _Binder, packing: Node,
                 args: dict[str, ir.Expr] | None = None) -> list[ir.Stmt]:
    """`uv_t = <filler>_map_uv(uv, …)` when the packing's optional slot `uv` is filled (KHR_texture_transform:
    bricks/packing/uv/), and from then on every entry reading uv, and the glue's own samples, get uv_t: one
    transform for all the material's textures. [] when the slot is empty: nothing is declared and the shader
    is the one without the slot. Called before anything that samples (shade(), a stage sampling the coverage)."""
    node = dict(packing.fillers).get("uv")
    if node is None:
        return []
    call = bind.call(prog, node, "map_uv", "m_", "material", None, {}, args)
    bind.uv = b.var(UV_LOCAL, SURFACE["uv"])
    return [b.decl(UV_LOCAL, call)]


def ambient(prog: Program, b: Builder, bind: _Binder, r: Resolved, provided: dict) -> list[ir.Stmt]:
    """`Lo += <environment>_ambient(N, V, kd, f0, alpha, …)` after the lights when the permutation has an
    environment (image-based lighting: library/kinds.py's contract), [] otherwise. f0 and alpha are the BRDF's
    parameters by name (the packing's where it provides them); kd is what the diffuse ambient term multiplies
    (spec/ambient.py DIFFUSE_HOW): rho_d (1 − f0) for Gotanda's diffuse (his footnote 4), rho_d for Lambert (the
    vertex-coloured one with COLOR_0), 0 with no diffuse term. The environment's textures bind by the contract's
    names: the radiance cube with the light set's values (set 0), the AmbientBRDF table with the material's (set 1).
    What the BRDF cannot give (a refused term, no alpha or f0) is a verdict of spec/resolve.py, raised before."""
    node = r.environment
    if node is None:
        return []
    from ..library.kinds import ENVIRONMENT_GROUP
    from ..spec.ambient import classify_nodes

    def value(name: str) -> ir.Expr:
        if name in provided:
            return b.copy(provided[name])
        ty = r.brdf_params[name].ty
        bind.params[f"m_{name}"] = ty
        return b.var(f"m_{name}", ty, "param")

    diffuse = [t.how for t in classify_nodes(r.brdf) if t.kind == "diffuse"]
    f0 = value("f0")
    if f0.ty != VEC3:
        f0 = b.construct(VEC3, f0)
    if not diffuse:
        kd = b.construct(VEC3, b.const(0.0))
    elif diffuse[0] == "gotanda_eq4":
        kd = b.arith("*", value("rho_d"), b.arith("-", b.construct(VEC3, b.const(1.0)), b.copy(f0)))
    else:
        kd = value("rho_d")
    args = {"N": b.var("N", VEC3), "V": b.var("V", VEC3, "param"), "kd": kd, "f0": f0, "alpha": value("alpha")}
    before = len(bind.textures)
    call = bind.call(prog, node, "ambient", "e_", "environment", None, {}, args)
    for t in bind.textures[before:]:  # the contract's textures: the light set's cube, the material's table
        t.group, t.environment = ENVIRONMENT_GROUP[t.param], True
    return [b.assign(b.var("Lo", VEC3), call, "+")]


def surface_inputs(b: Builder, bind: _Binder, r: Resolved, bg: BrdfGlue, provided: dict) -> list[ir.Stmt]:
    """With vertex colours (spec/surface.py): rho_d · COLOR_0.rgb, declared as `vc_rho_d` and given to the BRDF
    in place of the packing's (or the material's) rho_d. Nothing otherwise. (A BRDF without rho_d is a verdict
    of spec/resolve.py: link refuses the permutation before the glue is built.)"""
    if not r.surface.vertex_color:
        return []
    rho = b.copy(provided["rho_d"]) if "rho_d" in provided else b.var("m_rho_d", VEC3, "param")
    if "rho_d" not in provided:
        bind.params["m_rho_d"] = VEC3
    rgb = ir.Swizzle(VEC3, b.here(), b.var(VERTEX_COLOR, VEC4, "param"), "xyz")
    provided["rho_d"] = b.var("vc_rho_d", VEC3)
    return [b.decl("vc_rho_d", b.arith("*", rho, rgb))]


def coverage_texture(packing: Node) -> str:
    """The packing's texture whose A is the base colour's coverage: the sRGB 2D texture its get_rho_d samples
    (glTF's baseColorTexture: albedo_map, base_color_map), or '' when rho_d is not textured."""
    f = packing.brick.module.functions.get("get_rho_d")
    for p in (f.params if f is not None else []):
        if p.ty.kind == "texture" and p.ty.dim == "2d" and not p.ty.compare \
                and _texture_decl([packing], p.name).get("srgb"):
            return p.name
    return ""


def _sample(b: Builder, bind: _Binder, tname: str, param: str, srgb: bool) -> ir.Expr:
    """sample(t_<param>, uv) in shade(), binding the material texture if nothing bound it yet."""
    if tname not in {t.name for t in bind.textures}:
        bind.textures.append(Texture(tname, param, "material", srgb, "2d"))
    bind.surface.add("uv")
    tex = bind.b.var(tname, texture_type("2d"), "param")
    uv = b.copy(bind.uv) if bind.uv is not None else b.var("uv", SURFACE["uv"], "param")
    return b.intrinsic("sample", VEC4, tex, uv)


def emission(b: Builder, bind: _Binder, sf) -> list[ir.Stmt]:
    """Lo += m_emissive [· sample(t_emissive_map, uv).rgb] (glTF emissiveFactor · emissiveTexture)."""
    if sf.emissive == "none":
        return []
    e = b.var("m_emissive", VEC3, "param")
    if sf.emissive == "texture":
        e = b.arith("*", e, ir.Swizzle(VEC3, b.here(), _sample(b, bind, f"t_{EMISSIVE_MAP}", EMISSIVE_MAP, True), "xyz"))
    return [b.assign(b.var("Lo", VEC3), e, "+")]


def surface_output(b: Builder, bind: _Binder, r: Resolved, shaded: ir.Expr) -> list[ir.Stmt]:
    """The return of shade(): the output brick's colour, its alpha replaced by the coverage for MASK (1 kept, 0
    discarded by the template) and BLEND (the coverage itself); OPAQUE returns the output brick's value as is."""
    sf = r.surface
    if sf.alpha == "opaque":
        return [b.ret(shaded)]
    cov = coverage(b, bind, r)
    stmts = [b.decl("shaded", shaded), b.decl("coverage", cov)]
    a = coverage_alpha(b, sf)
    rgb = ir.Swizzle(VEC3, b.here(), b.var("shaded", VEC4), "xyz")
    return stmts + [b.ret(b.construct(VEC4, rgb, a))]


def coverage(b: Builder, bind: _Binder, r: Resolved) -> ir.Expr:
    """m_base_alpha [· the packing's base colour texture's A at uv] [· COLOR_0's A]: glTF's coverage, the one
    expression shade() and the mask depth stage (link/depth.py) both read."""
    cov = b.var("m_base_alpha", FLOAT, "param")
    tex = coverage_texture(r.packing)
    if tex:
        cov = b.arith("*", cov, ir.Swizzle(FLOAT, b.here(), _sample(b, bind, f"t_{tex}", tex, True), "w"))
    if r.surface.vertex_color:
        cov = b.arith("*", cov, ir.Swizzle(FLOAT, b.here(), b.var(VERTEX_COLOR, VEC4, "param"), "w"))
    return cov


def coverage_alpha(b: Builder, sf) -> ir.Expr:
    """The alpha of a declared `coverage`: itself (BLEND), or 1 where it reaches m_alpha_cutoff and 0 elsewhere
    (MASK)."""
    a = b.var("coverage", FLOAT)
    if sf.alpha == "mask":  # glTF 3.9.4: fully opaque where coverage ≥ alphaCutoff, else not drawn
        a = ir.Select(FLOAT, b.here(), b.compare(">=", a, b.var("m_alpha_cutoff", FLOAT, "param")),
                      b.const(1.0), b.const(0.0))
    return a


def has_tangent(normal: Node) -> bool:
    """Whether a normal filler defines the optional `tangent` entry (library/kinds.py)."""
    return "tangent" in normal.brick.module.functions


def shading_tangent(prog: Program, b: Builder, bind: _Binder, normal: Node, needed: bool,
                    args: dict[str, ir.Expr] | None = None) -> list[tuple[str, ir.Expr]]:
    """[("Ts", <normal>_tangent(Np = N, ...)), ("Bs", cross(N, Ts))]: the perturbed frame (T', B', N') a BRDF
    reading the tangent frame gets when the normal filler defines `tangent` (a twist map); [] otherwise, and
    the BRDF gets the interpolated T and B. B' = N' × T' as in the notes' shader (Hoffman & Baker 2006,
    "Anisotropic BRDF with Normal Map": `float3x3 inv = float3x3(T, cross(N,T), N)`)."""
    if not (needed and has_tangent(normal)):
        return []
    T = bind.call(prog, normal, "tangent", "m_", "material", None, {}, {**(args or {}), "Np": b.var("N", VEC3)})
    return [("Ts", T), ("Bs", b.intrinsic("cross", VEC3, b.var("N", VEC3), b.var("Ts", VEC3)))]


def _light_buffer(prog: Program, b: Builder, i: int, lt: LightPart, out: list,
                  slots_out: list) -> dict[str, ir.Expr]:
    """The storage buffer of dynamic light i and, per parameter, the expression reading it for element k<i>.

    The element struct LightData<i> is `vec4 data[n]`, the light's parameters packed as a
    Lights block packs them (interface.layout): the layout rule of types.buffer_layout_error, so
    GLSL std430, HLSL structured buffers and WGSL storage agree byte for byte.
    """
    params = buffer_params(lt)  # a shadowed pair's face matrices and first layer too (link/faces.py)
    _untextured(lt, shadow=True)
    slots, n = layout([(k, k, None, p.ty, p, i) for k, p in params.items()])
    data_ty = array(VEC4, max(n, 1))
    elem = struct(f"LightData{i}", (("data", data_ty),))
    g = ir.Global(f"light_buffer{i}", storage_buffer(elem))
    prog.structs.append(elem)
    out.append(g)
    slots_out.append(slots)
    item = ir.Index(elem, b.here(), ir.Var(g.ty, b.here(), g.name, "global"), ir.Var(UINT, b.here(), f"k{i}"))
    return {s.name: read_slot(b, item, data_ty, s) for s in slots}


def _untextured(lt: LightPart, shadow: bool = False) -> None:
    """Refuse a buffer light whose brick or (unless `shadow`: a loop that reads a pair's shadow array) shadow filter
    binds a texture (a located error at the brick)."""
    owners = [(n.brick, x) for n in [lt.node, *([] if shadow else lt.shadow.tree)] for x in n.brick.textures]
    if owners:
        brick, tex = owners[0]
        loc = brick.module.meta_loc
        raise SourceError(brick.display_path, loc.line, loc.col, f"a loop over a buffer of '{lt.brick.id}' lights cannot "
                          f"bind texture '{tex}' of {brick.kind} '{brick.id}' per light",
                          "use a shadow filter without a texture (shadow none) for buffer lights")


SWITCH_IDS = VEC4_BYTES  # a switch buffer's element: ids (ivec4, ids.x the light index), then data at this offset


def _switch_buffer(prog: Program, b: Builder, j: int, pairs: list, out: list,
                   slots_out: list) -> tuple[ir.Expr, dict[int, dict[str, ir.Expr]]]:
    """The one storage buffer of a switch loop (named for its first light j) and, per light index i of `pairs`,
    the expressions reading its parameters from element k<j>.

    The element LightData<j> is the ubershader's LightEntry: `ivec4 ids` (ids.x: the light index, the switch's
    case) then `vec4 data[K]`, each pair's parameters packed from data[0] as interface.layout packs them, K the
    most any pair needs. Its slots (slots_out) are the pairs' slots together, each with its light index, at byte
    offsets in the element (after the ids)."""
    laid = []
    for i, lt in pairs:
        _untextured(lt)
        laid.append((i, *layout([(k, k, None, p.ty, p, i) for k, p in lt.params.items()])))
    data_ty = array(VEC4, max([1] + [n for _, _, n in laid]))
    elem = struct(f"LightData{j}", (("ids", IVEC4), ("data", data_ty)))
    g = ir.Global(f"light_buffer{j}", storage_buffer(elem))
    prog.structs.append(elem)
    out.append(g)
    slots_out.append([dataclasses.replace(x, base=SWITCH_IDS) for _, slots, _ in laid for x in slots])
    entry = ir.Index(elem, b.here(), ir.Var(g.ty, b.here(), g.name, "global"), ir.Var(UINT, b.here(), f"k{j}"))
    le = b.var(f"le{j}", elem)
    return entry, {i: {x.name: read_slot(b, le, data_ty, x) for x in slots} for i, slots, _ in laid}


def read_slot(b: Builder, entry: ir.Expr, data_ty: Type, slot: Slot) -> ir.Expr:
    """The value of `slot` in entry.data, a vec4 array: its components of vec4 slot.index (a mat4 spans four)."""
    def vec4(i):
        return ir.Index(VEC4, b.here(), ir.Member(data_ty, b.here(), b.copy(entry), "data"), ir.Const(INT, b.here(), i))
    if slot.ty == MAT4:
        return b.construct(MAT4, *(vec4(slot.index + c) for c in range(4)))
    if slot.ty.components == 4:
        return vec4(slot.index)
    return ir.Swizzle(slot.ty, b.here(), vec4(slot.index), slot.swizzle[1:])


def bind_texture(bind: _Binder, name: str, ty: Type, nodes) -> ir.Var:
    """A BRDF texture in shade(): a material texture t_<name>."""
    tname = f"t_{name}"
    if tname not in {t.name for t in bind.textures}:
        decl = _texture_decl(nodes, name)
        bind.textures.append(Texture(tname, name, "material", bool(decl.get("srgb")), ty.dim, compare=ty.compare))
    return bind.b.var(tname, ty, "param")


# ------------------------------------------------------------------ several BRDFs in one program


def switch_params(glues: list[BrdfGlue]) -> Params:
    """The parameters of a switch: BRDF k's parameter `name` is `b<k>_<name>`, so each BRDF keeps
    its own values, type, range and default (unrelated BRDFs may share a name)."""
    out = {}
    for k, g in enumerate(glues):
        for name, spec in g.params.items():
            out[f"b{k}_{name}"] = dataclasses.replace(spec, name=f"b{k}_{name}")
    return Params(out)


def switch_textures(glues: list[BrdfGlue]) -> list[tuple[str, Type, dict]]:
    """The textures of a switch, each once (a texture name is one table in every BRDF that samples it)."""
    out = []
    for g in glues:
        for tex in g.textures:
            if tex[0] not in {x[0] for x in out}:
                out.append(tex)
    return out


def brdf_switch(prog: Program, brdfs: list[ResolvedBrdf],
                b: Builder | None = None) -> tuple[ir.Function, list[BrdfGlue]]:
    """`brdf_switch(id: int, L, V, N[, T, B], b0_params..., b1_params..., textures...) -> vec3`.

    id k evaluates brdf_<k> with its own parameters (switch_params); another id gives 0.
    """
    b = b or Builder()
    glues = [brdf_glue(prog, rb.nodes, rb.params, suffix=f"_{k}", b=b) for k, rb in enumerate(brdfs)]
    tangent = any(g.tangent for g in glues)
    frame = [(n, BY_NAME[n].ty) for n in FRAME + (TANGENT_FRAME if tangent else ())]
    textures = switch_textures(glues)
    sig = [("id", INT)] + frame + [(n, ty) for n, _, _, ty, _ in switch_params(glues).flat] \
        + [(n, ty) for n, ty, _ in textures]
    env = dict(sig)

    def body():
        cases = []
        for k, g in enumerate(glues):
            own = {n for n, _, _, _, _ in g.params.flat}
            args = [b.var(f"b{k}_{n}" if n in own else n, env[f"b{k}_{n}" if n in own else n])
                    for n, _ in g.signature]
            cases.append(((k,), [b.ret(b.call(g.guarded, args))]))
        return [ir.Switch(b.loc(), b.var("id", INT), cases, [b.ret(b.construct(VEC3, b.const(0.0)))])]
    f = prog.add(b.function("brdf_switch", sig, VEC3, body))
    return f, glues


__all__ = ["BrdfGlue", "ShadeGlue", "brdf_glue", "shade_glue", "brdf_switch", "switch_params", "switch_textures"]
