"""Scene manifests (TOML) → the permutations a scene needs, and nothing more.

Schema (docs/guide/scenes.md, every key):
    [scene]            name, output (default "linear"), precision (default "fp32")
    [materials.NAME]   brdf = spec, packing = spec (default "constants"), params = {...},
                       alpha = "opaque"|"mask"|"blend", double_sided, vertex_color = true|false,
                       emissive = "none"|"factor"|"texture" (the surface state: spec/surface.py),
                       textures = { TEXTURE = "path.png" }, samplers = { TEXTURE = { filter, … } }
                       (the images and samplers of the packing's textures: scene/textures.py)
    [lights.NAME]      type = light brick, shadow = spec (default "none"), params = {...}
    [light_sets]       NAME = [light names, in order]  (static: the key lists them)
    [light_sets.NAME]  dynamic = true, lights = [names], max = N (default 256), model = ["type/shadow", …]
                       (dynamic: the key carries the model; scene/light_sets.py)
    [environments.NAME] image = "file.hdr" | sky = "default", rotation, intensity, size, light_sets = [...], brick
                       ([scene] environment = NAME: every other light set's; scene/environments.py)
    [[objects]]        name, material = NAME, lights = light set NAME
Only (material × light set) pairs that some object uses become permutations.
"""
from __future__ import annotations

import difflib
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..io.bulk import collector_paused
from ..library.bricks import Library
from ..lang import SourceError
from ..lang.errors import MAX_INPUT_BYTES, read_text
from ..spec.permutation import PRECISIONS, LightKey, Permutation, SpecError, canonical, parse_brdf, parse_spec
from ..spec.resolve import Resolved, check_packing, light_params, resolve
from ..spec.surface import DEFAULT as DEFAULT_SURFACE, Surface
from ..spec.where import Origin, Where
from .environments import read_environments
from .light_sets import MAX_LIGHTS_PER_SET, DynamicSet, read_light_sets  # noqa: F401 (the cap, read here too)
from .locate import Locator
from .textures import declared, toml_bindings


@dataclass
class Material:
    name: str
    brdf: str
    packing: str
    params: dict
    surface: Surface = DEFAULT_SURFACE  # what of alpha, sidedness, vertex colours and emission the shader does
    # texture name -> TextureBinding (scene/textures.py): every texture the material binds, with its image
    # (named, or generated) and sampler
    images: dict = field(default_factory=dict)


@dataclass
class Light:
    name: str
    type: str
    shadow: str
    params: dict


@dataclass
class Scene:
    path: Path
    name: str
    output: str
    precision: str
    materials: dict[str, Material]
    lights: dict[str, Light]
    light_sets: dict[str, list[str]]
    objects: list[dict]
    permutations: dict[str, Permutation] = field(default_factory=dict)  # hash -> key
    users: dict[str, list[str]] = field(default_factory=dict)  # hash -> object names
    # where messages about a permutation point: its first object's `material = ...` (line, col); the
    # ubershader's, which every material feeds, points at [scene]
    where: dict[str, tuple[int, int]] = field(default_factory=dict)
    head_at: tuple[int, int] = (1, 1)
    notes: list[str] = field(default_factory=list)  # what an importer accepted or did not apply (scene/gltf.py)
    extra: dict = field(default_factory=dict)  # an importer's own data: glTF's extensions and pygltflib document
    # light set name -> DynamicSet (scene/light_sets.py): the sets whose lights a loop reads from buffers
    dynamic_sets: dict[str, DynamicSet] = field(default_factory=dict)
    ubershader: bool = True  # [scene] ubershader = false: build ships no fallback ubershader (assemble/entries.py ubershader_warning)
    # [environments.NAME] (scene/environments.py), and per light set the one that lights it and where it is declared
    environments: dict = field(default_factory=dict)
    environment_of: dict[str, str] = field(default_factory=dict)
    environment_at: dict[str, tuple[int, int]] = field(default_factory=dict)


