"""resolve(permutation, library): everything a permutation key means, computed once, frozen.

The spec stage's hand-off. Link (the glue, the layout, the ubershader), compose, eval, measure,
the scene loader and the build read its fields; nothing downstream parses a spec string again
or applies the parameter policy again (spec/params.py runs once per permutation, here). The
value is kept in the library's memo per key and origin, and made again when a brick it names was
replaced in the library since.

Errors name the position of the part of the key that is wrong (spec/where.py): the scene key
that asked for it, a spec string's column, or the key's own text.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

from ..library.bricks import Brick, Library
from ..library.inputs import BY_NAME, SHADING
from .constraints import CONSTRAINTS, supplies_tangent
from .ambient import ambient_problem
from .params import Frozen, Params, group, spec_params
from .permutation import Node, Permutation, parse_brdf, parse_spec
from .surface import Surface
from .where import KeyProblem, Origin, Where, within


@dataclass(frozen=True)
class LightPart:
    """One light of a permutation: its brick, its shadow filter, and their parameters."""

    brick: Brick
    node: Node  # the light brick as a node (no fillers)
    shadow: Node
    dynamic: bool  # a loop over a storage buffer of such lights
    params: Params  # light and shadow filter as one group: the light's values (l<i>_*)
    light_params: Params  # the light brick's alone
    shadow_params: Params  # the shadow filter's alone
    textures: tuple[str, ...]  # the textures the shadow filter samples


@dataclass(frozen=True)
class ResolvedBrdf:
    """A BRDF spec alone (eval kernels, accuracy, references, cost plans): its nodes and parameters."""

    text: str  # as given
    key: str  # canonical
    nodes: tuple[Node, ...]  # diffuse first
    params: Params
    tangent: tuple[str, ...]  # the tangent-frame rows (T, B, HdotT, …) its bricks read
    inputs: tuple[str, ...]  # the shading inputs its bricks' entries read, in the inputs table's order
    where: Where | None = None  # the scene key that asked for it; None: a spec string (Node.col locates)


@dataclass(frozen=True)
class Resolved:
    """A permutation key, resolved: its bricks, parameter groups, needs and verdict."""

    perm: Permutation
    key: str  # the canonical key
    hash: str  # its 12 hex digits (file names, cache keys)
    brdf: tuple[Node, ...]
    brdf_key: str
    packing: Node
    normal: Node  # the packing's normal filler
    lights: tuple[LightPart, ...]
    output: Brick
    output_node: Node
    surface: Surface
    brdf_params: Params  # the BRDF's own: the material values the BRDF reads (m_*)
    packing_params: Params  # the packing's beyond the BRDF's (m_*)
    output_params: Params  # the output brick's (o_*)
    material_params: Params  # BRDF, packing and output as one group: what a material may set, with the
    #                          surface state's (surface_params) beside it
    surface_params: Params  # what the surface state reads (base_alpha, alpha_cutoff, emissive)
    textures: dict  # texture name -> declaration, over the BRDF's, packing's and output's bricks (first wins)
    tangent: tuple[str, ...]  # the tangent-frame rows the BRDF reads
    packing_tangent: bool  # the packing's bricks read the vertex tangent
    inputs: tuple[str, ...]  # the shading inputs the BRDF's bricks read
    # (part, what is wrong, what to do) per rule the permutation breaks: the packing constraints
    # (spec/constraints.py) under part "packing", the surface state's under its key; () when it may exist
    problems: tuple[tuple[str, str, str], ...]
    origin: Origin | None  # where it was asked for (Permutation.origin)
    # the environment brick (image-based lighting after the lights: Permutation.environment) and its parameters,
    # the light set's values (e_*: the Lights block's last group); None and empty without one
    environment: Node | None = None
    environment_params: Params = field(default_factory=Params)


def _walk(*tops: Node):
    return [x for top in tops for x in top.tree]


def _fresh(bricks, lib: Library) -> bool:
    """Whether every brick a resolved value holds is still the library's (a test or a tool may replace one)."""
    return all(lib.bricks.get((b.kind, b.id)) is b for b in bricks)


def _inputs(nodes) -> tuple[str, ...]:
    names = {p.name for x in _walk(*nodes) for f in x.brick.entries for p in f.params if p.name in SHADING}
    return tuple(sorted(names, key=list(BY_NAME).index))


def _tangent(nodes) -> tuple[str, ...]:
    return tuple(sorted(n for n in _inputs(nodes) if BY_NAME[n].tangent))


