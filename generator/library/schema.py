"""The BRICK metadata dict's shape as a JSON Schema, checked before its meaning.

Like the scene's (scene/schema.py): keys and value types are data here; library/bricks.py then checks
what a schema cannot (a kind's contract, a default inside its range, filler ids that exist). Every
violation is one line at the offending key of the BRICK literal (its position in the brick's source),
with the closest valid key for an unknown one. Names that reach generated code (parameters, slots,
textures, slot defaults) must be identifiers of the brick language, at most 64 characters.
"""
from __future__ import annotations

import ast
import difflib

from ..lang.exprs import F32_MAX

IDENT = {"type": "string", "pattern": r"^[A-Za-z_][A-Za-z0-9_]{0,63}(?!\n)$"}  # Python's $ matches before a final \n

NUMBER = {"type": "number", "minimum": -F32_MAX, "maximum": F32_MAX}  # parameters are float32 in every shader
VALUE = {"anyOf": [NUMBER, {"type": "array", "items": NUMBER, "minItems": 1, "maxItems": 64},
                   {"type": "array", "items": {"type": "array", "items": NUMBER, "minItems": 1, "maxItems": 16},
                    "minItems": 1, "maxItems": 16}]}
BRICK_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "shadermatrix BRICK metadata",
    "type": "object",
    "additionalProperties": False,
    "required": ["kind"],
    "properties": {
        "kind": {"type": "string"},
        "cite": {"type": "string", "maxLength": 1000},
        "doc": {"type": "string"},
        "fp16": {"type": "string", "maxLength": 1000},  # "unsafe: why" makes an fp16 build warn
        # "no: why" where the model itself is not reciprocal (f(l, v) != f(v, l)): plausibility then skips the
        # reciprocity check and says why; a brick that says nothing is held to it (eval/plausibility.py)
        "reciprocal": {"type": "string", "pattern": r"^no: \S", "maxLength": 1000},
        "needs": {"type": "array", "items": IDENT},
        "tolerance": {"type": "number", "minimum": 0.0, "maximum": 100.0},  # a 3-factor fit: ~36 (homomorphic_factorization)
        # an output brick's colour: linear radiance, or encoded for display (exactly sRGB, or sqrt's approximation)
        "encodes": {"enum": ["linear", "srgb", "sqrt"]},
        "params": {"type": "object", "propertyNames": IDENT, "additionalProperties": {
            "type": "object", "additionalProperties": False, "required": ["type", "default"],
            "properties": {"type": {"type": "string"}, "default": VALUE, "doc": {"type": "string"},
                           "range": {"type": "array", "items": NUMBER, "minItems": 2, "maxItems": 2},
                           "count": {"type": "integer", "minimum": 1}}}},
        "slots": {"type": "object", "propertyNames": IDENT, "additionalProperties": {
            "type": "object", "additionalProperties": False, "required": ["kind"],
            "properties": {"kind": {"type": "string"}, "default": IDENT, "optional": {"const": True}}}},
        "textures": {"type": "object", "propertyNames": IDENT, "additionalProperties": {
            "type": "object", "additionalProperties": False,
            "properties": {"srgb": {"type": "boolean"}, "doc": {"type": "string"},
                           # what a scene's image holds, which decides how its mip chain is filtered
                           # (assemble/textures.py); keep_length: normals averaged, not renormalized
                           "holds": {"enum": ["color", "data", "normal", "normal_xy"]},
                           "keep_length": {"type": "boolean"},
                           # a lookup table the generator bakes (generator/reference/tables.py), its size
                           # [W, H] (a cube: [S, S]) and stored format, chosen by measured error
                           "table": IDENT,
                           "size": {"type": "array", "items": {"type": "integer", "minimum": 1, "maximum": 4096},
                                    "minItems": 2, "maxItems": 2},
                           "format": {"enum": ["unorm8", "fp16", "fp32"]}}}},
    },
}

_TYPES = {"object": "a dict", "array": "a list", "string": "a string", "number": "a number", "integer": "an integer",
          "boolean": "True or False"}


def _what(v) -> str:
    if isinstance(v, bool):
        return "a boolean"
    return {dict: "a dict", list: "a list", tuple: "a tuple", str: "a string", int: "an integer", float: "a number",
            set: "a set", bytes: "bytes", type(None): "None"}.get(type(v), type(v).__name__)


def key_positions(node: ast.AST) -> dict[tuple, tuple[int, int]]:
    """(line, col) of every key of a literal dict (and of its nested dicts), by key path."""
    out: dict[tuple, tuple[int, int]] = {}

    def walk(n, path):
        if isinstance(n, ast.Dict):
            for k, v in zip(n.keys, n.values):
                if isinstance(k, ast.Constant):
                    p = (*path, k.value)
                    out[p] = (k.lineno, k.col_offset + 1)
                    walk(v, p)
    walk(node, ())
    return out