def read_toml(path: Path, what: str, syntax_hint: str, limit: int = MAX_INPUT_BYTES) -> tuple[dict, "Locator"]:
    """A TOML file's data and a Locator over its text (at most `limit` bytes); a syntax error is a located
    SourceError."""
    shown = str(path)
    text = read_text(path, what, limit)
    try:
        data = tomllib.loads(text)
    except (RecursionError, MemoryError):  # tomllib recurses on nested arrays and inline tables
        raise SourceError(shown, 1, 1, f"the {what} nests arrays or tables too deeply to read",
                          "a scene needs at most a table of tables of arrays") from None
    except tomllib.TOMLDecodeError as e:
        m = re.search(r"\(at line (\d+), column (\d+)\)", str(e))
        line, col = (int(m.group(1)), int(m.group(2))) if m else (1, 1)
        msg = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(e))
        raise SourceError(shown, line, col, f"TOML syntax error: {msg}", syntax_hint) from None
    return data, Locator(shown, text)


# a scene file larger than this is refused: one of 100,000 permutations written plainly (scenegen.py) is 17 MB,
# and reading one takes about 0.6 s per MB
MAX_SCENE_BYTES = 64 << 20
SCENE_SUFFIXES = (".toml", ".gltf", ".glb")  # what a SCENE argument may be: TOML, or glTF 2.0 (scene/gltf.py)


def load_scene(path, lib: Library) -> Scene:
    """Read, validate and reduce a TOML scene (or a glTF 2.0 .gltf/.glb: scene/gltf.py) to its permutations."""
    path = Path(path)
    if path.suffix.lower() in SCENE_SUFFIXES[1:]:
        from .gltf import load_gltf
        return load_gltf(path, lib)
    with collector_paused():  # what loading makes lives on: io/bulk.py
        return _load_toml(path, lib)