def resolve_brdf(spec: str, lib: Library, where: Where | None = None) -> ResolvedBrdf:
    """A BRDF spec resolved (SpecError for a bad spec string; the policy's errors at the brick that breaks it)."""
    key = ("resolved_brdf", spec, where)
    hit = lib.memo.get(key)
    if hit is not None and _fresh([x.brick for x in _walk(*hit.nodes)], lib):
        return hit
    nodes = tuple(parse_brdf(spec, lib))
    policy = spec_params(nodes)
    canon = "+".join(n.key for n in nodes)
    r = lib.memo[key] = ResolvedBrdf(spec, canon, nodes, policy.brdf, _tangent(nodes), _inputs(nodes), where)
    return r


def light_params(lib: Library, light: str, shadow: str) -> Params:
    """The parameters of one light brick with a shadow filter spec (a scene's light, the renderer's values)."""
    key = ("light_params", light, shadow)
    hit = lib.memo.get(key)
    if hit is not None and _fresh(hit[1], lib):
        return hit[0]
    lb = lib.get("light", light)
    if lb is None:
        raise KeyProblem("light0", f"unknown light brick '{light}'",
                         f"known: {', '.join(b.id for b in lib.of_kind('light'))}")
    sh = parse_spec(shadow, lib, ("shadow",))[0]
    params = spec_params(lights=[(Node(lb, ()), sh)]).lights[0].params
    lib.memo[key] = (params, [lb, *(x.brick for x in sh.tree)])
    return params


def resolve(perm: Permutation, lib: Library) -> Resolved:
    """Everything `perm` means (module docstring); errors are located at the part of the key that is wrong.

    The value depends on the key alone: where it was asked for (its origin) only locates errors. So a key
    resolved once, from anywhere, is the same value for another origin (its perm and origin swapped in), and a
    scene's 10,000 materials and the matrix report's every BRDF × packing pair each resolve once."""
    key = ("resolved", perm, perm.origin)
    hit = lib.memo.get(key)
    if hit is not None and _fresh(_bricks(hit), lib):
        return hit
    same = lib.memo.get(("resolved", perm, None))
    if same is not None and _fresh(_bricks(same), lib):
        r = lib.memo[key] = replace(same, perm=perm, origin=perm.origin)
        return r
    with within(perm.origin, perm.canonical()):
        r = lib.memo[key] = _resolve(perm, lib)
    if perm.origin is not None:
        lib.memo[("resolved", perm, None)] = replace(r, perm=replace(perm, origin=None), origin=None)
    return r


def _bricks(r: Resolved) -> list[Brick]:
    return [x.brick for x in _walk(*r.brdf, r.packing, *(lt.shadow for lt in r.lights))] \
        + [lt.brick for lt in r.lights] + [r.output] + ([r.environment.brick] if r.environment is not None else [])


def _kept(lib: Library, what: str, nodes, make):
    """make(), kept in the library's memo per these very Node objects (as params._cached: the entry holds them,
    and parse_spec makes new ones when a brick is replaced)."""
    key = (what, *map(id, nodes))
    hit = lib.memo.get(key)
    if hit is not None:
        return hit[1]
    value = make()
    lib.memo[key] = (tuple(nodes), value)
    return value


def _node(lib: Library, brick: Brick) -> Node:
    """The Node of a brick without fillers (a light, an output), one per brick: what _kept and the parameter
    memo key on."""
    key = ("node", brick.kind, brick.id)
    hit = lib.memo.get(key)
    if hit is not None and hit.brick is brick:
        return hit
    node = lib.memo[key] = Node(brick, ())
    return node