def _jsonable(v):
    """Tuples are lists to the schema (a literal's (1, 2) is a range too); anything else stays itself."""
    if isinstance(v, tuple):
        return [_jsonable(x) for x in v]
    if isinstance(v, list):
        return [_jsonable(x) for x in v]
    if isinstance(v, dict):
        return {k: _jsonable(x) for k, x in v.items()}
    return v


def check(meta: dict, shown: str, loc, positions: dict) -> None:
    """Raise the first schema violation of a BRICK dict as a SourceError at its key."""
    from jsonschema import Draft202012Validator

    from ..lang import SourceError

    bad_keys = [k for k in _walk_keys(meta) if not isinstance(k, str)]
    if bad_keys:
        line, col = next((pos for p, pos in positions.items() if not isinstance(p[-1], str)), (loc.line, loc.col))
        raise SourceError(shown, line, col, f"BRICK has a key that is not a string: {bad_keys[0]!r}",
                          "write every key as a string")
    errors = sorted(Draft202012Validator(BRICK_SCHEMA).iter_errors(_jsonable(meta)),
                    key=lambda e: [str(p) for p in e.path])
    if not errors:
        return
    e = errors[0]
    path = tuple(e.path)
    line, col = next((positions[path[:n]] for n in range(len(path), 0, -1) if path[:n] in positions),
                     (loc.line, loc.col))
    key = "BRICK" + "".join(f"[{p!r}]" for p in path)
    if e.validator == "additionalProperties":
        allowed = sorted(e.schema.get("properties", {}))
        extra = sorted(set(e.instance) - set(allowed))[0]
        line, col = positions.get((*path, extra), (line, col))
        near = difflib.get_close_matches(extra, allowed, n=1)
        raise SourceError(shown, line, col, f"unknown key '{extra}' in {key}",
                          f"did you mean '{near[0]}'?" if near else f"allowed: {', '.join(allowed)}")
    if path == ("reciprocal",) and e.validator == "pattern":
        raise SourceError(shown, line, col, f"{key} is {e.instance!r}: only a model that is not reciprocal says so",
                          'write "reciprocal": "no: why" (with the reason), or leave the key out')
    if e.validator == "propertyNames" or (e.validator == "pattern" and isinstance(e.instance, str)):
        name = e.instance if isinstance(e.instance, str) else ""
        line, col = positions.get((*path, name), (line, col))  # at the bad name itself
        raise SourceError(shown, line, col, f"{key} {name!r} is not a name of the brick language",
                          "use letters, digits and _, starting with a letter or _, at most 64 characters")
    if e.validator == "required":
        missing = next(k for k in e.validator_value if k not in e.instance)
        raise SourceError(shown, line, col, f"{key} has no '{missing}'", f"add \"{missing}\": …")
    huge = _past_float32(e.instance)
    if e.validator in ("minimum", "maximum") or (e.validator == "anyOf" and huge is not None):
        raise SourceError(shown, line, col, f"{key} holds {huge!r}, outside the float32 range (±3.4e38)",
                          "write a finite number of at most 3.4e38 in magnitude (parameters are float32 in shaders)")
    if e.validator == "type":
        raise SourceError(shown, line, col, f"{key} must be {_TYPES.get(e.validator_value, e.validator_value)}, "
                          f"not {_what(e.instance)}", "see docs/reference/language.md, \"BRICK metadata\"")
    if e.validator == "anyOf":
        raise SourceError(shown, line, col, f"{key} must be a number or a list of numbers, not {_what(e.instance)}",
                          "write e.g. 0.5 or [0.5, 0.5, 0.5]")
    if e.validator in ("minItems", "maxItems"):
        raise SourceError(shown, line, col, f"{key} has {len(e.instance)} items", "a range is [low, high]"
                          if path and path[-1] == "range" else "give fewer items")
    raise SourceError(shown, line, col, f"{key}: {e.message}", "see docs/reference/language.md, \"BRICK metadata\"")


def _past_float32(v):
    """The first number in v (a number or nested lists) that no float32 holds (1e400 is inf to literal_eval)."""
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return None if abs(v) <= F32_MAX else v
    if isinstance(v, (list, tuple)):
        return next((x for x in map(_past_float32, v) if x is not None), None)
    return None


def _walk_keys(v):
    if isinstance(v, dict):
        for k, x in v.items():
            yield k
            yield from _walk_keys(x)
    elif isinstance(v, (list, tuple)):
        for x in v:
            yield from _walk_keys(x)
