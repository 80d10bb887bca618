"""The scene file's shape as a JSON Schema, checked before any value is interpreted.

Why a schema (jsonschema, pinned): the rules are data, not code spread over the reader — one place
says which keys a table has and what type each value is, and an engine's tools can read the same
schema (`SCENE_SCHEMA`). Every violation becomes one located line through the scene's Locator: the
TOML position of the offending key, what is wrong, and what to do — for an unknown key, the closest
valid one ("unknown key 'ouput' in [scene] — did you mean 'output'?"). The reader then checks what a
schema cannot: that names exist (bricks, materials, light sets), and the parameters' ranges.
"""
from __future__ import annotations

import datetime
import difflib
import itertools
import re

from ..spec.surface import ALPHA_MODES, EMISSIVE
from .textures import FILTERS, MIPMAPS, WRAPS

NAME = {"type": "string", "minLength": 1, "maxLength": 256,
        "pattern": r"^[^\x00-\x1f\x7f\u0085\u2028\u2029]*(?!\n)$"}  # (?!\n): Python's $ also matches before a final \n
SPEC = {"type": "string", "minLength": 1, "maxLength": 4096}
NUMBER = {"type": "number"}
VECTOR = {"type": "array", "items": NUMBER, "minItems": 1, "maxItems": 64}
# a number, a vector, or an array parameter's elements ("count": N in the brick: [[…], […]]); check_value does the rest
PARAMS = {"type": "object", "propertyNames": NAME, "additionalProperties": {"anyOf": [
    NUMBER, VECTOR, {"type": "array", "items": {"anyOf": [NUMBER, VECTOR]}, "minItems": 1, "maxItems": 64}]}}
# per material: texture name -> image path; texture name -> sampler (scene/textures.py checks names and ranges)
TEXTURES = {"type": "object", "propertyNames": NAME, "additionalProperties": {"type": "string", "minLength": 1,
                                                                              "maxLength": 4096}}
SAMPLERS = {"type": "object", "propertyNames": NAME, "additionalProperties": {
    "type": "object", "additionalProperties": False,
    "properties": {**{k: {"type": "string", "enum": list(FILTERS)} for k in ("filter", "mag_filter", "min_filter")},
                   "mipmap": {"type": "string", "enum": list(MIPMAPS)},
                   **{k: {"type": "string", "enum": list(WRAPS)} for k in ("wrap", "wrap_u", "wrap_v")},
                   "anisotropy": NUMBER, "lod_bias": NUMBER}}}
SCENE_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "shadermatrix scene",
    "type": "object",
    "additionalProperties": False,
    "properties": {
        "scene": {"type": "object", "additionalProperties": False,
                  "properties": {"name": NAME, "output": SPEC, "precision": NAME, "ubershader": {"type": "boolean"},
                                 # the environment of every light set no environment names (scene/environments.py)
                                 "environment": NAME}},
        # image-based lighting: an image or the procedural sky, and the light sets it lights
        "environments": {"type": "object", "propertyNames": NAME, "additionalProperties": {
            "type": "object", "additionalProperties": False,
            "properties": {"image": {"type": "string", "minLength": 1, "maxLength": 4096}, "sky": NAME,
                           "rotation": NUMBER, "intensity": NUMBER, "size": {"type": "integer"},
                           "light_sets": {"type": "array", "items": NAME, "maxItems": 4096}, "brick": NAME}}},
        "materials": {"type": "object", "propertyNames": NAME, "additionalProperties": {
            "type": "object", "additionalProperties": False, "required": ["brdf"],
            "properties": {"brdf": SPEC, "packing": SPEC, "params": PARAMS,
                           # the surface state (spec/surface.py); absent = the default, the key unchanged
                           "alpha": {"type": "string", "enum": list(ALPHA_MODES)},
                           "double_sided": {"type": "boolean"}, "vertex_color": {"type": "boolean"},
                           "emissive": {"type": "string", "enum": list(EMISSIVE)},
                           "textures": TEXTURES, "samplers": SAMPLERS}}},
        "lights": {"type": "object", "propertyNames": NAME, "additionalProperties": {
            "type": "object", "additionalProperties": False, "required": ["type"],
            "properties": {"type": NAME, "shadow": SPEC, "params": PARAMS}}},
        # a static set is a list of light names; a dynamic one a table (scene/light_sets.py): the keywords of
        # one type are ignored by the other, so one schema says both
        "light_sets": {"type": "object", "propertyNames": NAME, "additionalProperties": {
            "type": ["array", "object"], "items": NAME, "maxItems": 4096,
            "additionalProperties": False, "required": ["dynamic"],
            "properties": {"dynamic": {"type": "boolean"}, "lights": {"type": "array", "items": NAME, "maxItems": 1 << 16},
                           "max": {"type": "integer"}, "model": {"type": "array", "items": SPEC, "maxItems": 256},
                           "loop": {"type": "string"}, "culling": {"type": "string"}}}},
        "objects": {"type": "array", "items": {
            "type": "object", "additionalProperties": False, "required": ["material", "lights"],
            "properties": {"name": NAME, "material": NAME, "lights": NAME}}},
    },
}

