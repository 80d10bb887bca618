"""Spec strings and permutation keys: one canonical string and a short stable hash.

A spec names bricks and their slot fillers:
    lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)
    albedo_texture(normal=normal_map)
Canonical form: every slot written out (defaults included) in the brick's
declared slot order, no spaces; an optional slot (no default) only when filled.
The hash of the canonical key names files; raw strings from users never do.
"""
from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass, field

from ..library.bricks import Brick, Library
from ..library.kinds import BRDF_KINDS
from ..lang.errors import UserError
from .params import Frozen
from .surface import DEFAULT as DEFAULT_SURFACE, Surface
from .where import Origin

_TOKEN = re.compile(r"\s*([A-Za-z][A-Za-z0-9_]*|[0-9]+|[()+=,])")
PRECISIONS = ("fp32", "fp16")  # fp16: the BRDF and glue arithmetic in half (backends/*/emit.py, *Half*), the interface 32-bit


class SpecError(UserError, ValueError):
    """A bad spec string; `col` is the 1-based column inside the spec."""

    def __init__(self, spec: str, col: int, message: str, hint: str = ""):
        self.spec, self.col, self.message, self.hint = spec, col, message, hint
        super().__init__(f"{message} in '{spec}' at column {col}" + (f" — {hint}" if hint else ""))


@dataclass(frozen=True)
class Node:
    """One brick of a spec with its slot fillers (resolved).

    `key` (the canonical text), `tree` (this node and every filler below it, callers first) and `textures`
    (each texture name the tree's bricks declare, first declaration first) are computed once, when the node
    is made: the link stage reads them for every function it names and every texture it binds."""

    brick: Brick
    fillers: tuple  # ((slot, Node), ...) in the brick's slot order
    counts: tuple = ()  # ((array parameter, element count), ...) in the brick's parameter order
    col: int = field(default=0, compare=False)  # the column of the brick's id in the spec string (0: a default)
    key: str = field(init=False, compare=False, repr=False)
    tree: tuple = field(init=False, compare=False, repr=False)
    textures: dict = field(init=False, compare=False, repr=False)

    def __post_init__(self):
        parts = [f"{s}={n.key}" for s, n in self.fillers] + [f"{p}={c}" for p, c in self.counts]
        object.__setattr__(self, "key", f"{self.brick.id}({','.join(parts)})" if parts else self.brick.id)
        object.__setattr__(self, "tree", (self, *(x for _, n in self.fillers for x in n.tree)))
        decls: dict = {}
        for x in self.tree:
            for name, d in x.brick.textures.items():
                decls.setdefault(name, d)
        object.__setattr__(self, "textures", Frozen(decls))

    def canonical(self) -> str:
        return self.key

    def count(self, param: str) -> int | None:
        return dict(self.counts).get(param)

    def walk(self):
        """This node and every filler below it, callers first."""
        return iter(self.tree)


def _tokens(spec: str):
    pos, out = 0, []
    while pos < len(spec):
        if spec[pos:].strip() == "":
            break
        m = _TOKEN.match(spec, pos)
        if not m:
            raise SpecError(spec, pos + 1, f"unexpected character {spec[pos]!r}",
                            "a spec is brick ids joined by '+', with slot fillers in parentheses: a+b(slot=c)")
        out.append((m.group(1), m.start(1) + 1))
        pos = m.end()
    out.append(("", len(spec) + 1))
    return out


def parse_spec(spec: str, lib: Library, kinds) -> list[Node]:
    """Parse and resolve a '+'-joined spec whose top-level bricks have one of `kinds`.

    Kept in the library's memo per spec string: a scene of 10,000 materials names a few hundred specs, and a
    permutation's BRDF and packing are parsed again wherever it is resolved. A hit is used only while every brick
    of its nodes is still the library's and no brick was added or removed since (either may change what a name
    resolves to); a spec that does not parse is not kept, so its error is raised again, from its own text."""
    key = ("spec", spec, tuple(kinds), len(lib.bricks))
    hit = lib.memo.get(key)
    if hit is not None and all(lib.bricks.get((x.brick.kind, x.brick.id)) is x.brick for n in hit for x in n.tree):
        return list(hit)
    nodes = _parse_spec(spec, lib, kinds)
    lib.memo[key] = tuple(nodes)
    return nodes


