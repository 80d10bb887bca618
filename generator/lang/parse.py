"""Brick files (Python syntax) → typed IR. Parsed with `ast`; never imported or executed.

A brick file holds a docstring, a literal `BRICK = {...}` metadata dict (read
with ast.literal_eval), optional UPPERCASE literal constants, optional structs
(`class Name:` with annotated fields only), read-only buffer declarations
(`lights: storage_buffer[Light]`, `table: uniform_buffer[Entry, 16]`: global
resources the functions read by name; ir.Module.globals) and typed pure functions.
"""
from __future__ import annotations

import ast
import hashlib
import re
from dataclasses import dataclass

from . import ir
from .errors import SourceError, position
from .intrinsics import CONSTANTS
from .annotations import check_identifier, parse_type
from .typecheck import Checker
from .types import BUILTIN_TYPES, Type, struct


@dataclass(frozen=True)
class Signature:
    """The signature of a function defined outside the module being parsed (slots, other bricks)."""

    params: tuple  # ((name, Type), ...)
    ret: Type


def _loc(path: str, node) -> ir.Loc:
    return ir.Loc(path, getattr(node, "lineno", 1), getattr(node, "col_offset", 0) + 1)


def _err(path, node, message, hint=""):
    loc = _loc(path, node)
    return SourceError(loc.path, loc.line, loc.col, message, hint)


# Bounds on a brick's syntax, each far above any real brick (measured over bricks/ and the test bricks): the
# type checker, the link stage and the emitters walk trees recursively, and the time to link, emit and compile a
# brick grows with its size (a brick of 100,000 statements kept `build` busy past 60 s; one of 1,000 short
# statements builds in about 6 s). docs/design/language.md lists them.
MAX_DEPTH = 100  # syntax nesting, expressions and statements: the deepest shipped brick is 13 (gotanda_fitted)
MAX_STATEMENTS = 1000  # statements in a brick: the longest shipped brick has 27 (conductor_exact), test bricks 133
MAX_NODES = 20000  # syntax nodes in a brick: the largest shipped brick has 612 (gotanda_fitted), test bricks 1,946
MAX_BRICK_BYTES = 1 << 20  # a brick file: the largest shipped one is 5,954 bytes; Python's parser needs ~1 s per MiB
WHY_DEPTH = "a limit far above any real brick, which keeps the tree walks of this tool and the compilers bounded"
WHY_SIZE = "a limit far above any real brick, which bounds the time to link, emit and compile it"


def _check_size(tree: ast.AST, path: str) -> None:
    """A brick nested deeper than MAX_DEPTH, or with more than MAX_STATEMENTS statements or MAX_NODES syntax
    nodes, is one located error. `a and b and c` is one node in Python's tree but a chain of binary operations in
    the IR (each operand one level deeper), so a BoolOp of n operands counts n - 1 levels. An explicit stack: the
    check itself has no depth limit."""
    stack = [(tree, 0, 1, 1)]
    statements = nodes = 0
    while stack:
        node, depth, line, col = stack.pop()
        line, col = getattr(node, "lineno", line), getattr(node, "col_offset", col - 1) + 1  # operators: the parent's
        nodes += 1
        if isinstance(node, ast.stmt):
            statements += 1
            if statements > MAX_STATEMENTS:
                raise SourceError(path, line, col, f"the brick has more than {MAX_STATEMENTS} statements ({WHY_SIZE})",
                                  "split it into several bricks, or compute in loops")
        if nodes > MAX_NODES:
            raise SourceError(path, line, col, f"the brick has more than {MAX_NODES} syntax nodes ({WHY_SIZE})",
                              "split it into several bricks, or compute in loops")
        step = depth + 1 + (len(node.values) - 1 if isinstance(node, ast.BoolOp) else 0)
        below = list(ast.iter_child_nodes(node))
        if below and step > MAX_DEPTH:  # at the node whose operands are one level too deep (a BoolOp: its start)
            raise SourceError(path, line, col, f"this expression or statement is nested more than {MAX_DEPTH} deep "
                              f"({WHY_DEPTH})", "split it into locals (a sum of many terms, a chain of and/or: "
                              "combine a few at a time)")
        stack.extend((child, step, line, col) for child in below)


# What Python's parser cannot take: a NUL (3.11.2 raises ValueError, later 3.11 releases SyntaxError) and a lone
# surrogate (a str handed in, not read from a file: UTF-8 decoding refuses those).
_UNPARSABLE = re.compile("[\x00\ud800-\udfff]")


