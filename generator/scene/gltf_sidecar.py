"""A glTF scene's lights file, SCENE.lights.toml beside SCENE.gltf / SCENE.glb: what glTF cannot say about lights.

KHR_lights_punctual has no shadows and no notion of a light buffer, so a glTF scene's lights are imported with
shadow "none", one static set per glTF scene (scene/gltf_lights.py). The sidecar says the rest, and load_scene
reads it, so every command (build, render, matrix, check, costs) sees the same lights:

    [lights.Lamp]              # a light by its imported name: the glTF light's name, else its node's
    shadow = "pcf"             # its shadow filter (default "none")
    params = { bias = 0.002 }  # optional: its light's or filter's parameters, over what the import mapped

    [light_set]                # every glTF scene's light set (the import makes one per glTF scene)
    dynamic = true             # default false: static, its lights unrolled (at most 32)
    max = 64                   # as a TOML scene's dynamic set (scene/light_sets.py)
    model = ["point/none"]
    culling = "tiles"          # optional, as a TOML scene's dynamic set: loops read a screen tile's light list

Why a file beside the scene, not a glTF extension: the .gltf stays what a DCC tool exported, and the placement
file (SCENE.placement.toml, for rendering) already sits there the same way. Every key is checked: an unknown key
or light name is a located error in the sidecar, with the closest name.
"""
from __future__ import annotations

import difflib
from pathlib import Path

from ..library.bricks import Library
from ..spec.permutation import canonical, parse_spec
from ..spec.resolve import light_params
from .locate import Locator

SIDECAR_SCHEMA = {
    "type": "object", "additionalProperties": False,
    "properties": {
        "lights": {"type": "object", "additionalProperties": {
            "type": "object", "additionalProperties": False,
            "properties": {"shadow": {"type": "string", "minLength": 1, "maxLength": 4096},
                           "params": {"type": "object"}}}},
        "light_set": {"type": "object", "additionalProperties": False,
                      "properties": {"dynamic": {"type": "boolean"}, "max": {"type": "integer"},
                                     "model": {"type": "array", "items": {"type": "string"}, "maxItems": 256},
                                     "loop": {"type": "string"}, "culling": {"type": "string"}}},
    },
}


def sidecar_path(scene_path) -> Path:
    """Where a glTF scene's lights file lives: beside it, SCENE.lights.toml (as SCENE.placement.toml does)."""
    p = Path(scene_path)
    return p.with_name(p.stem + ".lights.toml")


class Sidecar:
    """A read and shape-checked lights file (or none: every method then leaves the import as it is)."""

    def __init__(self, scene_path, lib: Library):
        from .load import read_toml
        self.path, self.lib = sidecar_path(scene_path), lib
        self.data: dict = {}
        self.loc: Locator | None = None
        if self.path.is_file():
            self.data, self.loc = read_toml(self.path, "lights file", "fix the lights file's syntax")
            _check(self.data, self.loc)

    @property
    def found(self) -> bool:
        return self.loc is not None

    @property
    def dynamic(self) -> bool:
        return bool(self.data.get("light_set", {}).get("dynamic", False))

    def apply_lights(self, scene, names: list[str]) -> None:
        """Give lights `names` (just imported) the shadow filter and parameters the sidecar names for them."""
        from .load import Light, _check_params, _one, _spec
        if not self.found:
            return
        loc, lib = self.loc, self.lib
        for n in names:
            t = self.data.get("lights", {}).get(n)
            if t is None:
                continue
            old = scene.lights[n]
            shadow = _spec(loc, f"lights.{n}", "shadow", t.get("shadow", old.shadow),
                           lambda s: canonical(_one(s, parse_spec(s, lib, ("shadow",)), "shadow filter")))
            specs = light_params(lib, old.type, shadow)
            params = t.get("params", {})
            _check_params(loc, f"lights.{n}", params, specs, f"light '{old.type}' with shadow '{shadow}'")
            scene.lights[n] = Light(n, old.type, shadow, {**old.params, **params})

    def apply_set(self, scene, set_name: str) -> None:
        """Make glTF scene light set `set_name` dynamic when [light_set] says so."""
        from .light_sets import dynamic_set
        t = self.data.get("light_set")
        if not self.found or t is None:
            return
        if not t.get("dynamic", False):
            extra = sorted(set(t) - {"dynamic"})
            if extra:
                raise self.loc.error(self.loc.find("light_set", extra[0]), f"'{extra[0]}' is for a dynamic light "
                                     "set, and [light_set] is static", "add dynamic = true, or remove it")
            return
        dynamic_set(self.loc, set_name, t, scene, self.lib, ("light_set",))

    def check_names(self, scene) -> None:
        """Every light the sidecar names is one the import made (called once every glTF scene is read)."""
        if not self.found:
            return
        for n in self.data.get("lights", {}):
            if n not in scene.lights:
                near = difflib.get_close_matches(n, list(scene.lights), n=1)
                hint = f"did you mean '{near[0]}'?" if near else f"lights: {', '.join(scene.lights) or 'none'}"
                raise self.loc.error(self.loc.find(f"lights.{n}"), f"the glTF scene has no light '{n}'", hint)


def _check(data: dict, loc: Locator) -> None:
    """The sidecar's first shape violation, by position, as a located SourceError (the scene schema's words)."""
    from jsonschema import Draft202012Validator

    from .schema import _located
    first = None
    for e in Draft202012Validator(SIDECAR_SCHEMA).iter_errors(data):
        err = _located(e, loc)
        if first is None or (err.line, err.col) < (first.line, first.col):
            first = err
    if first is not None:
        raise first
