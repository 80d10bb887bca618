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

from ..link.faces import FIRST_LAYER, shadow_layers
from ..link.values import is_switch, light_buffer_of, light_values, material_values
from ..scene.light_sets import light_indices
from ..scene.load import Scene


def scene_tables(scene: Scene, interfaces: dict, previous: dict | None = None, platforms=()) -> dict:
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
    dynamic = dynamic_tables(scene, interfaces, previous, platforms)
    return {"materials": dict(sorted(materials.items())), "lights": dict(sorted(lights.items())),
            "light_sets": {k: list(v) for k, v in sorted(scene.light_sets.items())},
            **({"dynamic_light_sets": dynamic} if dynamic else {}),
            "objects": [{"name": o["name"], "material": o["material"], "light_set": o["light_set"],
                         "permutation": o["permutation"]} for o in scene.objects]}



FILL = ("per pair, the set's lights of that type and shadow filter, in the set's order: element k at k x stride, "
        "each parameter at its offset (little-endian float32; a vector parameter fills its components), zeros "
        "elsewhere; bind the first count x stride bytes of a buffer of max x stride: the shader's light count is "
        "the bound range / stride (no light: bind a range below the stride, e.g. 4 bytes)")


FILL_SWITCH = ("one buffer for every pair (each pair's block is the same): pair after pair in the pairs' order, "
               "from element first, the set's lights of that pair in the set's order; element k at k x stride holds "
               "ids (int32 x4: the pair's id, 0, 0, 0) at offset 0, then each parameter at its offset (little-endian "
               "float32), zeros elsewhere; bind the first count x stride bytes of a buffer of max x stride, count "
               "all pairs' lights (no light: bind a range below the stride, e.g. 4 bytes)")


FILL_TILES = ("every frame, from the engine's light culling: a flat array of uint32 words, words 0-3 tiles_x, "
              "tiles_y, tile_size (pixels, the engine's choice) and pairs (the key's pair count); then per tile t = x + "
              "y x tiles_x (x = min(floor(pixel x / tile_size), tiles_x - 1), y likewise; a 0 in tiles_x, tiles_y or "
              "tile_size reads as 1), from the framebuffer origin the API gives "
              "the fragment's coordinate: top left in Vulkan, D3D and WebGPU, bottom left in OpenGL) and per pair i, "
              "at word 4 + 2 (t x pairs + i), its list's offset (a word index into this buffer) and count; then the "
              "lists, each word an element of pair i's buffer. A light may be in more tiles than it reaches, never "
              "fewer (every light in every tile, tiles_x = tiles_y = 1, draws what the untiled loop draws)")


def _tiles(c, platforms) -> dict:
    """The LightTiles block of a tiled set's permutation: where it binds, per platform too (link/tiles.py)."""
    from ..link.tiles import TILES_BLOCK
    from .platforms import PLATFORM_TABLE
    block = c.interface.block(TILES_BLOCK)
    bindings = {p: next({k: v for k, v in row.items() if k not in ("name", "stages", "visibility")}
                        for rows_ in PLATFORM_TABLE[p].reflection(c.interface).values() if isinstance(rows_, list)
                        for row in rows_ if isinstance(row, dict) and row.get("name") == TILES_BLOCK)
                for p in platforms}
    return {"block": TILES_BLOCK, "set": block.set, "binding": block.binding, "bindings": bindings,
            "header_words": 4, "record_words": 2, "fill": FILL_TILES}


def dynamic_tables(scene: Scene, interfaces: dict, previous: dict | None, platforms) -> dict:
    """Per dynamic light set: its capacity and, per pair of its model, the storage buffer an engine fills.

    The block, its layout and its bindings are those of every permutation the set lights (a dynamic set's
    permutations have its model as their lights, so the builder places the buffers alike: link.link_permutation);
    read from the first composed one, or from the last build's manifest when none was composed this time."""
    from .platforms import PLATFORM_TABLE
    old = (previous or {}).get("dynamic_light_sets", {})
    out = {}
    for name, dyn in sorted(scene.dynamic_sets.items()):
        c = next((interfaces[o["permutation"]] for o in scene.objects
                  if o["light_set"] == name and o["permutation"] in interfaces), None)
        members = scene.light_sets[name]

        def lights_of(i, members=members, dyn=dyn):  # the set's lights of pair i, in its order
            return [n for n in members if dyn.pair_of(scene.lights[n]) == i]
        def first_of(i, dyn=dyn, lights_of=lights_of):  # a switch buffer: where pair i's lights start
            return sum(len(lights_of(k)) for k in range(i)) if dyn.loop == "switch" else None

        def layers_of(i, layout, dyn=dyn, lights_of=lights_of):  # a shadowed pair: its lights' first layers, here
            if not any(sl["name"] == FIRST_LAYER for sl in layout):
                return {}
            return {"first_layers": [k * shadow_layers(dyn.model[i].light) for k in range(len(lights_of(i)))]}
        if c is None:  # its blocks as the last build described them; its capacity and lights as the scene says now
            if name in old:
                out[name] = {**old[name], "max": dyn.max, "fill": FILL_SWITCH if dyn.loop == "switch" else FILL, "pairs": [
                    {**{k: v for k, v in p.items() if k != "first_layers"}, "lights": lights_of(p["light_index"]),
                     **({"first": first_of(p["light_index"])} if "first" in p else {}),
                     **layers_of(p["light_index"], p["layout"])} for p in old[name]["pairs"]]}
            continue
        pairs = []
        for i, pair in enumerate(dyn.model):
            block = light_buffer_of(c.interface, i)
            stride = block.members[0]["array_stride"]
            switch = {"id": i, "first": first_of(i)} if is_switch(block) else {}
            bindings = {}
            for p in platforms:
                rows = PLATFORM_TABLE[p].reflection(c.interface)
                bindings[p] = next({k: v for k, v in row.items() if k not in ("name", "stages", "visibility")}
                                   for rows_ in rows.values() if isinstance(rows_, list) for row in rows_
                                   if isinstance(row, dict) and row.get("name") == block.name)
            layout = [{k: v for k, v in sl.as_dict().items() if k in ("name", "type", "offset", "size")}
                      for sl in block.slots if sl.light == i]
            pairs.append({"pair": pair.canonical(), "light_index": i, "block": block.name, "set": block.set,
                          "binding": block.binding, "bindings": bindings, "stride": stride, "layout": layout,
                          "lights": lights_of(i), **switch, **layers_of(i, layout)})
        out[name] = {"max": dyn.max, "pairs": pairs, "fill": FILL_SWITCH if dyn.loop == "switch" else FILL,
                     **({"loop": dyn.loop} if dyn.loop != "types" else {}),
                     **({"culling": dyn.culling, "tiles": _tiles(c, platforms)} if dyn.culling == "tiles" else {})}
    return out
