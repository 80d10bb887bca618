"""What manifest.json tells an engine: per permutation its Interface, per material and light set its values.

The Interface (link/interface.py) is the reflection: blocks with members, offsets, sizes and
types, textures with set, binding, dimension and color space (a texture2d_shadow: a depth format and a
comparison sampler), vertex inputs with locations and formats, interpolants, entry points, and for
every parameter where the engine writes it.
The scene's values are written beside it: per material and per light the named values
(defaults filled in), and per (permutation, material, light set) the blocks ready to upload,
laid out by that permutation's Interface (little-endian float32, hex).
"""
from __future__ import annotations

from ..link.values import light_values, material_values
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
        for i, ln in enumerate(obj["lights"]):
            lspecs = iface.params.get(f"light{i}", {})
            L = scene.lights[ln]
            lights.setdefault(ln, {"type": L.type, "shadow": L.shadow, "params": light_values(scene, ln, lspecs)})
    return {"materials": dict(sorted(materials.items())), "lights": dict(sorted(lights.items())),
            "light_sets": {k: list(v) for k, v in sorted(scene.light_sets.items())},
            "objects": [{"name": o["name"], "material": o["material"], "light_set": o["light_set"],
                         "permutation": o["permutation"]} for o in scene.objects]}


# ------------------------------------------------------------------ per platform: each one's binding model

_STAGES = {"Frame": ["vert", "frag"], "Object": ["vert"]}  # every other block and texture: the fragment stage
_WGPU_FORMAT = {"R32G32B32_SFLOAT": "float32x3", "R32G32B32A32_SFLOAT": "float32x4", "R32G32_SFLOAT": "float32x2"}
_DXGI_FORMAT = {"R32G32B32_SFLOAT": "DXGI_FORMAT_R32G32B32_FLOAT", "R32G32B32A32_SFLOAT": "DXGI_FORMAT_R32G32B32A32_FLOAT",
                "R32G32_SFLOAT": "DXGI_FORMAT_R32G32_FLOAT"}
_SEMANTIC = {"a_position": ("POSITION", 0), "a_normal": ("NORMAL", 0), "a_tangent": ("TANGENT", 0),
             "a_uv": ("TEXCOORD", 0), "a_color": ("COLOR", 0)}  # backends/hlsl/templates/vertex.hlsl.j2


def _resources(iface):
    """(kind, set, binding, name, stages, extra) of every resource, in (set, binding) order: blocks, then each
    texture's image and sampler (the sampler at binding + 1)."""
    from ..backends import get_target
    glsl = get_target("glsl")
    rows = [(b.kind, b.set, b.binding, b.name, _STAGES.get(b.name, ["frag"]), {}) for b in iface.blocks]
    for t in iface.textures:
        compare = bool(getattr(t, "compare", False))
        info = {"dimension": t.dim, "compare": compare, "parameter": t.param}
        rows.append(("image", t.set, t.binding, glsl.ident(t.name), ["frag"], info))
        rows.append(("sampler", t.set, t.binding + 1, glsl.sampler_name(t.name), ["frag"], info))
    return sorted(rows, key=lambda r: (r[1], r[2]))


def platform_reflection(iface, platform: str) -> dict:
    """The Interface in `platform`'s binding model: what an engine binds, by the names the sources declare.

    vulkan: descriptor (set, binding, descriptor type); d3d12: register class and number, space (the HLSL's
    ``register(xN, spaceM)``), and the input layout's semantics; gl: uniform-block binding points, texture
    units and storage-block bindings (backends/gl/emit.py gl_bindings: Vulkan's pairs flattened per namespace);
    webgpu: bind group, binding and the GPUBindGroupLayoutEntry resource type."""
    rows = _resources(iface)
    vin = iface.vertex_inputs
    if platform == "vulkan":
        kinds = {"uniform": "uniform_buffer", "storage": "storage_buffer", "image": "sampled_image", "sampler": "sampler"}
        return {"descriptors": [{"set": s, "binding": b, "type": kinds[k], "name": n, "stages": st, **x}
                                for k, s, b, n, st, x in rows],
                "vertex_inputs": [{"location": v.location, "name": v.name, "format": v.format} for v in vin],
                "push_constants": []}
    if platform == "d3d12":
        cls = {"uniform": ("CBV", "b"), "storage": ("SRV", "t"), "image": ("SRV", "t"), "sampler": ("Sampler", "s")}
        return {"resources": [{"name": n, "type": cls[k][0], "register": f"{cls[k][1]}{b}", "space": s,
                               "visibility": st, **x} for k, s, b, n, st, x in rows],
                "input_layout": [{"semantic": _SEMANTIC[v.name][0], "semantic_index": _SEMANTIC[v.name][1],
                                  "format": _DXGI_FORMAT[v.format], "name": v.name} for v in vin]}
    if platform == "gl":
        from ..backends.gl.emit import gl_bindings
        m = gl_bindings(iface.blocks, iface.textures)
        blocks = [r for r in rows if r[0] in ("uniform", "storage")]
        return {"uniform_blocks": [{"name": n, "binding": m["uniform"][(s, b)], "stages": st}
                                   for k, s, b, n, st, _ in blocks if k == "uniform"],
                "storage_blocks": [{"name": n, "binding": m["storage"][(s, b)], "stages": st}
                                   for k, s, b, n, st, _ in blocks if k == "storage"],
                "samplers": [{"name": n, "unit": m["texture"][(s, b)], "type": _gl_sampler(x), **x}
                             for k, s, b, n, st, x in rows if k == "image"],
                "vertex_inputs": [{"location": v.location, "name": v.name} for v in vin]}
    if platform == "webgpu":
        def resource(k, x):
            if k in ("uniform", "storage"):
                return {"buffer": {"type": "uniform" if k == "uniform" else "read-only-storage"}}
            if k == "image":
                return {"texture": {"sampleType": "depth" if x["compare"] else "float", "viewDimension": x["dimension"]}}
            return {"sampler": {"type": "comparison" if x["compare"] else "filtering"}}
        return {"bind_groups": [{"group": s, "binding": b, "name": n, "visibility": [v.upper().replace("VERT", "VERTEX")
                                 .replace("FRAG", "FRAGMENT") for v in st], **resource(k, x)} for k, s, b, n, st, x in rows],
                "vertex_inputs": [{"shaderLocation": v.location, "name": v.name, "format": _WGPU_FORMAT[v.format]}
                                  for v in vin]}
    raise ValueError(f"unknown platform {platform!r}")


def _gl_sampler(x: dict) -> str:
    if x["compare"]:
        return "sampler2DShadow"
    return {"2d": "sampler2D", "cube": "samplerCube"}[x["dimension"]]