def _load_toml(path: Path, lib: Library) -> Scene:
    shown = str(path)
    if path.is_dir():
        raise SourceError(shown, 1, 1, "is a directory, not a scene file", "pass a .toml scene file")
    data, loc = read_toml(path, "scene", "fix the scene file's syntax", MAX_SCENE_BYTES)
    from .schema import check
    check(data, loc)  # the shape first: keys and types (scene/schema.py), then what the names mean
    head = data.get("scene", {})
    output = head.get("output", "linear")
    precision = head.get("precision", "fp32")
    if precision not in PRECISIONS:
        raise loc.error(loc.find("scene", "precision"), f"precision '{precision}' is not supported",
                        f"use one of {', '.join(PRECISIONS)}")
    if lib.get("output", output) is None:
        raise loc.error(loc.find("scene", "output"), f"unknown output brick '{output}'",
                        f"known: {', '.join(b.id for b in lib.of_kind('output'))}")
    scene = Scene(path, head.get("name", path.stem), output, precision, {}, {}, {}, [], head_at=(loc.top("scene")[0], 1),
                  ubershader=head.get("ubershader", True))

    def at(*where) -> Where:
        return Where(shown, *loc.find(*where))

    # where each part of a permutation key was asked for (spec/where.py): errors resolving or linking it point there
    parts: dict[str, tuple] = {}
    # resolved path -> DecodedImage: a file several materials name is read once; ("generated", texture name) ->
    # (image, digest): the image a texture no file is named for gets (scene/textures.py)
    image_cache: dict = {}
    for name, m in _table(loc, data, "materials").items():
        where = loc.find(f"materials.{name}")
        if not isinstance(m, dict) or "brdf" not in m:
            raise loc.error(where, f"material '{name}' has no brdf", 'add brdf = "lambert+blinn_phong_normalized"')
        brdf = _spec(loc, f"materials.{name}", "brdf", m["brdf"], lambda s: canonical(parse_brdf(s, lib)))
        packing = _spec(loc, f"materials.{name}", "packing", m.get("packing", "constants"),
                        lambda s: canonical(_one(s, parse_spec(s, lib, ("packing",)), "packing")))
        surface = Surface(m.get("alpha", "opaque"), m.get("double_sided", False), m.get("vertex_color", False),
                          m.get("emissive", "none"))
        parts[name] = tuple((k, at(f"materials.{name}", k)) for k in ("brdf", "packing", *SURFACE_KEYS)) \
            + (("output", at("scene", "output")),)
        try:
            # one policy over the BRDF, the packing and the output brick (whose parameters,
            # exposure say, are set per material: they live in the Material block)
            r = resolve(Permutation(brdf, (), packing, output, precision, surface, Origin(parts[name])), lib)
        except SourceError as e:
            if e.path == shown:
                raise
            raise loc.error(where, e.message, e.hint) from None
        specs = surface_specs(r, lambda key, msg, todo: loc.error(
            loc.find(f"materials.{name}", key), f"material '{name}': {msg}", todo))
        params = m.get("params", {})
        _check_params(loc, f"materials.{name}", params, specs, f"BRDF '{brdf}'")
        problem, todo = check_packing(r)
        if problem:
            raise loc.error(loc.find(f"materials.{name}", "packing"), f"material '{name}': {problem}", todo)
        images = toml_bindings(loc, f"materials.{name}", m, declared(r.packing, surface), path.parent, image_cache,
                               scene.notes)
        scene.materials[name] = Material(name, brdf, packing, params, surface, images)

    for name, li in _table(loc, data, "lights").items():
        where = loc.find(f"lights.{name}")
        ltype = li.get("type") if isinstance(li, dict) else None
        lb = lib.get("light", ltype) if isinstance(ltype, str) else None
        if lb is None:
            raise loc.error(loc.find(f"lights.{name}", "type") if ltype else where,
                            f"light '{name}' has unknown type {ltype!r}",
                            f"type is one of {', '.join(b.id for b in lib.of_kind('light'))}")
        shadow = _spec(loc, f"lights.{name}", "shadow", li.get("shadow", "none"),
                       lambda s: canonical(_one(s, parse_spec(s, lib, ("shadow",)), "shadow filter")))
        parts[f"light:{name}"] = at(f"lights.{name}", "type")
        try:
            specs = light_params(lib, ltype, shadow)
        except SourceError as e:
            raise loc.error(where, e.message, e.hint) from None
        params = li.get("params", {})
        _check_params(loc, f"lights.{name}", params, specs, f"light '{ltype}' with shadow '{shadow}'")
        scene.lights[name] = Light(name, ltype, shadow, params)

    read_light_sets(loc, data, scene, lib)  # static lists and dynamic tables (scene/light_sets.py)
    read_environments(loc, data, scene, lib)  # image-based lighting per light set (scene/environments.py)

    objects = data.get("objects", [])
    if not isinstance(objects, list):
        raise loc.error((1, 1), "objects must be an array of tables", "write [[objects]] sections")
    seen_names: dict[str, int] = {}
    hashes: dict[Permutation, str] = {}
    for i, obj in enumerate(objects):
        oname = obj.get("name", f"object{i}")
        if oname in seen_names:
            raise loc.error(loc.find("objects", *(["name"] if "name" in obj else []), nth=i),
                            f"object name '{oname}' is used twice (object {seen_names[oname] + 1} and {i + 1})",
                            "give every object its own name")
        seen_names[oname] = i
        mat = obj.get("material")
        if mat not in scene.materials:
            raise loc.error(loc.find("objects", "material", nth=i), f"object '{oname}' uses unknown material {mat!r}",
                            f"materials: {', '.join(scene.materials) or 'none defined'}")
        lset = obj.get("lights", [])
        if isinstance(lset, str):
            if lset not in scene.light_sets:
                raise loc.error(loc.find("objects", "lights", nth=i), f"object '{oname}' uses unknown light set {lset!r}",
                                f"light sets: {', '.join(scene.light_sets) or 'none defined'}")
            names = scene.light_sets[lset]
        else:
            raise loc.error(loc.find("objects", *(["lights"] if "lights" in obj else []), nth=i),
                            f"object '{oname}' needs lights = a light set name", 'write lights = "outdoor"')
        m = scene.materials[mat]
        dyn = scene.dynamic_sets.get(lset)
        if dyn is None:
            keys = tuple(LightKey(scene.lights[n].type, scene.lights[n].shadow) for n in names)
            origin = Origin(parts[mat] + tuple((f"light{k}", parts[f"light:{n}"]) for k, n in enumerate(names)))
        else:  # the set's model: one loop per pair, whatever the number of lights
            keys = dyn.model
            set_at = at("light_sets", lset, "model" if "model" in data["light_sets"][lset] else "lights")
            origin = Origin(parts[mat] + tuple((f"light{k}", set_at) for k in range(len(keys))))
        env = scene.environment_of.get(lset)
        if env is not None:  # the environment's brick is an axis of the key; its image is the set's data
            origin = Origin(origin.parts + (("environment", Where(shown, *scene.environment_at[lset])),))
        perm = Permutation(m.brdf, keys, m.packing, output, precision, m.surface, origin,
                           scene.environments[env].brick if env is not None else "")
        if env is not None and perm not in hashes:
            _check_environment(loc, perm, lib, mat, env, lset)
        h = hashes.get(perm)
        if h is None:  # the first object of a permutation: where messages about it will point
            h = hashes[perm] = perm.hash
            scene.permutations.setdefault(h, perm)
            scene.where.setdefault(h, loc.find("objects", "material", nth=i))
        scene.users.setdefault(h, []).append(oname)
        scene.objects.append({"name": oname, "material": mat, "light_set": lset, "lights": names, "permutation": h})
    return scene