def _densest_line(text: str) -> tuple[int, int]:
    """Where Python's parser most likely gave up: the start of the logical line holding the most tokens."""
    import io
    import tokenize
    best, most, count, start = (1, 0), 0, 0, None
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if start is None and tok.type not in (tokenize.INDENT, tokenize.DEDENT, tokenize.NL, tokenize.COMMENT):
                start = tok.start
            count += 1
            if tok.type in (tokenize.NEWLINE, tokenize.ENDMARKER):
                if count > most and start is not None:
                    best, most = start, count
                count, start = 0, None
    except (tokenize.TokenError, SyntaxError, RecursionError, MemoryError):
        pass
    return best[0], best[1] + 1


def _syntax_tree(text: str, path: str) -> ast.Module:
    import warnings
    bad = _UNPARSABLE.search(text)
    if bad:
        line, col = position(text, bad.start())
        if bad.group() == "\x00":
            head = text[:200]  # every other byte NUL: UTF-16 text of ASCII characters
            utf16 = len(head) >= 8 and head.count("\x00") * 3 >= len(head)
            raise SourceError(path, line, col, "a NUL character" + (" (the file looks UTF-16)" if utf16 else ""),
                              "save the brick as UTF-8 text" if utf16 else "remove it: a brick is UTF-8 text")
        raise SourceError(path, line, col, f"a lone surrogate U+{ord(bad.group()):04X}", "a brick is UTF-8 text")
    try:
        with warnings.catch_warnings():  # Python's warnings about its own syntax (an invalid escape in a docstring)
            warnings.simplefilter("ignore", SyntaxWarning)
            warnings.simplefilter("ignore", DeprecationWarning)
            tree = ast.parse(text, filename=path)
    except SyntaxError as e:  # "too many nested parentheses" and indentation levels among them, located
        raise SourceError(path, e.lineno or 1, e.offset or 1, f"syntax error: {e.msg}",
                          "a brick is written in a small typed subset of Python syntax") from None
    except (RecursionError, MemoryError, ValueError) as e:  # the parser's own stack: a 10,000-term sum
        line, col = _densest_line(text)
        what = "an expression is too long or too deeply nested to parse" if not isinstance(e, ValueError) \
            else f"Python cannot parse this text ({e})"
        raise SourceError(path, line, col, what, "split it into locals of a few terms each") from None
    _check_size(tree, path)
    return tree


def read_meta(text: str, path: str) -> tuple[dict, ir.Loc, str]:
    """Read only a brick's docstring and BRICK metadata (no function bodies)."""
    meta, loc, doc, _ = read_meta_node(text, path)
    return meta, loc, doc


def read_meta_node(text: str, path: str) -> tuple[dict, ir.Loc, str, ast.AST]:
    """read_meta, and the BRICK literal's syntax node (where each of its keys is). A second BRICK is an error."""
    tree = _syntax_tree(text, path)
    doc = ast.get_docstring(tree) or ""
    found = None
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "BRICK" for t in node.targets):
            if found is not None:
                raise _err(path, node, f"a second BRICK (the first is at line {found[1].line})",
                           "keep one BRICK dict per brick")
            try:
                meta = ast.literal_eval(node.value)
            except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
                raise _err(path, node.value, "BRICK must be a literal dict",
                           "use only strings, numbers, lists and dicts in BRICK (no names or calls)") from None
            if not isinstance(meta, dict):
                raise _err(path, node.value, "BRICK must be a dict", 'write BRICK = {"kind": ..., "params": {...}}')
            found = (meta, _loc(path, node), doc, node.value)
    if found is None:
        raise SourceError(path, 1, 1, "no BRICK metadata dict", 'add BRICK = {"kind": "...", "params": {...}} at top level')
    return found


