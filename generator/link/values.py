"""Scene values laid out by an Interface: named parameter values and ready-to-upload blocks.

`uploads(scene, h, c)` gives, per (material, light set) drawn with permutation `h`, the
Material and Lights blocks as float32 bytes (hex), laid out by `c`'s Interface, and for a dynamic light
set each pair's storage buffer (`light_buffers`); the manifest writes them and the renderer uploads them. `light_entry` and `entry_bytes` lay out the
ubershader's LightEntry / MaterialEntry storage buffers (link/uber.py).
"""
from __future__ import annotations

import struct

from ..scene.load import Scene
from .faces import FIRST_LAYER, shadow_layers
from .interface import pack, put


def material_values(scene: Scene, name: str, specs: dict) -> dict:
    """A material's parameters by name: the scene's values, the bricks' defaults for the rest."""
    given = scene.materials[name].params
    return {k: given.get(k, s.default) for k, s in specs.items()}


def light_values(scene: Scene, name: str, specs: dict) -> dict:
    given = scene.lights[name].params
    out = {k: given.get(k, s.default) for k, s in specs.items()}
    if FIRST_LAYER in specs:  # a buffer light's first layer in its pair's shadow array (link/faces.py)
        out[FIRST_LAYER] = first_layer(scene, name)
    return out


def first_layer(scene: Scene, name: str) -> float:
    """A buffer light's first layer in its pair's shadow array: its ordinal among the lights of its pair in its
    (first) dynamic set, × its layers (six for a point light's faces)."""
    light = scene.lights[name]
    for set_name, dyn in scene.dynamic_sets.items():
        names = scene.light_sets[set_name]
        if name in names:
            pair = dyn.pair_of(light)
            same = [n for n in names if dyn.pair_of(scene.lights[n]) == pair]
            return float(same.index(name) * shadow_layers(light.type))
    return 0.0


def environment_values(scene: Scene, light_set: str, specs: dict, baked: dict | None = None) -> dict:
    """The values of the environment lighting `light_set` (scene/environments.py), by the brick's names: its
    intensity and the radiance cube's levels from the scene, the SH9 coefficients sh0 … sh8 from `baked`
    ({environment name: {name: value}}, what assemble/environments.py computes from its image), the brick's
    defaults (0) for what is not given."""
    name = scene.environment_of.get(light_set)
    if name is None:
        return {}
    env = scene.environments[name]
    out = {k: s.default for k, s in specs.items()}
    out.update({k: v for k, v in (("intensity", env.intensity), ("radiance_levels", float(env.levels))) if k in specs})
    out.update({k: v for k, v in ((baked or {}).get(name) or {}).items() if k in specs})
    return out


