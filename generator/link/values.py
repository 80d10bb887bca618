"""Scene values laid out by an Interface: named parameter values and ready-to-upload blocks.

`uploads(scene, h, c)` gives, per (material, light set) drawn with permutation `h`, the
Material and Lights blocks as float32 bytes (hex), laid out by `c`'s Interface; the
manifest writes them and the renderer uploads them.
"""
from __future__ import annotations

from ..matrix.scene import Scene
from .interface import pack


def material_values(scene: Scene, name: str, specs: dict) -> dict:
    """A material's parameters by name: the scene's values, the bricks' defaults for the rest."""
    given = scene.materials[name].params
    return {k: given.get(k, s.default) for k, s in specs.items()}


def light_values(scene: Scene, name: str, specs: dict) -> dict:
    given = scene.lights[name].params
    return {k: given.get(k, s.default) for k, s in specs.items()}


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