_TYPES = {"object": "a table", "array": "an array", "string": "a string", "number": "a number",
          "integer": "a whole number", "boolean": "true or false"}
_EXAMPLES = {"scene": "[scene] name = \"courtyard\"", "materials": "[materials.NAME] brdf = \"lambert\"",
             "lights": "[lights.NAME] type = \"point\"", "light_sets": "[light_sets] NAME = [\"sun\"]",
             "objects": "[[objects]] material = \"NAME\" lights = \"SET\"",
             "environments": "[environments.NAME] sky = \"default\""}


def _what(value) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (datetime.date, datetime.time)):
        return "a date or time"
    return {dict: "a table", list: "an array", str: "a string", int: "a number", float: "a number"}.get(
        type(value), type(value).__name__)


def _header(path: list) -> tuple[str, list, int]:
    """(TOML header, keys below it, nth) of a schema error path such as ['objects', 3, 'name']."""
    if not path:
        return "", [], 0
    if path[0] == "objects":
        nth = path[1] if len(path) > 1 and isinstance(path[1], int) else 0
        return "objects", [str(p) for p in path[2:]], nth
    if path[0] in ("materials", "lights", "environments") and len(path) > 1:
        return f"{path[0]}.{path[1]}", [str(p) for p in path[2:]], 0
    return str(path[0]), [str(p) for p in path[1:]], 0


def _where(path: list) -> str:
    head, keys, nth = _header(path)
    if head == "objects":
        return f"object {nth + 1} ([[objects]])"
    if head == "light_sets" and keys:
        return f"light set '{keys[0]}'"
    return f"[{head}]" if head else "the scene"


def check(data: dict, loc) -> None:
    """Raise the scene's first schema violation, by position in the file, as a located SourceError."""
    from jsonschema import Draft202012Validator

    objects, materials = data.get("objects"), data.get("materials")
    if isinstance(materials, dict):  # a plain material (a spec or two and the surface keys) checked directly too
        data = {**data, "materials": {k: m for k, m in materials.items() if not _plain_material(k, m)}}
    if isinstance(objects, list):  # objects one by one, each plain one checked directly: linear and quick
        errors = Draft202012Validator(SCENE_SCHEMA).iter_errors({**data, "objects": []})
        item = Draft202012Validator(SCENE_SCHEMA["properties"]["objects"]["items"])
        errors = itertools.chain(errors, (_under(e, "objects", i) for i, o in enumerate(objects)
                                          if not _plain_object(o) for e in item.iter_errors(o)))
    else:
        errors = Draft202012Validator(SCENE_SCHEMA).iter_errors(data)
    first = None
    for k, e in enumerate(errors):
        err = _located(e, loc)
        if first is None or (err.line, err.col) < (first.line, first.col):
            first = err
        if k >= 10_000:  # enough to find the earliest of a hostile file's violations
            break
    if first is not None:
        raise first


_NAME_PATTERN = re.compile(NAME["pattern"])
_OBJECT_KEYS = frozenset(SCENE_SCHEMA["properties"]["objects"]["items"]["properties"])