def parse_module(text: str, path: str, externals: dict[str, Signature] | None = None) -> ir.Module:
    """Parse and type-check one brick file. `externals` are callable names it may use (slots)."""
    tree = _syntax_tree(text, path)
    doc = ast.get_docstring(tree) or ""
    meta, meta_loc = None, ir.Loc(path, 1, 1)
    structs: dict[str, Type] = {}
    constants: dict[str, ir.Const] = {}
    fdefs: list[ast.FunctionDef] = []
    resources: dict[str, ir.Global] = {}
    for i, node in enumerate(tree.body):
        if i == 0 and isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            continue
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            name = node.targets[0].id
            if name == "BRICK":
                meta, meta_loc, _ = read_meta(text, path)
                continue
            constants[name] = _module_constant(path, node, name, node.value)
            continue
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.value is None:
            name = node.target.id
            resources[name] = _resource(path, node, name, structs, constants, resources)
            continue
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.value is not None:
            name = node.target.id
            c = _module_constant(path, node, name, node.value)
            want = parse_type(path, node.annotation, structs, constants)
            if c.ty != want:
                raise _err(path, node.value, f"constant {name} is declared {want} but its value is {c.ty}",
                           "write a float literal with a decimal point (1.0) for float constants")
            constants[name] = c
            continue
        if isinstance(node, ast.ClassDef):
            structs[node.name] = _parse_struct(path, node, structs, constants)
            continue
        if isinstance(node, ast.FunctionDef):
            fdefs.append(node)
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            raise _err(path, node, "imports are not allowed in a brick",
                       "bricks are parsed, never executed; intrinsics (pow, dot, ...) and constants (PI) need no import")
        raise _err(path, node, f"'{type(node).__name__}' is not allowed at the top level of a brick",
                   "a brick holds a docstring, BRICK = {...}, UPPERCASE constants, structs, buffers and functions")
    if meta is None:
        raise SourceError(path, 1, 1, "no BRICK metadata dict", 'add BRICK = {"kind": "...", "params": {...}} at top level')

    # First pass: signatures, so functions may call each other in any order.
    sigs: dict[str, Signature] = dict(externals or {})
    for f in fdefs:
        check_identifier(path, f, f.name)
        if f.name in sigs:
            raise _err(path, f, f"function '{f.name}' is defined twice or shadows a slot", "rename one of them")
        if f.name in resources:
            raise _err(path, f, f"function '{f.name}' has the name of a buffer", "rename one of them")
        sigs[f.name] = _signature(path, f, structs, constants)
    functions: dict[str, ir.Function] = {}
    for f in fdefs:
        checker = Checker(path, structs, constants, sigs, set(externals or {}), resources)
        functions[f.name] = checker.function(f, sigs[f.name])
    _reject_recursion(path, functions, fdefs)
    digest = hashlib.sha256(text.encode()).hexdigest()
    return ir.Module(path, doc, meta, meta_loc, structs, constants, functions, digest, resources)


def _resource(path, node: ast.AnnAssign, name, structs, constants, resources) -> ir.Global:
    """`name: storage_buffer[S]` or `name: uniform_buffer[S, N]` at the top level."""
    check_identifier(path, node.target, name)
    if name.isupper():
        raise _err(path, node, f"constant {name} has no value", f"write {name}: {ast.unparse(node.annotation)} = <literal>")
    ty = parse_type(path, node.annotation, structs, constants, resource=True)
    if ty.kind != "buffer":
        raise _err(path, node, f"'{name}: {ty}' at the top level declares nothing",
                   "top-level declarations without a value are buffers (storage_buffer[S], uniform_buffer[S, N]); "
                   "textures are function parameters")
    if name in resources or name in structs or name in CONSTANTS or name in BUILTIN_TYPES:
        raise _err(path, node, f"'{name}' is declared twice or shadows a type or constant", "rename the buffer")
    return ir.Global(name, ty, -1, -1, _loc(path, node))


def _module_constant(path, node, name, value) -> ir.Const:
    if not name.isupper():
        raise _err(path, node, f"module-level name '{name}' is not a constant",
                   "only BRICK and UPPERCASE literal constants may be assigned at the top level")
    if name in CONSTANTS:
        raise _err(path, node, f"'{name}' redefines a built-in constant", "use the built-in or pick another name")
    sign = 1
    v = value
    if isinstance(v, ast.UnaryOp) and isinstance(v.op, ast.USub):
        sign, v = -1, v.operand
    if isinstance(v, ast.Constant) and type(v.value) in (int, float):
        val = sign * v.value
        if isinstance(val, int) and not -2**31 <= val < 2**31:
            raise _err(path, value, f"constant {name} = {val} does not fit in 32 bits", "use a smaller value or a float")
        if isinstance(val, float) and not abs(val) <= 3.4028234663852886e38:
            raise _err(path, value, f"constant {name} = {val!r} is outside the fp32 range", "use a value below 3.4e38")
        ty = BUILTIN_TYPES["float" if isinstance(val, float) else "int"]
        return ir.Const(ty, _loc(path, node), val)
    raise _err(path, value, f"constant {name} must be a number literal", "write e.g. K = 0.5 or N = 4")


# Struct and block names of the templates and the glue (backends/*/templates, link/glue.py LightData<i>, link/uber.py,
# link/__init__.py): a brick's struct is emitted under its own name beside them, so it may be none of them.
TEMPLATE_STRUCTS = frozenset({"Blur", "Draw", "Frame", "Info", "LightEntry", "Lights", "Material", "MaterialBuffer",
                              "MaterialEntry", "Object", "PSIn", "Params", "Result", "Samples", "VSIn", "VSOut"})