def _resolve(perm: Permutation, lib: Library) -> Resolved:
    brdf = tuple(parse_brdf(perm.brdf, lib))
    packings = parse_spec(perm.packing, lib, ("packing",))
    if len(packings) != 1:
        raise KeyProblem("packing", f"packing '{perm.packing}' names more than one brick", "name one packing")
    packing = packings[0]
    pairs = []
    for i, lk in enumerate(perm.lights):
        lb = lib.get("light", lk.light)
        if lb is None:
            raise KeyProblem(f"light{i}", f"unknown light brick '{lk.light}'",
                             f"known: {', '.join(b.id for b in lib.of_kind('light'))}")
        pairs.append((lb, _node(lib, lb), parse_spec(lk.shadow, lib, ("shadow",))[0]))
    out = lib.get("output", perm.output)
    if out is None:
        raise KeyProblem("output", f"unknown output brick '{perm.output}'",
                         f"known: {', '.join(b.id for b in lib.of_kind('output'))}")
    out_node = _node(lib, out)
    env_node, env_params = None, Params()
    if perm.environment:
        eb = lib.get("environment", perm.environment)
        if eb is None:
            raise KeyProblem("environment", f"unknown environment brick '{perm.environment}'",
                             f"known: {', '.join(b.id for b in lib.of_kind('environment')) or 'none'}")
        env_node = _node(lib, eb)
        env_params = group([env_node], lib.memo)
    policy = spec_params(brdf, packing, out_node, [(ln, sh) for _, ln, sh in pairs], memo=lib.memo)
    lights = tuple(LightPart(lb, ln, sh, lk.dynamic, lp.params, lp.light, lp.shadow,
                             tuple(t for x in sh.tree for t in x.brick.textures))
                   for (lb, ln, sh), lk, lp in zip(pairs, perm.lights, policy.lights))
    textures: dict = {}
    for top in (*brdf, packing, out_node):
        for name, d in top.textures.items():
            textures.setdefault(name, d)
    # what the BRDF reads and whether the packing supplies a tangent: the same for every permutation sharing them
    tangent, inputs = _kept(lib, "brdf_inputs", brdf, lambda: (_tangent(brdf), _inputs(brdf)))
    frame = _kept(lib, "packing_tangent", (packing,), lambda: supplies_tangent(packing))
    key = perm.canonical()
    r = Resolved(perm, key, perm.hash, brdf, "+".join(n.key for n in brdf), packing, dict(packing.fillers)["normal"],
                 lights, out, out_node, perm.surface, policy.brdf, policy.packing, policy.output, policy.material,
                 Params(perm.surface.params()), Frozen(textures), tangent, frame, inputs, (), perm.origin,
                 env_node, env_params)
    # the verdict reads the value it belongs to: set before the value leaves here (a second dataclass made by
    # replace() cost as much as the rest of a resolve that the memos serve)
    object.__setattr__(r, "problems", tuple(_problems(r)))
    return r


def _problems(r: Resolved):
    for c in CONSTRAINTS:
        what, todo = c.problem(r)
        if what:
            yield "packing", what, todo
    sf = r.surface
    if sf.vertex_color and "rho_d" not in r.brdf_params:
        yield ("vertex_color", "vertex_color multiplies rho_d, and this BRDF has no rho_d",
               "use a BRDF with a diffuse term (lambert, …) or drop vertex_color")
    if r.environment is not None:  # what the environment's glue binds of the BRDF (spec/ambient.py)
        what, todo = ambient_problem(r.brdf, r.brdf_params)
        if what:
            yield "brdf", what, todo
    clash = [k for k in r.surface_params if k in r.material_params]
    if clash:
        yield ("alpha" if clash[0] != "emissive" else "emissive", f"the surface state's parameter '{clash[0]}' is "
               "also a parameter of the material's bricks", "rename the brick's parameter")


def check_packing(r: Resolved) -> tuple[str, str]:
    """('', '') when the packing fits the BRDF, else (what is wrong, what to do): the first rule of
    spec/constraints.py the permutation breaks."""
    return next(((what, todo) for part, what, todo in r.problems if part == "packing"), ("", ""))


def fp16_warnings(perms, lib: Library) -> list[str]:
    """One line per brick whose metadata says "fp16": "unsafe: why" and that fp16 permutations use, with how many
    (`build` prints them as warnings; the permutations still build)."""
    users: dict[tuple, list[str]] = {}
    why: dict[tuple, tuple[str, str]] = {}
    for perm in perms:
        if perm.precision != "fp16":
            continue
        r = resolve(perm, lib)
        nodes = _walk(*r.brdf, r.packing, *(lt.shadow for lt in r.lights))
        for b in [n.brick for n in nodes] + [lt.brick for lt in r.lights] + [r.output]:
            if b.fp16_unsafe:
                key = (b.kind, b.id)
                why[key] = (b.fp16_unsafe, b.display_path)
                if r.hash not in users.setdefault(key, []):
                    users[key].append(r.hash)
    return [f"{len(hs)} fp16 permutation(s) ({', '.join(hs[:3])}{', …' if len(hs) > 3 else ''}) use {kind} brick "
            f"'{bid}', unsafe in fp16: {why[(kind, bid)][0]} ({why[(kind, bid)][1]})"
            for (kind, bid), hs in users.items()]