def _check_environment(loc: Locator, perm: Permutation, lib: Library, mat: str, env: str, lset: str) -> None:
    """A material an environment lights needs a BRDF whose terms it can light (spec/ambient.py): refused at the
    material's brdf, naming the material, the environment and the light set."""
    for part, what, todo in resolve(perm, lib).problems:
        if part == "brdf":
            raise loc.error(loc.find(f"materials.{mat}", "brdf"), f"material '{mat}', lit by environment '{env}' "
                            f"(light set '{lset}'): {what}", todo)


SURFACE_KEYS = ("alpha", "double_sided", "vertex_color", "emissive")  # a material's surface state (spec/surface.py)


def surface_specs(r: Resolved, error) -> dict:
    """A resolved material's parameter specs: its bricks' as one group and those its surface state reads
    (spec/surface.py); error(key, what, todo) makes the exception for a surface state the material's bricks
    cannot take (the resolved verdict: vertex colours need the BRDF's own rho_d, the state's names are not
    the bricks')."""
    for part, what, todo in r.problems:
        if part != "packing":
            raise error(part, what, todo)
    return {**r.material_params, **r.surface_params}


def _table(loc: Locator, data: dict, key: str) -> dict:
    t = data.get(key, {})
    if not isinstance(t, dict):
        raise loc.error(loc.top(key), f"'{key}' must be a table", f"write [{key}.NAME] sections")
    return t


def _one(spec: str, nodes: list, what: str) -> list:
    """The one brick a packing or shadow spec names; a second term ('shadow_map+none') is an error, not dropped."""
    if len(nodes) != 1:
        plus = spec.find("+")
        raise SpecError(spec, plus + 1 if plus >= 0 else 1, f"a {what} is one brick, and '{spec}' names {len(nodes)}",
                        f"keep one: {nodes[0].canonical()}")
    return nodes


def _spec(loc: Locator, header: str, key: str, value, resolve) -> str:
    where = loc.find(header, key)
    if not isinstance(value, str):
        raise loc.error(where, f"{key} must be a spec string", 'write e.g. "lambert+blinn_phong_normalized"')
    try:
        return resolve(value)
    except SpecError as e:
        line, col = where
        text = loc.lines[line - 1] if 0 < line <= len(loc.lines) else ""
        q = text.find('"', col - 1)
        col = q + 1 + e.col if q >= 0 else col
        raise loc.error((line, col), e.message, e.hint) from None


def _check_params(loc: Locator, header: str, params, specs: dict, owner: str) -> None:
    """Scene values against the one parameter policy (spec/params.py)."""
    if not isinstance(params, dict):
        raise loc.error(loc.find(header, "params"), "params must be a table", "write params = { n = 64.0 }")
    for k, v in params.items():
        where = loc.find(header, "params", k)
        if k not in specs:
            close = difflib.get_close_matches(k, list(specs), n=1)
            hint = f"did you mean '{close[0]}'? " if close else ""
            raise loc.error(where, f"unknown parameter '{k}' for {owner}",
                            f"{hint}its parameters: {', '.join(specs) or 'none'}")
        problem = specs[k].check(v)
        if problem:
            raise loc.error(where, f"parameter '{k}': {problem}", "see `shadermatrix bricks` for types and ranges")