_TEMPLATE_STRUCT_FAMILIES = re.compile(r"(LightData|LightBuffer)[0-9]*")
_STRUCT_NAME = re.compile(r"[A-Z][A-Za-z0-9]*")


def _parse_struct(path, node: ast.ClassDef, structs, constants) -> Type:
    check_identifier(path, node, node.name)
    if not _STRUCT_NAME.fullmatch(node.name):  # every generated function name holds a '_' (`<brick>_<function>`)
        raise _err(path, node, f"struct name '{node.name}' must start with a capital letter and hold no '_'",
                   "name structs in CamelCase (Lobe, LightSample): function names in generated code hold a '_', "
                   "so a struct never meets one")
    if node.name in TEMPLATE_STRUCTS or _TEMPLATE_STRUCT_FAMILIES.fullmatch(node.name):
        raise _err(path, node, f"struct name '{node.name}' is a block or struct name of the generated code "
                   "(templates and glue)", "rename the struct")
    if node.bases or node.keywords or node.decorator_list:
        raise _err(path, node, "a struct is a plain class with annotated fields", "remove base classes and decorators")
    fields = []
    for i, item in enumerate(node.body):
        if i == 0 and isinstance(item, ast.Expr) and isinstance(item.value, ast.Constant) and isinstance(item.value.value, str):
            continue
        if isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name) and item.value is None:
            check_identifier(path, item, item.target.id)
            fields.append((item.target.id, parse_type(path, item.annotation, structs, constants)))
            continue
        raise _err(path, item, "a struct body holds only annotated fields (name: type)",
                   "move functions to the top level; remove default values")
    if not fields:
        raise _err(path, node, f"struct {node.name} has no fields", "add at least one annotated field")
    return struct(node.name, fields)


def _signature(path, f: ast.FunctionDef, structs, constants) -> Signature:
    a = f.args
    if a.vararg or a.kwarg or a.kwonlyargs or a.defaults or a.posonlyargs or a.kw_defaults:
        raise _err(path, f, "only plain positional parameters with type annotations are allowed",
                   "remove *args, **kwargs, defaults and keyword-only parameters")
    if f.decorator_list:
        raise _err(path, f.decorator_list[0], "decorators are not allowed", "remove the decorator")
    params = []
    for arg in a.args:
        check_identifier(path, arg, arg.arg)
        if arg.annotation is None:
            raise _err(path, arg, f"parameter '{arg.arg}' has no type", f"annotate it, e.g. {arg.arg}: float")
        params.append((arg.arg, parse_type(path, arg.annotation, structs, constants)))
    if f.returns is None:
        raise _err(path, f, f"function '{f.name}' has no return type", "annotate it, e.g. -> vec3")
    ret = parse_type(path, f.returns, structs, constants)
    if ret.kind == "array":
        raise _err(path, f.returns, f"function '{f.name}' returns an array (HLSL functions cannot)",
                   "return a struct with an array field, or write into the caller's array")
    return Signature(tuple(params), ret)


MAX_CALL_DEPTH = 32  # a brick's functions calling each other in a chain: docs/design/language.md


def _reject_recursion(path, functions: dict[str, ir.Function], fdefs) -> None:
    """No function reaches itself (shading languages forbid recursion), and no chain of calls within the brick is
    longer than MAX_CALL_DEPTH (the linker and the emitters walk it; a 3,000-deep chain overflowed Python's stack
    here). An explicit stack, so that the check itself has no depth limit."""
    nodes = {f.name: f for f in fdefs}
    state: dict[str, int] = {}  # 1: on the current chain, 2: done
    depth: dict[str, int] = {}

    def callees(name: str) -> list[str]:
        return [c for c in functions[name].calls if c in functions]

    for root in functions:
        if root in state:
            continue
        state[root] = 1
        chain, todo = [root], [iter(callees(root))]
        while todo:
            callee = next(todo[-1], None)
            if callee is None:
                name = chain.pop()
                todo.pop()
                state[name] = 2
                depth[name] = 1 + max((depth[c] for c in callees(name)), default=0)
                if depth[name] > MAX_CALL_DEPTH:
                    raise _err(path, nodes[name], f"function '{name}' starts a chain of {depth[name]} nested calls, "
                               f"more than the {MAX_CALL_DEPTH} allowed", "call fewer functions in a row")
            elif state.get(callee) == 1:
                raise _err(path, nodes[callee], f"recursion: {' -> '.join(chain + [callee])}",
                           "shading languages do not allow recursion; unroll it or use a loop")
            elif callee not in state:
                state[callee] = 1
                chain.append(callee)
                todo.append(iter(callees(callee)))