def _parse_spec(spec: str, lib: Library, kinds) -> list[Node]:
    toks = _tokens(spec)
    i = 0

    def term(kinds_here):
        nonlocal i
        name, col = toks[i]
        if not name or not (name[0].isalpha()):
            raise SpecError(spec, col, "expected a brick id" + (f", got {name!r}" if name else ""),
                            "list bricks with `shadermatrix bricks`")
        i += 1
        found = lib.find(name, kinds_here)
        if not found:
            known = sorted({b.id for k in kinds_here for b in lib.of_kind(k)})
            raise SpecError(spec, col, f"unknown {'/'.join(kinds_here)} brick '{name}'",
                            f"known: {', '.join(known)}")
        brick = found[0]
        given: dict[str, Node] = {}
        counts: dict[str, int] = {}
        arrays = {k: p.ty.size for k, p in brick.params.items() if p.ty.kind == "array"}
        if toks[i][0] == "(":
            i += 1
            while True:
                sname, scol = toks[i]
                if sname not in brick.slots and sname not in arrays:
                    if not arrays:
                        slots = ", ".join(brick.slots) or "none"
                        raise SpecError(spec, scol, f"'{brick.id}' has no slot {sname!r}", f"its slots: {slots}")
                    slots = ", ".join(list(brick.slots) + [f"{a}=1..{n}" for a, n in arrays.items()])
                    raise SpecError(spec, scol, f"'{brick.id}' has no slot or array parameter {sname!r}",
                                    f"its slots and counts: {slots}")
                if sname in given:
                    raise SpecError(spec, scol, f"slot '{sname}' is filled twice", "fill each slot once")
                if sname in counts:
                    raise SpecError(spec, scol, f"count '{sname}' is given twice", "give each count once")
                i += 1
                if toks[i][0] != "=":
                    raise SpecError(spec, toks[i][1], "expected '='", "write slot=filler")
                i += 1
                if sname in arrays:
                    num, ncol = toks[i]
                    if not num.isdigit() or not 1 <= int(num) <= arrays[sname]:
                        raise SpecError(spec, ncol, f"'{sname}' takes a count from 1 to {arrays[sname]}",
                                        f"write {sname}=1 … {sname}={arrays[sname]}")
                    counts[sname] = int(num)
                    i += 1
                else:
                    given[sname] = term((brick.slots[sname]["kind"],))
                if toks[i][0] == ",":
                    i += 1
                    continue
                if toks[i][0] == ")":
                    i += 1
                    break
                raise SpecError(spec, toks[i][1], "expected ',' or ')'", "close the slot list")
        fillers = []
        for sname, s in brick.slots.items():
            node = given.get(sname)
            if node is None and s.get("optional"):
                continue  # an optional slot left empty: no filler, nothing in the key
            if node is None:
                dflt = lib.get(s["kind"], s["default"])
                if dflt is None:
                    raise SpecError(spec, col, f"default filler '{s['default']}' of slot '{sname}' is missing",
                                    f"fill the slot explicitly: {brick.id}({sname}=...)")
                node = Node(dflt, _default_fillers(dflt, lib, spec, col), _default_counts(dflt))
            fillers.append((sname, node))
        return Node(brick, tuple(fillers), tuple((a, counts.get(a, n)) for a, n in arrays.items()), col)

    nodes = [term(kinds)]
    while toks[i][0] == "+":
        i += 1
        nodes.append(term(kinds))
    if toks[i][0]:
        raise SpecError(spec, toks[i][1], f"unexpected {toks[i][0]!r}", "join bricks with '+'")
    return nodes