def _plain_object(o) -> bool:
    """What the objects' schema accepts, checked without jsonschema (it took 1 s for 10,000 objects)."""
    return (isinstance(o, dict) and "material" in o and "lights" in o and o.keys() <= _OBJECT_KEYS
            and all(isinstance(v, str) and 1 <= len(v) <= NAME["maxLength"] and _NAME_PATTERN.search(v)
                    for v in o.values()))


_SPEC_MAX = SPEC["maxLength"]
_MATERIAL = SCENE_SCHEMA["properties"]["materials"]["additionalProperties"]["properties"]
_ENUMS = {k: frozenset(_MATERIAL[k]["enum"]) for k in ("alpha", "emissive")}


def _plain_material(name, m) -> bool:
    """What the materials' schema accepts of a material without params, textures or samplers, checked without
    jsonschema (1.2 s for 10,000 materials): the rest goes through the schema, which says what is wrong."""
    if not (isinstance(name, str) and 1 <= len(name) <= NAME["maxLength"] and _NAME_PATTERN.search(name)
            and isinstance(m, dict) and "brdf" in m):
        return False
    for k, v in m.items():
        if k in ("brdf", "packing"):
            ok = isinstance(v, str) and 1 <= len(v) <= _SPEC_MAX
        elif k in _ENUMS:
            ok = isinstance(v, str) and v in _ENUMS[k]
        elif k in ("double_sided", "vertex_color"):
            ok = isinstance(v, bool)
        else:
            ok = False
        if not ok:
            return False
    return True


def _under(e, *prefix):
    """A violation found in a part of the scene, with the path from the scene's root."""
    e.path.extendleft(reversed(prefix))
    return e


def _located(e, loc):
    """One schema violation as a SourceError at its key (a message and what to do)."""
    path = list(e.path)
    head, keys, nth = _header(path)
    if e.validator == "additionalProperties":
        allowed = sorted(e.schema.get("properties", {}))
        extra = sorted(set(e.instance) - set(allowed))[0]
        pos = loc.top(extra) if not path else loc.find(head, *keys, extra, nth=nth)
        near = difflib.get_close_matches(extra, allowed, n=1)
        hint = f"did you mean '{near[0]}'?" if near else f"allowed: {', '.join(allowed)}"
        return loc.error(pos, f"unknown key '{extra}' in {_where(path)}", hint)
    pos = loc.find(head, *keys, nth=nth) if head else (1, 1)
    key = ".".join(str(p) for p in path) or "the scene"
    if e.validator == "required":
        missing = next(k for k in e.validator_value if k not in e.instance)
        return loc.error(pos, f"{_where(path)} has no '{missing}'", f"add {missing} = …")
    if e.validator == "type":
        types = e.validator_value if isinstance(e.validator_value, list) else [e.validator_value]
        want = " or ".join(_TYPES.get(t, t) for t in types)
        example = _EXAMPLES.get(str(path[0]) if path else "", "see docs/guide/scenes.md")
        return loc.error(pos, f"'{key}' must be {want}, not {_what(e.instance)}", f"write {example}"
                         if len(path) <= 1 else f"give {want}")
    if e.validator == "enum":
        return loc.error(pos, f"'{key}' is {e.instance!r}, not one of {', '.join(map(str, e.validator_value))}",
                         f"write {key.split('.')[-1]} = \"{e.validator_value[0]}\"")
    if e.validator == "anyOf":
        return loc.error(pos, f"'{key}' must be a number or an array of numbers, not {_what(e.instance)}",
                         "write e.g. 0.5 or [0.8, 0.1, 0.1]")
    if e.validator == "propertyNames":
        return loc.error(pos, f"a name in '{key}' is empty, too long or holds a control character",
                         "give printable names of at most 256 characters")
    if e.validator in ("minLength", "maxLength", "pattern", "minItems", "maxItems"):
        limit = e.validator_value
        what, todo = {"minLength": ("is empty", "give a value"),
                      "maxLength": (f"is longer than {limit} characters", f"keep it to {limit}"),
                      "pattern": ("holds a control character or a line break", "give a printable name"),
                      "minItems": ("is empty", "give at least one item"),
                      "maxItems": (f"has more than {limit} items", f"keep it to {limit}")}[e.validator]
        return loc.error(pos, f"'{key}' {what}", todo)
    return loc.error(pos, f"'{key}': {e.message}", "see docs/guide/scenes.md")
