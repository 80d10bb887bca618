"""A scene's light sets: a static set lists its lights (the key lists them, in order); a dynamic set is a table.

    [light_sets]
    outdoor = ["sun"]                 # static: every light is unrolled in the shader, at most MAX_LIGHTS_PER_SET

    [light_sets.crowd]                # dynamic: one loop per type/shadow-filter pair over a storage buffer
    dynamic = true
    lights = ["lamp0", "lamp1"]       # the lights it holds (any number up to max)
    max = 64                          # the capacity of its buffers (what an engine allocates); default 256
    model = ["point/none"]            # optional: the pairs a light of it may be; default: its lights' pairs
    loop = "types"                    # optional: "types" (default), one loop per pair over its own buffer;
                                      # "switch", one loop over one buffer of every light, switching on the pair
    culling = "tiles"                 # optional: "none" (default), each loop reads every light of its buffer;
                                      # "tiles", each loop reads its fragment's screen tile's list of indices
                                      # into the buffer (the LightTiles buffer an engine's light culling fills)

The permutation key of an object lit by a dynamic set carries the set's model (sorted dynamic LightKeys,
`lights=*point/none,*spot/none`; with loop = "switch" `lights=**point/none,**spot/none`), not its lights: any
number of lights of those pairs is one shader per material; culling = "tiles" marks each pair `@tiles`
(`lights=*point/none@tiles`): another shader, whose loops read the tile's index list (link/tiles.py tiled_loop).
Why "types" is the default: docs/design/link.md,
"Which light loop" (measured by benchmarks/lights.py).
Why a model may name pairs no light has yet: an engine adding lights at run time needs the shader that reads
them. A pair whose shadow filter samples a texture reads one 2D array per (pair, filter texture): each light of it
one layer (six for a point light's faces), its first layer in its element; the array holds max × that many layers,
max × layers × size² × 4 bytes of depth (16 for vsm's moments), so max × layers above MAX_SHADOW_LAYERS is refused
here, at the set's max, as are a shadowed pair of a switch loop and a light brick that samples a texture itself.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass

from ..library.bricks import Library
from ..spec.permutation import LightKey, SpecError, canonical, parse_spec
from .locate import Locator

MAX_LIGHTS_PER_SET = 32  # measured: 40 shadowed point lights compile, 64 exceed SPIR-V's 255 function arguments
DEFAULT_MAX = 256  # a dynamic set's buffer capacity when the scene gives none
MAX_DYNAMIC = 1 << 16  # a dynamic set's largest capacity: what an engine allocates per pair must stay sane
LOOPS = ("types", "switch")  # a dynamic set's light loop; the first is the default
CULLINGS = ("none", "tiles")  # what a dynamic set's loops read: every light of a buffer (the default), or a tile's
CUBE_TYPES = ("point", "point_range")  # the light bricks whose shadow is six faces (link/faces.py)
MAX_SHADOW_LAYERS = 2048  # Vulkan's guaranteed minimum maxImageArrayLayers: the most layers of a pair's shadow array


@dataclass(frozen=True)
class DynamicSet:
    """A dynamic light set: its model (the key's sorted dynamic LightKeys) and its buffers' capacity."""

    name: str
    model: tuple  # (LightKey(dynamic=True), ...) sorted by canonical text
    max: int  # the capacity of each pair's buffer (loop "switch": of its one buffer), in lights
    loop: str = LOOPS[0]  # "types": a loop per pair; "switch": one loop, a switch on the pair (LOOPS)
    culling: str = CULLINGS[0]  # "tiles": each loop reads the fragment's tile's index list (CULLINGS)

    def pair_of(self, light) -> int:
        """The index in the model (the permutation's light index) of a scene Light."""
        return self.model.index(self.key(light.type, light.shadow))

    def key(self, light_type: str, shadow: str) -> LightKey:
        """The model's LightKey of pair light_type/shadow, marked as the set's loop and culling mark it."""
        return LightKey(light_type, shadow, True, self.loop == "switch", self.culling == "tiles")


def set_keys(scene, name: str) -> tuple:
    """The permutation key's lights for light set `name`: a static set's lights in order, a dynamic set's model."""
    dyn = scene.dynamic_sets.get(name)
    if dyn is not None:
        return dyn.model
    return tuple(LightKey(scene.lights[n].type, scene.lights[n].shadow) for n in scene.light_sets[name])


def light_indices(scene, obj) -> list[tuple[int, str]]:
    """(permutation light index, light name) for every light of an object: a static set's lights are the key's
    lights in order; a dynamic set's light is read by the loop of its type/filter pair."""
    dyn = scene.dynamic_sets.get(obj["light_set"])
    if dyn is None:
        return list(enumerate(obj["lights"]))
    return [(dyn.pair_of(scene.lights[n]), n) for n in obj["lights"]]


def dynamic_set(loc: Locator, name: str, t: dict, scene, lib: Library, header: tuple) -> None:
    """Make light set `name` (its lights already in scene.light_sets) dynamic by table t, found at `header`."""
    _dynamic(loc, name, t, scene, lib, header, scene.light_sets[name])


def read_light_sets(loc: Locator, data: dict, scene, lib: Library) -> None:
    """Fill scene.light_sets (name -> light names) and scene.dynamic_sets from [light_sets]; located errors."""
    table = data.get("light_sets", {})
    if not isinstance(table, dict):
        raise loc.error(loc.top("light_sets"), "'light_sets' must be a table", "write [light_sets] NAME = [\"sun\"]")
    for name, value in table.items():
        where = loc.find("light_sets", name)
        if isinstance(value, dict):
            members = _dynamic(loc, name, value, scene, lib)
        else:
            members = value
            if not isinstance(members, list) or not all(isinstance(x, str) for x in members):
                raise loc.error(where, f"light set '{name}' must be a list of light names", 'write outdoor = ["sun"]')
            if len(members) > MAX_LIGHTS_PER_SET:
                raise loc.error(where, f"light set '{name}' has {len(members)} lights, more than the "
                                f"{MAX_LIGHTS_PER_SET} a specialized shader takes (its lights are unrolled: every "
                                "light adds arguments, and SPIR-V allows a function 255)",
                                f"split it into sets of at most {MAX_LIGHTS_PER_SET}, or make it dynamic "
                                f"([light_sets.{name}] dynamic = true, lights = [...])")
            _known(loc, where, name, members, scene)
        scene.light_sets[name] = list(members)


def _known(loc: Locator, where, name: str, members: list, scene) -> None:
    for x in members:
        if x not in scene.lights:
            raise loc.error(where, f"light set '{name}' names unknown light '{x}'",
                            f"lights: {', '.join(scene.lights) or 'none defined'}")


def _dynamic(loc: Locator, name: str, t: dict, scene, lib: Library, header: tuple = (), given=None) -> list:
    """A dynamic set's lights; records its DynamicSet in scene.dynamic_sets. header: where its table is, the
    keys before its own (a scene's ("light_sets", name), the default; a glTF sidecar's ("light_set",));
    given: its lights when the table does not list them (a glTF scene's)."""
    header = header or ("light_sets", name)

    def at(key):
        return loc.find(*header, key)
    if t.get("dynamic") is not True:
        raise loc.error(at("dynamic") if "dynamic" in t else loc.find(*header),
                        f"light set '{name}' is a table, which only a dynamic set is",
                        f"add dynamic = true, or write a static set as a list: {name} = [\"sun\"]")
    listed, t = t, {"lights": [], **t, **({"lights": given} if given is not None else {})}
    members = t["lights"]
    _known(loc, at("lights"), name, members, scene)
    if len(set(members)) != len(members):
        twice = next(x for x in members if members.count(x) > 1)
        raise loc.error(at("lights"), f"light set '{name}' holds light '{twice}' twice", "list each light once")
    if "model" in t:
        model = tuple(_model_entry(loc, at("model"), name, e, lib) for e in t["model"])
        if len(set(model)) != len(model):
            raise loc.error(at("model"), f"light set '{name}': its model names a pair twice", "name each pair once")
        if not model:
            raise loc.error(at("model"), f"dynamic light set '{name}' has an empty model",
                            'give the pairs its lights may be: model = ["point/none"]')
    else:
        model = tuple(dict.fromkeys(LightKey(scene.lights[n].type, scene.lights[n].shadow, True) for n in members))
        if not model:
            raise loc.error(loc.find(*header), f"dynamic light set '{name}' has no lights and no model",
                            'give the pairs its lights may be: model = ["point/none"]')
    loop = _choice(loc, at, name, t, "loop", LOOPS, "\"types\" loops over each pair's buffer, \"switch\" over one "
                   "buffer, switching on the pair")
    culling = _choice(loc, at, name, t, "culling", CULLINGS, "\"none\" reads every light of a pair's buffer, "
                      "\"tiles\" the fragment's screen tile's list (LightTiles, filled by the engine's culling)")
    if culling == "tiles" and loop == "switch":
        raise loc.error(at("culling"), f"light set '{name}': culling = \"tiles\" reads one index list per pair, and "
                        "a switch loop has one loop for every pair", 'use loop = "types" with culling = "tiles"')
    proto = DynamicSet(name, (), 1, loop, culling)
    model = tuple(sorted((proto.key(k.light, k.shadow) for k in model), key=LightKey.canonical))
    for n in members:
        light = scene.lights[n]
        if proto.key(light.type, light.shadow) not in model:
            raise loc.error(at("lights" if "lights" in listed else "model"),
                            f"light '{n}' ({light.type}/{light.shadow}) is not in the model of dynamic light set "
                            f"'{name}' ({', '.join(f'{k.light}/{k.shadow}' for k in model)})",
                            f"add \"{light.type}/{light.shadow}\" to its model, or move '{n}' to another set")
    where = at("model") if "model" in t else at("lights")
    cap = t.get("max", DEFAULT_MAX)
    if not 1 <= cap <= MAX_DYNAMIC:
        raise loc.error(at("max"), f"light set '{name}': max is {cap}, not between 1 and {MAX_DYNAMIC}",
                        f"give the capacity its buffers are allocated for, e.g. max = {DEFAULT_MAX}")
    for k in model:
        _shadow_capacity(loc, at("max") if "max" in t else where, name, k, cap, lib)
    if cap < len(members):
        raise loc.error(at("max"), f"light set '{name}' holds {len(members)} lights, more than its max = {cap}",
                        f"raise max to at least {len(members)}")
    scene.dynamic_sets[name] = DynamicSet(name, model, cap, loop, culling)
    return members


def shadow_layers(light_type: str) -> int:
    """The shadow-map array layers one buffer light of `light_type` takes: six faces for a point light, else one."""
    return 6 if light_type in CUBE_TYPES else 1


def _shadow_capacity(loc: Locator, where, name: str, k: LightKey, cap: int, lib: Library) -> None:
    """Refuse a pair whose lights a buffer cannot shadow: a light brick that samples a texture, a shadowed pair of a
    switch loop, or one whose array (cap × its layers) would exceed MAX_SHADOW_LAYERS."""
    sampled = _texture_of(lib, k)
    if not sampled:
        return
    light = lib.get("light", k.light)
    if light is not None and light.textures:
        raise loc.error(where, f"light set '{name}': a light in a buffer cannot bind its brick's texture "
                        f"({k.light} samples '{sampled}')", "use a static set for it")
    if k.switch:
        raise loc.error(where, f"light set '{name}': a switch loop cannot shadow its lights yet ({k.light}/{k.shadow} "
                        f"samples '{sampled}')", 'use loop = "types" for shadowed lights, or shadow none')
    layers = cap * shadow_layers(k.light)
    if layers > MAX_SHADOW_LAYERS:
        most = MAX_SHADOW_LAYERS // shadow_layers(k.light)
        raise loc.error(where, f"light set '{name}': {k.light}/{k.shadow} lights take {layers} shadow-map layers at "
                        f"max = {cap} ({shadow_layers(k.light)} each), more than the {MAX_SHADOW_LAYERS} every Vulkan "
                        "device allows in one array (maxImageArrayLayers)", f"lower max to at most {most}")


def _choice(loc: Locator, at, name: str, t: dict, key: str, choices: tuple, what: str) -> str:
    """The set's `key`, one of choices, the first by default (a located error with the closest one otherwise)."""
    value = t.get(key, choices[0])
    if value not in choices:
        near = difflib.get_close_matches(str(value), choices, n=1)
        raise loc.error(at(key), f"light set '{name}': {key} is {value!r}, not one of {', '.join(choices)}",
                        (f"did you mean {key} = \"{near[0]}\"? " if near else "") + what)
    return value


def _model_entry(loc: Locator, where, name: str, entry: str, lib: Library) -> LightKey:
    """One `type/shadow` pair of a model, checked against the library (a malformed entry is a located error)."""
    ltype, slash, shadow = entry.partition("/")
    if not slash or not ltype or not shadow:
        raise loc.error(where, f"light set '{name}': model entry {entry!r} is not TYPE/SHADOW",
                        'write e.g. model = ["point/none", "spot/none"]')
    if lib.get("light", ltype) is None:
        raise loc.error(where, f"light set '{name}': model entry {entry!r} names unknown light type '{ltype}'",
                        f"type is one of {', '.join(b.id for b in lib.of_kind('light'))}")
    try:
        nodes = parse_spec(shadow, lib, ("shadow",))
    except SpecError as e:
        raise loc.error(where, f"light set '{name}': model entry {entry!r}: {e.message}", e.hint) from None
    if len(nodes) != 1:
        raise loc.error(where, f"light set '{name}': model entry {entry!r} names {len(nodes)} shadow filters",
                        "a pair is one light type and one shadow filter")
    return LightKey(ltype, canonical(nodes), True)


def _texture_of(lib: Library, k: LightKey) -> str:
    """The first texture a pair's light brick or shadow filter samples ('' when none)."""
    light = lib.get("light", k.light)
    if light is not None and light.textures:
        return next(iter(light.textures))
    for n in parse_spec(k.shadow, lib, ("shadow",)):
        if n.textures:
            return next(iter(n.textures))
    return ""
