"""KHR_lights_punctual lights → the scene's lights and light sets.

The lights instanced by nodes become the scene's lights (one Light per node instance, shadow "none"):
directional → `directional` (direction = the node's +Z, towards the light), point → `point_range`
(radius = range) or `point` (no range), spot → `spot` (position, direction = the node's −Z, radius =
range or 1e6 when absent, inner_angle/outer_angle = innerConeAngle/outerConeAngle). color = color ·
intensity (the bricks' "game intensity"; candela / lux are taken as is). Each glTF scene is one light set
(its lights in node order, at most MAX_LIGHTS_PER_SET), and every mesh node of that scene uses it. A light
is named from its definition, else its node, else `light<k>` (scene/gltf_names.py); an error about it is
at its definition, `/extensions/KHR_lights_punctual/lights/<k>`. A lights file beside the scene
(SCENE.lights.toml, scene/gltf_sidecar.py) then gives lights shadow filters and may make the sets dynamic.
"""
from __future__ import annotations

import math

import numpy as np

from ..library.bricks import Library
from ..spec.permutation import parse_spec
from ..spec.resolve import light_params
from .gltf_names import clean, free_name
from .gltf_read import Reader
from .jsonpos import pointer
from .load import Light, Scene

MAX_LIGHTS_PER_SET = 32  # as scene/load.py: a specialized shader unrolls its lights
SPOT_NO_RANGE = 1.0e6  # a spot light without `range` (infinite in glTF): the spot brick's largest radius
LIGHTS = "/extensions/KHR_lights_punctual"  # where the file defines its lights


class LightSets:
    """The file's KHR_lights_punctual lights, mapped into scene.lights as the scenes' nodes instance them."""

    def __init__(self, rd: Reader, lib: Library, scene: Scene):
        self.rd, self.lib, self.scene = rd, lib, scene
        lights_def = rd.get(rd.get(rd.raw, "extensions", "", "obj", {}), "KHR_lights_punctual", "/extensions", "obj", {})
        self.defs = rd.get(lights_def, "lights", LIGHTS, "arr", [])
        self.names: set[str] = set()
        self.ptrs: dict[str, str] = {}  # light name -> the pointer of its KHR_lights_punctual definition

    def of_scene(self, si: int, instances: list, limit: bool = True) -> list[str]:
        """The names of the lights glTF scene si's node instances carry, in node order (its light set); limit:
        at most MAX_LIGHTS_PER_SET (a static set; a dynamic one, by the lights file, holds up to its max)."""
        rd, klights = self.rd, self.defs
        nodes = rd.array("nodes")
        members = []
        for ni, world in instances:
            ext = nodes[ni].get("extensions")
            if not isinstance(ext, dict) or "KHR_lights_punctual" not in ext:
                continue
            nptr = pointer("nodes", ni, "extensions", "KHR_lights_punctual")
            li = rd.get(ext, "KHR_lights_punctual", pointer("nodes", ni, "extensions"), "obj")
            k = rd.get(li, "light", nptr, "int")
            if not 0 <= k < len(klights):
                raise rd.err(f"{nptr}/light", f"light {k} does not exist ({len(klights)} lights in {LIGHTS}/lights)",
                             f"use an index from 0 to {len(klights) - 1}" if klights else f"define it in {LIGHTS}/lights")
            base = (klights[k].get("name") if isinstance(klights[k], dict) and isinstance(klights[k].get("name"), str)
                    and klights[k].get("name") else nodes[ni].get("name") if isinstance(nodes[ni].get("name"), str)
                    and nodes[ni].get("name") else f"light{k}")
            lname = free_name(clean(base), self.names)
            self.names.add(lname)
            self.scene.lights[lname] = light(rd, self.lib, klights[k], f"{LIGHTS}/lights/{k}", lname, world)
            self.ptrs[lname] = f"{LIGHTS}/lights/{k}"
            members.append(lname)
        if limit and len(members) > MAX_LIGHTS_PER_SET:
            raise rd.err(pointer("scenes", si), f"scene {si} has {len(members)} lights, more than the "
                         f"{MAX_LIGHTS_PER_SET} a specialized shader takes (its lights are unrolled)",
                         f"split it into scenes of at most {MAX_LIGHTS_PER_SET} lights, or make its lights "
                         "dynamic in SCENE.lights.toml ([light_set] dynamic = true)")
        return members


