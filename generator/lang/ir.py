"""Typed intermediate representation of brick functions.

Every node carries its source location; every expression carries its type.
Emitters (generator/backends/) walk these nodes; nothing else reads brick text.

Every node is a plain dataclass, so glue (the link stage) builds IR directly,
without brick text. The rules the checker enforces on parsed bricks hold for
built IR too; the emitters assume them:

- Arrays (`types.array(elem, n)`): read with Index(elem, base, i) (i int or uint),
  written with Assign(target=Index(...)); an array value is built only as
  Decl(value=Construct(array_type, [n elements])) (HLSL has no array expression),
  and functions never return arrays.
- Buffers (`types.storage_buffer(struct)`, `types.uniform_buffer(struct, n)`) are
  global resources: declared by a Global (or a template calling the target's
  declare_buffer), referenced as Var(buffer_type, loc, name, "global") and only as
  the base of an Index (the element, a struct) or the argument of
  Intrinsic(UINT, loc, "buffer_length", [var]). They are never written, passed or
  stored.
- Textures (`TEXTURE2D`, `TEXTURECUBE`, `TEXTURE2D_SHADOW`) are parameters or globals, passed by name.
- Switch selectors are int or uint; case values are distinct ints in the
  selector's range; a case never falls through.
- A runtime For bound is an int or uint expression that the body does not change
  (the shading languages re-evaluate it before every iteration).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .types import INT, Type


@dataclass(frozen=True)
class Loc:
    path: str
    line: int
    col: int

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.col}"


# ---------------------------------------------------------------- expressions

@dataclass
class Expr:
    ty: Type
    loc: Loc


@dataclass
class Const(Expr):
    value: Any  # float, int or bool


@dataclass
class Var(Expr):
    """A local, a parameter, a named constant (PI) or a global resource."""

    name: str
    scope: str = "local"  # "local" | "param" | "const" | "global"


@dataclass
class Unary(Expr):
    op: str  # "-" | "not"
    operand: Expr


@dataclass
class Binary(Expr):
    """Arithmetic (+ - * / %), comparison (< <= > >= == !=), logic (and or).

    Mixed scalar/vector and matrix/vector operands are allowed where every
    target allows them; the checker has already rejected everything else.
    """

    op: str
    lhs: Expr
    rhs: Expr


@dataclass
class Call(Expr):
    """A call to a brick function (by its linked name)."""

    func: str
    args: list[Expr]


@dataclass
class Intrinsic(Expr):
    """A call to an entry of the intrinsics table (generator/lang/intrinsics.py)."""

    name: str
    args: list[Expr]


@dataclass
class Construct(Expr):
    """vec3(x, y, z), vec3(s) splat, mat3(c0, c1, c2) columns, float(i), Struct(a, b)."""

    args: list[Expr]


@dataclass
class Swizzle(Expr):
    base: Expr
    components: str  # over "xyzw"


@dataclass
class Member(Expr):
    base: Expr
    field: str


@dataclass
class Index(Expr):
    base: Expr
    index: Expr


@dataclass
class Select(Expr):
    """`a if cond else b`; emitted as ?: or WGSL select()."""

    cond: Expr
    if_true: Expr
    if_false: Expr


# ---------------------------------------------------------------- statements

@dataclass
class Stmt:
    loc: Loc


@dataclass
class Decl(Stmt):
    """First assignment of a local: declares it in the enclosing block."""

    name: str
    ty: Type
    value: Expr


@dataclass
class Assign(Stmt):
    target: Expr  # Var, single-component Swizzle, Member, or Index
    op: str | None  # None for =, "+" for +=, ...
    value: Expr


@dataclass
class If(Stmt):
    cond: Expr
    then: list[Stmt]
    orelse: list[Stmt]


@dataclass
class For(Stmt):
    """for var in range(count) with a compile-time int constant count, or
    for var in range(bound) with a runtime int/uint expression (then `count` is unused, 0).

    The loop variable is int, or uint when the bound is uint (`var_type`). A runtime
    bound is read before every iteration in GLSL/HLSL/WGSL: the body must not
    assign anything it reads (the checker enforces this for bricks).
    """

    var: str
    count: int
    body: list[Stmt]
    bound: Expr | None = None

    @property
    def var_type(self) -> Type:
        return self.bound.ty if self.bound is not None and self.bound.ty.scalar == "uint" else INT


@dataclass
class Switch(Stmt):
    """match selector: case v0 | v1: ... case _: ... (`match` in bricks; `switch` in the targets).

    selector: an int or uint expression. cases: [((v, ...), body), ...] with every
    value a Python int, distinct across the switch and in the selector's range.
    default: the body of `case _` ([] when there is none). No fallthrough: a
    body that does not return ends with `break;` in GLSL/HLSL.
    """

    selector: Expr
    cases: list[tuple[tuple[int, ...], list[Stmt]]]
    default: list[Stmt] = field(default_factory=list)


@dataclass
class Return(Stmt):
    value: Expr | None


# ---------------------------------------------------------------- top level

@dataclass
class Param:
    name: str
    ty: Type
    loc: Loc
    assigned: bool = False  # the body assigns it (WGSL parameters are immutable)


@dataclass
class Function:
    name: str
    params: list[Param]
    ret: Type
    body: list[Stmt]
    loc: Loc
    doc: str = ""
    calls: list[str] = field(default_factory=list)  # brick functions it calls, in order

    def signature(self) -> str:
        args = ", ".join(f"{p.name}: {p.ty}" for p in self.params)
        return f"{self.name}({args}) -> {self.ret}"


@dataclass
class Global:
    """A global resource declaration: a buffer or texture that functions read as Var(..., "global").

    ty: a buffer type (types.storage_buffer / uniform_buffer), a texture type, or int/uint: a
    specialization constant whose SpecId is `binding` (set unused).
    set, binding: its descriptor set and binding (a texture takes B and B+1 for its
    sampler). Emitters declare it with Target.declare_global(g) between the
    structs and the functions (Target.emit(..., globals=[...])). Bricks declare
    buffers at top level (`lights: storage_buffer[Light]`) with set = binding = -1:
    the link stage assigns the real ones.
    """

    name: str
    ty: Type
    set: int = -1
    binding: int = -1
    loc: Loc | None = None


@dataclass
class Module:
    """One parsed brick file."""

    path: str
    doc: str
    meta: dict
    meta_loc: Loc
    structs: dict[str, Type]
    constants: dict[str, Const]
    functions: dict[str, Function]
    source_hash: str
    globals: dict[str, Global] = field(default_factory=dict)  # top-level buffer declarations


# ---------------------------------------------------------------- traversal

def children(node) -> list:
    """Direct sub-nodes of an expression or statement (for generic walks)."""
    if isinstance(node, (Unary,)):
        return [node.operand]
    if isinstance(node, Binary):
        return [node.lhs, node.rhs]
    if isinstance(node, (Call, Intrinsic, Construct)):
        return list(node.args)
    if isinstance(node, (Swizzle, Member)):
        return [node.base]
    if isinstance(node, Index):
        return [node.base, node.index]
    if isinstance(node, Select):
        return [node.cond, node.if_true, node.if_false]
    if isinstance(node, Decl):
        return [node.value]
    if isinstance(node, Assign):
        return [node.target, node.value]
    if isinstance(node, If):
        return [node.cond, *node.then, *node.orelse]
    if isinstance(node, For):
        return ([node.bound] if node.bound is not None else []) + list(node.body)
    if isinstance(node, Switch):
        return [node.selector, *(s for _, body in node.cases for s in body), *node.default]
    if isinstance(node, Return):
        return [node.value] if node.value is not None else []
    return []


def walk(node):
    """Pre-order walk over a node and everything below it (an explicit stack: no depth limit, and no chain of
    nested generators that a recursive walk would resume once per level for every node it yields)."""
    stack = [node]
    while stack:
        n = stack.pop()
        yield n
        stack.extend(reversed(children(n)))


def walk_body(stmts):
    for s in stmts:
        yield from walk(s)


_NODES = (Expr, Stmt, Function, Param)
_COPIED = (Expr, Stmt, Function, Param, list, tuple, dict)


def clone(node):
    """A copy of an IR tree (expressions, statements, functions, parameters) in which every node is new and
    types, locations and constants are shared: they are values, never mutated. What copy.deepcopy gives for
    these trees, several times faster (the link stage copies every brick function it links), and with an
    explicit stack: a tree of any depth is copied without recursion."""
    if not isinstance(node, _COPIED):
        return node
    out = [None]
    todo = [(node, out, 0)]  # (original, the container its copy goes into, the key there)
    tuples = []  # (list of copied items, container, key): made tuples once every item is copied
    while todo:
        src, dst, key = todo.pop()
        if isinstance(src, _NODES):
            new = object.__new__(type(src))
            fields = new.__dict__
            for k, v in src.__dict__.items():
                fields[k] = v
                if isinstance(v, _COPIED):
                    todo.append((v, fields, k))
        elif isinstance(src, dict):
            new = dict(src)
            todo.extend((v, new, k) for k, v in src.items() if isinstance(v, _COPIED))
        else:
            new = list(src)
            todo.extend((v, new, i) for i, v in enumerate(src) if isinstance(v, _COPIED))
            if isinstance(src, tuple):
                tuples.append((new, dst, key))
        dst[key] = new
    for items, dst, key in reversed(tuples):  # inner tuples were found after the ones holding them
        dst[key] = tuple(items)
    return out[0]
