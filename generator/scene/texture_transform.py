"""KHR_texture_transform on a glTF material's textures → the packing's optional `uv` slot.

The filler `texture_transform` (bricks/packing/uv/texture_transform.py) maps the texture coordinates once,
before the packing, for every texture the material samples (link/glue.py uv_transform): base colour,
metallic-roughness, normal and, when it emits, emissive. glTF allows a transform per textureInfo; this
mapping takes one per material:
  - the sampled textures all without the extension, or with the identity (offset [0, 0], rotation 0,
    scale [1, 1]) → no slot: the key, the shader and the Material block of the material without it;
  - all with one transform → `<packing>(normal=…,uv=texture_transform)` with the parameters uv_offset,
    uv_scale, uv_rotation = the file's offset, scale, rotation;
  - different transforms → an error at the first texture whose transform differs from the first one's.
A texture the material does not sample (occlusionTexture; emissiveTexture under a zero factor) may carry any
transform: it changes nothing drawn.
texCoord: the extension's overrides the textureInfo's (as the extension says: an exporter may keep the
pre-transform set there and a fallback set in the textureInfo); the set used must be 0, since the meshes
carry one UV set, TEXCOORD_0 (scene/gltf_meshes.py reads no TEXCOORD_1): another is an error at the texCoord that
chose it.
"""
from __future__ import annotations

import json

EXT = "KHR_texture_transform"
SLOT = ",uv=texture_transform"  # appended to a packing's slot list (the canonical form puts it in slot order)
IDENTITY = {"uv_offset": [0.0, 0.0], "uv_scale": [1.0, 1.0], "uv_rotation": 0.0}


def _extension(rd, info: dict, here: str):
    """(the extension's object, its pointer), or (None, '') without one."""
    ext = info.get("extensions")
    if not isinstance(ext, dict) or EXT not in ext:
        return None, ""
    return rd.get(ext, EXT, f"{here}/extensions", "obj"), f"{here}/extensions/{EXT}"


def check_texcoord(rd, info: dict, here: str) -> None:
    """The UV set textureInfo `info` (at pointer `here`) is sampled with must be TEXCOORD_0."""
    tc = rd.get(info, "texCoord", here, "int", 0)
    where = f"{here}/texCoord"
    e, eptr = _extension(rd, info, here)
    if e is not None and "texCoord" in e:
        tc, where = rd.get(e, "texCoord", eptr, "int"), f"{eptr}/texCoord"
    if tc != 0:
        raise rd.err(where, f"texture coordinate set {tc} is not supported: the bricks read TEXCOORD_0 "
                     "(the meshes carry one UV set)", "move the texture to UV set 0")


def params_of(rd, info: dict, here: str) -> dict:
    """uv_offset, uv_scale, uv_rotation of textureInfo `info`: the extension's values, or the identity."""
    e, eptr = _extension(rd, info, here)
    if e is None:
        return dict(IDENTITY)
    return {"uv_offset": rd.nums(e, "offset", eptr, 2, [0.0, 0.0]), "uv_scale": rd.nums(e, "scale", eptr, 2, [1.0, 1.0]),
            "uv_rotation": rd.num(e, "rotation", eptr, 0.0)}


def of_material(rd, sampled) -> tuple[str, dict]:
    """(SLOT or '', the uv parameters or {}) of a material whose sampled textureInfos are `sampled`:
    (container dict, key, container pointer) each, absent keys skipped."""
    first, first_ptr = None, ""
    for d, key, ptr in sampled:
        info = d.get(key)
        if not isinstance(info, dict):
            continue
        here = f"{ptr}/{key}"
        p = params_of(rd, info, here)
        if first is None:
            first, first_ptr = p, here
        elif p != first:
            shown = lambda q: "none" if q == IDENTITY else json.dumps(q)  # noqa: E731
            e, eptr = _extension(rd, info, here)
            raise rd.err(eptr or here, f"this texture's {EXT} ({shown(p)}) differs from {first_ptr}'s ({shown(first)}): "
                         "the packing maps the texture coordinates once for all the material's textures",
                         "give every texture of the material the same transform, or bake the transforms into the UVs")
    if first is None or first == IDENTITY:
        return "", {}
    return SLOT, first
