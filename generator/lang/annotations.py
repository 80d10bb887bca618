"""Type annotations of the brick language: builtin names, structs, arrays and buffers.

    float, vec3, mat4, texture2d, texturecube, ...   builtin types
    Lobe                                             a struct declared in the brick
    array[T, N]                                      T scalar/vector/matrix/struct, N an int
                                                     literal or UPPERCASE int constant, N ≥ 1
    storage_buffer[S]                                top-level resource declarations only:
    uniform_buffer[S, N]                             S a struct obeying types.buffer_layout_error
"""
from __future__ import annotations

import ast
import re

from .errors import SourceError
from .types import ARRAY_ELEMENT_KINDS, BUILTIN_TYPES, Type, array, buffer_layout_error, storage_buffer, uniform_buffer

BUFFER_TYPES = ("storage_buffer", "uniform_buffer")


def node_error(path: str, node, message: str, hint: str = "") -> SourceError:
    return SourceError(path, getattr(node, "lineno", 1), getattr(node, "col_offset", 0) + 1, message, hint)


MAX_IDENTIFIER = 64  # characters in a brick identifier: docs/design/language.md
# Generated names add at most a brick id, 6 hex digits and a few characters to one (`<id>_<6 hex>_<fn>`:
# 64 + 8 + 64), far below the shader compilers' limits (glslang: 1024 characters, GLSL and HLSL alike).
_ASCII_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def check_identifier(path: str, node, name: str) -> None:
    """A name the brick declares (function, parameter, local, struct, field, buffer, loop variable): ASCII,
    at most MAX_IDENTIFIER characters, never starting with '_' nor holding '__' (the generator's own names)."""
    if not _ASCII_IDENTIFIER.fullmatch(name):
        bad = next(c for c in name if not (c.isascii() and (c.isalnum() or c == "_")))
        raise node_error(path, node, f"identifier '{name}' holds {bad!r} (U+{ord(bad):04X}), not an ASCII letter, "
                         "digit or _", "rename it: GLSL and HLSL take ASCII names only")
    if len(name) > MAX_IDENTIFIER:
        raise node_error(path, node, f"identifier '{name[:24]}…' is {len(name)} characters long, more than the "
                         f"{MAX_IDENTIFIER} allowed", f"shorten it to at most {MAX_IDENTIFIER} characters (generated "
                         "names add the brick id and a hash to it; shader compilers limit names to 1024)")
    if name.startswith("_") or "__" in name:
        raise node_error(path, node, f"identifier '{name}' starts with or contains '__' / '_'",
                         "names beginning with '_' or containing '__' are reserved for the generator; rename it")


def const_int(path: str, node, constants: dict | None, what: str, hint: str) -> int:
    """An int literal or an UPPERCASE int module constant (the value), else a located error."""
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return node.value
    if isinstance(node, ast.Name) and constants and node.id in constants and constants[node.id].ty.name == "int":
        return constants[node.id].value
    shown = ast.unparse(node) if isinstance(node, ast.AST) else str(node)
    raise node_error(path, node, f"{what} '{shown}' is not a constant", hint)


def parse_type(path: str, node, structs: dict[str, Type], constants: dict | None = None,
               resource: bool = False) -> Type:
    """A type annotation. `resource`: a top-level declaration, where buffer types are allowed."""
    if isinstance(node, ast.Name):
        if node.id in BUILTIN_TYPES:
            return BUILTIN_TYPES[node.id]
        if node.id in structs:
            return structs[node.id]
        if node.id in BUFFER_TYPES or node.id == "array":
            raise node_error(path, node, f"'{node.id}' needs its element type",
                             "write array[T, N], storage_buffer[S] or uniform_buffer[S, N]")
    if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id in ("array",) + BUFFER_TYPES:
        return _generic(path, node, node.value.id, structs, constants, resource)
    if isinstance(node, ast.Constant) and node.value is None:
        raise node_error(path, node, "functions must return a value", "bricks are pure: return a float, vector or struct")
    names = ", ".join(sorted(BUILTIN_TYPES))
    shown = ast.unparse(node) if isinstance(node, ast.AST) else str(node)
    raise node_error(path, node, f"unknown type '{shown}'",
                     f"use one of {names}, array[T, N] or a struct declared in this brick")


def _generic(path, node: ast.Subscript, kind: str, structs, constants, resource) -> Type:
    args = list(node.slice.elts) if isinstance(node.slice, ast.Tuple) else [node.slice]
    want = {"array": 2, "storage_buffer": 1, "uniform_buffer": 2}[kind]
    spelled = {"array": "array[T, N]", "storage_buffer": "storage_buffer[S]", "uniform_buffer": "uniform_buffer[S, N]"}
    if len(args) != want:
        raise node_error(path, node, f"{kind} takes {want} argument{'s' if want > 1 else ''}", f"write {spelled[kind]}")
    if kind != "array" and not resource:
        raise node_error(path, node, f"a {kind} is a global resource, not a parameter, local or field",
                         f"declare it at the top level of the brick (lights: {spelled[kind]}) and read it by name")
    elem = parse_type(path, args[0], structs, constants)
    size = 0
    if want == 2:
        size = const_int(path, args[1], constants, f"{kind} size",
                         "write an int literal or an UPPERCASE int constant declared above (N = 4)")
        if size < 1:
            raise node_error(path, args[1], f"{kind} size {size} is not positive", "use a size of at least 1")
    if kind == "array":
        if elem.kind not in ARRAY_ELEMENT_KINDS:
            raise node_error(path, args[0], f"arrays of {elem} are not allowed",
                             "an array holds scalars, vectors, matrices or structs (wrap an inner array in a struct)")
        return array(elem, size)
    why = buffer_layout_error(elem)
    if why:
        raise node_error(path, args[0], why,
                         "every buffer member must be a vec4, ivec4 or uvec4 (or a struct/array of them) "
                         "so std140, std430, HLSL and WGSL lay it out alike; pack scalars into a vec4")
    return storage_buffer(elem) if kind == "storage_buffer" else uniform_buffer(elem, size)
