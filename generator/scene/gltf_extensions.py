"""The glTF extensions a file uses, accepted or refused before anything is mapped (scene/gltf.py).

A KHR_* extension that changes shading (SHADING_EXTENSIONS) is an error naming it and where it is used;
KHR_* ones that do not (ACCEPTED_EXTENSIONS) are accepted and listed in scene.notes; an unknown KHR_* one
is an error (it cannot be told harmless); another vendor's is ignored with a note unless
extensionsRequired names it (then an error, as the glTF spec requires). An extension declared in
extensionsUsed but found nowhere in the file gets a note (KHR_mesh_quantization excepted: no object of
its own marks it, its accessors use it).
"""
from __future__ import annotations

from .gltf_read import Reader
from .jsonpos import pointer

SHADING_EXTENSIONS = {  # change what the shader computes; no brick implements them yet
    "KHR_materials_clearcoat", "KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior",
    "KHR_materials_specular", "KHR_materials_sheen", "KHR_materials_iridescence", "KHR_materials_anisotropy",
    "KHR_materials_dispersion", "KHR_materials_diffuse_transmission", "KHR_materials_unlit",
    "KHR_materials_pbrSpecularGlossiness", "KHR_materials_variants",
}
ACCEPTED_EXTENSIONS = {  # do not change the shader (or are mapped here): accepted, listed in scene.notes
    "KHR_lights_punctual": "mapped to the scene's lights",
    "KHR_mesh_quantization": "quantized attributes are decoded on import",
    "KHR_materials_emissive_strength": "emissiveStrength scales the emissive parameter",
    "KHR_texture_basisu": "an image encoding: a texture's core source image is read (Basis KTX2 is not)",
    "KHR_texture_transform": "mapped to the packing's uv slot (texture_transform), one transform per material",
    "KHR_xmp_json_ld": "metadata",
    "KHR_animation_pointer": "animation, not shading",
}


def _used(rd: Reader) -> dict[str, str]:
    """Every extension whose object appears in the file -> the pointer of its first appearance."""
    used: dict[str, str] = {}

    def walk(x, ptr):
        if isinstance(x, dict):
            ext = x.get("extensions")
            if ext is not None and not isinstance(ext, dict):
                raise rd.err(f"{ptr}/extensions", "must be a JSON object", "write \"extensions\": {…}")
            for name in (ext or {}):
                used.setdefault(name, f"{ptr}/extensions/{pointer(name)[1:]}")
            for k, v in x.items():
                walk(v, f"{ptr}/{pointer(k)[1:]}")
        elif isinstance(x, list):
            for i, v in enumerate(x):
                walk(v, f"{ptr}/{i}")

    try:
        walk(rd.raw, "")
    except RecursionError:
        raise rd.err("", "the JSON nests too deeply to read", "check the file") from None
    return used


def check_extensions(rd: Reader, notes: list) -> list[str]:
    """Every extension used, by where: errors for the shading ones and unknown KHR_ ones, notes for the rest."""
    used = _used(rd)
    found = set(used)  # where an extension's object appears (KHR_mesh_quantization has none: its accessors use it)
    required = rd.get(rd.raw, "extensionsRequired", "", "arr", [])
    declared = rd.get(rd.raw, "extensionsUsed", "", "arr", [])
    for key, lst in (("extensionsRequired", required), ("extensionsUsed", declared)):
        for i, name in enumerate(lst):
            if not isinstance(name, str):
                raise rd.err(f"/{key}/{i}", "must be an extension name (a string)",
                             "write e.g. \"KHR_lights_punctual\"")
    for i, name in enumerate(required):
        used.setdefault(name, f"/extensionsRequired/{i}")
    for name, ptr in used.items():
        if name in SHADING_EXTENSIONS:
            raise rd.err(ptr, f"extension {name} changes shading and is not supported",
                         f"bake or remove {name} (no brick implements it yet)")
        if name.startswith("KHR_") and name not in ACCEPTED_EXTENSIONS:
            raise rd.err(ptr, f"extension {name} is not supported",
                         f"remove {name}, or export without it (it may change shading)")
    for i, name in enumerate(required):
        if not name.startswith("KHR_"):
            raise rd.err(f"/extensionsRequired/{i}", f"required extension {name} is not supported",
                         f"export without {name}")
    accepted = sorted(n for n in set(used) | {d for d in declared} if n in ACCEPTED_EXTENSIONS)
    for n in accepted:
        notes.append(f"extension {n} accepted: {ACCEPTED_EXTENSIONS[n]}")
    for i, n in enumerate(declared):
        if n not in found and n != "KHR_mesh_quantization":
            notes.append(f"extension {n} is declared in extensionsUsed (/extensionsUsed/{i}) but used nowhere "
                         "in the file")
    for n in sorted((set(used) | set(declared)) - set(ACCEPTED_EXTENSIONS) - set(required)):
        if not n.startswith("KHR_"):
            notes.append(f"extension {n} ignored (not required by the file)")
    return accepted