def _default_fillers(brick: Brick, lib: Library, spec: str, col: int, chain: tuple = ()) -> tuple:
    chain = (*chain, (brick.kind, brick.id))
    out = []
    for sname, s in brick.slots.items():
        if s.get("optional"):
            continue
        d = lib.get(s["kind"], s["default"])
        if d is None:
            raise SpecError(spec, col, f"default filler '{s['default']}' of slot '{sname}' is missing", "")
        if (d.kind, d.id) in chain:  # a slot default naming a brick it is inside: it would never end
            cycle = " → ".join(f"{k} '{i}'" for k, i in (*chain, (d.kind, d.id)))
            raise SpecError(spec, col, f"the slot defaults form a cycle: {cycle}",
                            f"change the default of slot '{sname}' in {brick.display_path}")
        out.append((sname, Node(d, _default_fillers(d, lib, spec, col, chain), _default_counts(d))))
    return tuple(out)


def _default_counts(brick: Brick) -> tuple:
    """Every array parameter at its full capacity."""
    return tuple((k, p.ty.size) for k, p in brick.params.items() if p.ty.kind == "array")


def parse_brdf(spec: str, lib: Library) -> list[Node]:
    """A BRDF spec: one diffuse and/or one specular term, diffuse first in canonical form."""
    nodes = parse_spec(spec, lib, BRDF_KINDS)
    kinds = [n.brick.kind for n in nodes]
    if len(set(kinds)) != len(kinds):
        raise SpecError(spec, 1, "a BRDF has at most one diffuse and one specular term",
                        "write diffuse+specular, e.g. lambert+blinn_phong_normalized")
    return sorted(nodes, key=lambda n: BRDF_KINDS.index(n.brick.kind))


def canonical(nodes: list[Node]) -> str:
    return "+".join(n.canonical() for n in nodes)


@dataclass(frozen=True)
class LightKey:
    """One light of a permutation, or (dynamic) any number of lights of one type read from a storage buffer."""

    light: str  # light brick id
    shadow: str  # canonical shadow spec
    dynamic: bool = False  # a loop over a storage buffer of lights with a runtime count
    switch: bool = False  # (dynamic) read by the key's one loop over one buffer, switching on the pair (`**`)
    tiles: bool = False  # (dynamic) the loop reads the fragment's screen tile's index list (`*point/none@tiles`)

    def canonical(self) -> str:
        tail = "@tiles" if self.tiles else ""  # absent: the key's text unchanged
        return f"{'**' if self.switch else '*' if self.dynamic else ''}{self.light}/{self.shadow}{tail}"


@dataclass(frozen=True)
class Permutation:
    """A permutation key: what one specialized shader implements."""

    brdf: str  # canonical BRDF spec
    lights: tuple  # (LightKey, ...) in order
    packing: str  # canonical packing spec
    output: str = "linear"
    precision: str = "fp32"
    surface: Surface = DEFAULT_SURFACE  # alpha mode, double-sided, vertex colours, emission (spec/surface.py)
    # where it was asked for (spec/where.py): not part of the key, so equal keys from two places are one permutation
    origin: Origin | None = field(default=None, compare=False, repr=False)
    # the environment brick that adds image-based lighting after the lights ("": none; the key's text unchanged)
    environment: str = ""

    def canonical(self) -> str:
        """The key as text; the surface state at its defaults writes nothing (earlier keys and hashes unchanged).
        Made once per value (a key is read by every stage; the matrix report makes 100,000 of them)."""
        text = self.__dict__.get("_canonical")
        if text is None:
            lights = ",".join(k.canonical() for k in self.lights) or "-"
            env = f";environment={self.environment}" if self.environment else ""  # absent: the key unchanged
            text = (f"brdf={self.brdf};lights={lights};packing={self.packing};"
                    f"output={self.output};precision={self.precision}{self.surface.canonical()}{env}")
            object.__setattr__(self, "_canonical", text)  # frozen: the text is derived, not a field
        return text

    @property
    def hash(self) -> str:
        """12 hex digits of the SHA-256 of the canonical key (file names, cache keys)."""
        return hashlib.sha256(self.canonical().encode()).hexdigest()[:12]