def uploads(scene: Scene, h: str, c, objects: list[dict] | None = None, environments: dict | None = None) -> list[dict]:
    """Per (material, light set) drawn with permutation `h`: the Material and Lights blocks, ready to upload.
    objects: the scene's objects drawn with `h`, when the caller has them grouped (else every object is looked at).
    environments: the baked values of the scene's environments (environment_values), {name: {param: value}}."""
    mine = [o for o in scene.objects if o["permutation"] == h] if objects is None else objects
    out, seen = [], set()
    for obj in mine:
        if (obj["material"], obj["light_set"]) in seen:
            continue
        seen.add((obj["material"], obj["light_set"]))
        mvals = material_values(scene, obj["material"], {s.param: s.spec for s in c.material if s.spec is not None})
        values = {s.name: _element(mvals[s.param], s) for s in c.material}
        item = {"material": obj["material"], "light_set": obj["light_set"], "objects": []}
        mat = c.interface.block("Material")
        if mat is not None:
            item["Material"] = pack(c.material, values, mat.members[-1]["size"] // 16).hex()
        dyn = scene.dynamic_sets.get(obj["light_set"])
        if dyn is not None:
            item["light_buffers"] = {b: data.hex() for b, data in light_buffers(scene, obj["lights"], dyn, c).items()}
        lb = c.interface.block("Lights")
        if lb is not None:
            lvals = {}
            for i, (ln, slots) in enumerate(zip(obj["lights"] if dyn is None else [], c.lights)):
                v = light_values(scene, ln, c.interface.params.get(f"light{i}", {}))
                lvals.update({s.name: _element(v[s.param], s) for s in slots})
            env = getattr(c, "environment", None) or []
            if env:  # the light set's environment: the block's last group (link._pack_values)
                ev = environment_values(scene, obj["light_set"], c.interface.params.get("environment", {}), environments)
                lvals.update({s.name: _element(ev[s.param], s) for s in env})
            item["Lights"] = pack([s for ls in c.lights for s in ls] + list(env), lvals,
                                  lb.members[-1]["size"] // 16).hex()
        out.append(item)
    for item in out:
        item["objects"] = [o["name"] for o in mine
                           if (o["material"], o["light_set"]) == (item["material"], item["light_set"])]
    return out


LIGHT_BUFFER = "LightBuffer"  # the storage blocks of dynamic lights: LightBuffer<i>, the ubershader's LightBuffer


def light_buffer_block(i: int) -> str:
    """The storage block of the key's dynamic light i (link.link_permutation names it)."""
    return f"{LIGHT_BUFFER}{i}"


def light_buffers(scene: Scene, names: list[str], dyn, c, overrides: dict | None = None) -> dict[str, bytes]:
    """Per pair of a dynamic set's model, its storage block's name and bytes: the lights `names` of that pair, in
    their order, each element laid out as the block's parameters say (a static set's values, so both draw alike).
    A switch loop's one block (every pair's block) holds the pairs one after another, in the model's order, each
    element its ids (ids.x the pair's light index, int32) then its values (link/glue.py _switch_buffer).
    A shadowed pair's light k has its first layer k × its layers (first_layer); overrides: {light: {param:
    value}} over the scene's values (the renderer's fitted shadow matrices)."""
    out = {}
    for i, pair in enumerate(dyn.model):
        block = light_buffer_of(c.interface, i)
        stride = block.members[0]["array_stride"]
        specs = c.interface.params.get(f"light{i}", {})
        slots = [s for s in block.slots if s.light == i]
        head = switch_ids(i) if is_switch(block) else b""
        data, ordinal = b"", 0
        for ln in names:
            if dyn.pair_of(scene.lights[ln]) == i:
                v = {**light_values(scene, ln, specs), **(overrides or {}).get(ln, {})}
                if FIRST_LAYER in specs:  # in this set's order (a light of two sets: light_values says the first's)
                    v[FIRST_LAYER], ordinal = float(ordinal * shadow_layers(pair.light)), ordinal + 1
                data += head + pack(slots, {s.name: _element(v[s.param], s) for s in slots}, (stride - len(head)) // 16)
        out[block.name] = out.get(block.name, b"") + data
    return out


def is_switch(block) -> bool:
    """Whether a light buffer's element starts with a switch loop's ids (link/glue.py _switch_buffer)."""
    return block.members[0]["members"][0]["name"] == "ids"


def switch_ids(i: int) -> bytes:
    """A switch buffer element's ids: (light index i, 0, 0, 0) as int32."""
    return struct.pack("<4i", i, 0, 0, 0)


def light_buffer_of(iface, i: int):
    """The storage block that reads the key's dynamic light i: its own LightBuffer<i>, or the one block of the
    key's switch loop (a key has at most one: every `**` light is in it), named for the loop's first light."""
    own = iface.block(light_buffer_block(i))
    if own is not None:
        return own
    return next((blk for blk in iface.blocks if blk.name.startswith(LIGHT_BUFFER) and is_switch(blk)), None)


def _element(value, slot):
    """The value a slot holds: an array parameter's element, or the value itself."""
    return value if slot.element is None else value[slot.element]


def light_entry(u, light_type: str, shadow: str, values: dict):
    """LightEntry.data of one light, (light_vec4s, 4) float32: each parameter at its slot of
    u.light_layouts (a scalar for a vector parameter splats, as pack() does; a mat4 spans four)."""
    import numpy as np

    data = np.zeros((u.light_vec4s, 4), np.float32)
    words = data.reshape(-1)
    for name, slot in u.light_layouts[(light_type, shadow)].items():
        put(words, slot, values[name])
    return data


def entry_bytes(ids, data):
    """Storage-buffer entries as uint32 words (n, 1 + k, 4): ids as int32 in the first vec4, then the data vec4s."""
    import numpy as np

    data = np.asarray(data)
    raw = np.zeros((len(ids), 1 + data.shape[1], 4), np.float32)
    raw[:, 1:, :] = data
    raw = raw.view(np.uint32)
    raw[:, 0, :] = np.asarray(ids).astype(np.int32).view(np.uint32)
    return raw
