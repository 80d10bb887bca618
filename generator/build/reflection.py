"""What manifest.json tells an engine: per permutation its Interface, per material and light set its values.

The Interface (link/interface.py) is the reflection: blocks with members, offsets, sizes and
types, textures with set, binding, dimension and color space, vertex inputs with locations and
formats, interpolants, entry points, and for every parameter where the engine writes it.
The scene's values are written beside it: per material and per light the named values
(defaults filled in), and per (permutation, material, light set) the blocks ready to upload,
laid out by that permutation's Interface (little-endian float32, hex).
"""
from __future__ import annotations

from ..link.interface import pack
from ..matrix.scene import Scene


def material_values(scene: Scene, name: str, specs: dict) -> dict:
    """A material's parameters by name: the scene's values, the bricks' defaults for the rest."""
    given = scene.materials[name].params
    return {k: given.get(k, s.default) for k, s in specs.items()}


def light_values(scene: Scene, name: str, specs: dict) -> dict:
    given = scene.lights[name].params
    return {k: given.get(k, s.default) for k, s in specs.items()}


def scene_tables(scene: Scene, interfaces: dict) -> dict:
    """Named materials, lights, light sets and objects, with every value an engine uploads.

    `interfaces`: permutation hash -> Composed (with .interface, .material, .lights slots).
    """
    materials, lights = {}, {}
    for obj in scene.objects:
        c = interfaces.get(obj["permutation"])
        if c is None:
            continue
        iface = c.interface
        m = scene.materials[obj["material"]]
        specs = {s.param: s.spec for s in c.material if s.spec is not None}
        materials.setdefault(m.name, {"brdf": m.brdf, "packing": m.packing,
                                      "params": material_values(scene, m.name, specs)})
        for i, ln in enumerate(obj["lights"]):
            lspecs = iface.params.get(f"light{i}", {})
            L = scene.lights[ln]
            lights.setdefault(ln, {"type": L.type, "shadow": L.shadow, "params": light_values(scene, ln, lspecs)})
    return {"materials": dict(sorted(materials.items())), "lights": dict(sorted(lights.items())),
            "light_sets": {k: list(v) for k, v in sorted(scene.light_sets.items())},
            "objects": [{"name": o["name"], "material": o["material"], "light_set": o["light_set"],
                         "permutation": o["permutation"]} for o in scene.objects]}


def uploads(scene: Scene, h: str, c) -> list[dict]:
    """Per (material, light set) drawn with permutation `h`: the Material and Lights blocks, ready to upload."""
    out, seen = [], set()
    for obj in scene.objects:
        if obj["permutation"] != h or (obj["material"], obj["light_set"]) in seen:
            continue
        seen.add((obj["material"], obj["light_set"]))
        mvals = material_values(scene, obj["material"], {s.param: s.spec for s in c.material if s.spec is not None})
        values = {s.name: _element(mvals[s.param], s) for s in c.material}
        item = {"material": obj["material"], "light_set": obj["light_set"], "objects": []}
        mat = c.interface.block("Material")
        if mat is not None:
            item["Material"] = pack(c.material, values, mat.members[-1]["size"] // 16).hex()
        lb = c.interface.block("Lights")
        if lb is not None:
            lvals = {}
            for i, (ln, slots) in enumerate(zip(obj["lights"], c.lights)):
                v = light_values(scene, ln, c.interface.params.get(f"light{i}", {}))
                lvals.update({s.name: _element(v[s.param], s) for s in slots})
            item["Lights"] = pack([s for ls in c.lights for s in ls], lvals, lb.members[-1]["size"] // 16).hex()
        out.append(item)
    for item in out:
        item["objects"] = [o["name"] for o in scene.objects if o["permutation"] == h
                           and (o["material"], o["light_set"]) == (item["material"], item["light_set"])]
    return out


def _element(value, slot):
    """The value a slot holds: an array parameter's element, or the value itself."""
    return value if slot.element is None else value[slot.element]