def light(rd: Reader, lib: Library, L, ptr: str, name: str, world: np.ndarray) -> Light:
    """Light definition L (at ptr), instanced by a node whose world matrix is `world`, as Light `name`."""
    if not isinstance(L, dict):
        raise rd.err(ptr, "must be a JSON object", "each light is an object")
    ltype = rd.get(L, "type", ptr, "str")
    color = rd.nums(L, "color", ptr, 3, [1.0, 1.0, 1.0], 0.0, None)
    intensity = rd.num(L, "intensity", ptr, 1.0, 0.0, None)
    rng = rd.num(L, "range", ptr, None, 0.0, None) if "range" in L else None
    if rng is not None and rng <= 0:
        raise rd.err(f"{ptr}/range", "range must be greater than 0", "remove it (infinite) or give a positive range")
    c = [x * intensity for x in color]
    pos = [float(x) for x in world[:3, 3]]
    axis = world[:3, :3] @ np.array([0.0, 0.0, -1.0])  # the light shines along its node's −Z
    norm = float(np.linalg.norm(axis))
    if norm < 1e-12 and ltype in ("directional", "spot"):
        raise rd.err(ptr, f"light '{name}' has a degenerate node transform (its −Z axis has length 0)",
                     "give the light's node a non-zero scale")
    axis = [float(x) / (norm or 1.0) for x in axis]
    if ltype == "directional":
        brick, params = "directional", {"direction": [-a for a in axis], "color": c}
    elif ltype == "point":
        brick, params = ("point", {"position": pos, "color": c}) if rng is None else \
            ("point_range", {"position": pos, "color": c, "radius": rng})
    elif ltype == "spot":
        sp = rd.get(L, "spot", ptr, "obj", {})
        inner = rd.num(sp, "innerConeAngle", f"{ptr}/spot", 0.0, 0.0, math.pi / 2)
        outer = rd.num(sp, "outerConeAngle", f"{ptr}/spot", math.pi / 4, 0.0, math.pi / 2)
        if inner >= outer:
            raise rd.err(f"{ptr}/spot/innerConeAngle", f"innerConeAngle {inner} is not below outerConeAngle {outer}",
                         "make innerConeAngle < outerConeAngle")
        lim = 1.5707963  # the spot brick's range: π/2 rounded down to float32
        brick, params = "spot", {"position": pos, "direction": axis, "color": c,
                                 "radius": rng if rng is not None else SPOT_NO_RANGE,
                                 "inner_angle": min(inner, lim), "outer_angle": min(outer, lim)}
    else:
        raise rd.err(f"{ptr}/type", f"'{ltype}' is not a KHR_lights_punctual type", "use directional, point or spot")
    return _checked(rd, lib, ptr, name, brick, params)


def _checked(rd: Reader, lib: Library, ptr: str, name: str, brick: str, params: dict) -> Light:
    """The Light, once the library has its brick (and shadow 'none') and the brick takes every parameter."""
    lb = lib.get("light", brick)
    snode = parse_spec("none", lib, ("shadow",))[0] if lib.get("shadow", "none") is not None else None
    if lb is None or snode is None:
        raise rd.err(ptr, f"light brick '{brick}' (or shadow 'none') is missing from the library",
                     "use the standard bricks")
    specs = light_params(lib, brick, "none")
    for k, v in params.items():
        problem = specs[k].check(v) if k in specs else f"no parameter '{k}'"
        if problem:
            raise rd.err(ptr, f"light '{name}' maps to {brick} parameter '{k}' = {v}: {problem}",
                         "fix the light's color, intensity, range or node transform")
    return Light(name, brick, "none", params)
