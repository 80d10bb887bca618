"""What manifest.json tells an engine: per permutation its Interface, per material and light set its values.

The Interface (link/interface.py) is the reflection: blocks with members, offsets, sizes and
types, textures with set, binding, dimension and color space (a texture2d_shadow: a depth format and a
comparison sampler), vertex inputs with locations and formats, interpolants, entry points, and for
every parameter where the engine writes it.
The scene's values are written beside it: per material and per light the named values
(defaults filled in), and per (permutation, material, light set) the blocks ready to upload,
laid out by that permutation's Interface (little-endian float32, hex).
Each platform spells the Interface in its own binding model (platforms.py: each platform's ``reflection``).
"""
from __future__ import annotations

from ..link.values import light_values, material_values
from ..scene.light_sets import light_indices
from ..scene.load import Scene


def scene_tables(scene: Scene, interfaces: dict, previous: dict | None = None) -> dict:
    """Named materials, lights, light sets and objects, with every value an engine uploads.

    `interfaces`: permutation hash -> Composed (with .interface, .material, .lights slots). `previous`: the
    manifest of the last build; an object whose permutation was kept (not composed: its key, which covers
    its materials' and lights' values, is unchanged) takes its material's and lights' entries from there.
    """
    materials, lights = {}, {}
    old_m, old_l = (previous or {}).get("materials", {}), (previous or {}).get("lights", {})
    for obj in scene.objects:
        c = interfaces.get(obj["permutation"])
        if c is None:
            if obj["material"] in old_m:
                materials.setdefault(obj["material"], old_m[obj["material"]])
            for ln in obj["lights"]:
                if ln in old_l:
                    lights.setdefault(ln, old_l[ln])
            continue
        iface = c.interface
        m = scene.materials[obj["material"]]
        specs = {s.param: s.spec for s in c.material if s.spec is not None}
        materials.setdefault(m.name, {"brdf": m.brdf, "packing": m.packing,
                                      "params": material_values(scene, m.name, specs)})
        for i, ln in light_indices(scene, obj):  # a dynamic set's light: its pair's loop reads it
            lspecs = iface.params.get(f"light{i}", {})
            L = scene.lights[ln]
            lights.setdefault(ln, {"type": L.type, "shadow": L.shadow, "params": light_values(scene, ln, lspecs)})
    return {"materials": dict(sorted(materials.items())), "lights": dict(sorted(lights.items())),
            "light_sets": {k: list(v) for k, v in sorted(scene.light_sets.items())},
            "objects": [{"name": o["name"], "material": o["material"], "light_set": o["light_set"],
                         "permutation": o["permutation"]} for o in scene.objects]}

