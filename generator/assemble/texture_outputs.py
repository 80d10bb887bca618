"""A scene's texture bindings as build artifacts: content-addressed KTX2 files, listed per material binding.

Every texture a material binds (scene/textures.py: the image the scene names, or the generated one) is
written as ``OUT/textures/<W>x<H>.<format>.<sha12>.ktx2`` with its full mip chain, filtered by what it holds
(assemble/textures.py), once per distinct (image, filter): two materials that bind one image share the file.
The manifest says, per material, ``textures``: per texture name the set and binding of the image and its
sampler as the specialized permutation's reflection has them (and the ubershader's, under ``ubershader``),
the artifact (path, sha256, format, width, height, levels, colour space, what it holds), where the image
came from (``source``: the path as the scene wrote it, the glTF JSON pointer of the image, or
``generated``), and the sampler state with ``index``, its row in the manifest's ``samplers``: each distinct
state once, spelled for every platform (assemble/samplers.py). The manifest's ``textures`` lists each file
once (with its bytes, its mip filter, the input key that lets the next build keep it without filtering
again, and the bindings that use it).

Shadow maps are the renderer's (or engine's) images, not artifacts: each platform reflection's sampler
descriptor of a light texture gets ``sampler_state``, the row of ``samplers`` its brick reads with —
bilinear, level 0, clamped; a ``texture2d_shadow`` (pcf_hardware) a comparison sampler, less-or-equal. Each
light's ``depth_pass.binds`` row names the same row by ``sampler_state``: the state is described once, here.
A vsm light's ``depth_pass.moments.blur`` names the row its passes read the moments through, likewise.

Baked tables (assemble/tables.py) are read as their bricks' texel-centre arithmetic assumes: bilinear, level
0, clamped to the edge. Each row of the manifest's ``tables`` gets ``sampler`` (that state with ``index``, its
row of ``samplers``, as a material binding has it), and each reflection's sampler descriptor of a table
``sampler_state``, the same index.
"""
from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

from ..io import content_key, sha256
from ..scene.load import Scene
from ..scene.textures import Sampler
from .samplers import spell
from .textures import TEXTURES_DIR, texture_artifact

# the states the shadow bricks are read with (what runtime/renderer.py binds: bilinear, clamp to edge, level 0)
SHADOW_SAMPLER = Sampler(mipmap="none", wrap_u="clamp", wrap_v="clamp")
SHADOW_COMPARE_SAMPLER = Sampler(mipmap="none", wrap_u="clamp", wrap_v="clamp", compare="less_or_equal")
# the state a baked table is read with: what its brick's texel-centre arithmetic assumes
TABLE_SAMPLER = Sampler(mipmap="none", wrap_u="clamp", wrap_v="clamp")
_LIGHT_NAME = re.compile(r"^(?:_smp_)?l\d+_(.+)$")  # a light texture's resource (l0_shadow_map) and sampler
_TEXTURE_NAME = re.compile(r"^(?:_smp_)?t_(.+)$")  # a material texture's resource (t_on_sin_sin) and sampler
_OWN_TMP = re.compile(r"^\..+\.[^.]+\.tmp$")  # io.atomic_write's temporaries, left by an interrupted build


def _stage_textures(entry: dict):
    for stage in (entry.get("interface") or {}).values():
        if isinstance(stage, dict):
            yield from (t for t in stage.get("textures", []) if isinstance(t, dict))


def _bound_at(t: dict) -> dict:
    return {k: t[k] for k in ("set", "binding", "sampler_binding") if k in t}


def _where_bound(manifest: dict, scene: Scene) -> tuple[dict, dict]:
    """({material: {texture: {set, binding, sampler_binding}}}, {texture: the same in the ubershader}) from the
    interfaces of the manifest's permutations (the first, by hash, that draws the material and binds the
    texture: the material textures' bindings do not depend on the lights) and of its ubershader."""
    entries = {e.get("hash"): e for e in manifest.get("permutations", [])}
    out: dict[str, dict] = {}
    for o in sorted(scene.objects, key=lambda o: o["permutation"]):
        mine = out.setdefault(o["material"], {})
        for t in _stage_textures(entries.get(o["permutation"], {})):
            if "light" not in t:
                mine.setdefault(t["name"], _bound_at(t))
    uber = {t["name"]: _bound_at(t) for t in _stage_textures(manifest.get("ubershader") or {}) if "light" not in t}
    return out, uber


def _intact(out: Path, row: dict) -> bool:
    try:
        return sha256((out / row["path"]).read_bytes()) == row["sha256"]
    except (OSError, KeyError, TypeError):
        return False


class _Samplers:
    """The manifest's ``samplers``: each distinct state once, in first-use order, with its platform spellings."""

    def __init__(self, platforms):
        self.platforms, self.rows, self.index = platforms, [], {}

    def __call__(self, s: Sampler) -> int:
        if s not in self.index:
            self.index[s] = len(self.rows)
            state = s.as_dict()
            self.rows.append({**state, "platforms": spell(state, self.platforms)})
        return self.index[s]


def write_textures(out: Path, scene: Scene, manifest: dict, count=None, previous: dict | None = None,
                   base: str = "") -> None:
    """Write every texture binding of the manifest's materials as a KTX2 artifact and list it (module docstring):
    sets ``textures`` on each material, the manifest's ``textures`` and ``samplers``, and each reflection's
    light sampler states. count(changed) is told of each file. A file whose input key (base: the build's key;
    the image's digest and how it is filtered) is in the `previous` manifest, and is intact, is kept unfiltered."""
    old = {r.get("input_key"): r for r in (previous or {}).get("textures", []) if isinstance(r, dict)}
    samplers = _Samplers(manifest.get("platforms") or ())
    where, uber = _where_bound(manifest, scene)
    files: dict[str, dict] = {}  # input key -> the manifest's row of the file
    for mname, mentry in manifest.get("materials", {}).items():
        m = scene.materials.get(mname)
        mentry.pop("textures", None)
        if m is None or not m.images:
            continue
        rows = {}
        for tname, b in m.images.items():
            key = content_key(base, "texture", b.digest, b.holds, b.colour_space, b.keep_length)
            if key not in files:
                files[key] = _file(out, b, key, old.get(key), count)
            f = files[key]
            f["used_by"].append(f"{mname}/{tname}")
            at = {**where.get(mname, {}).get(tname, {}), **({"ubershader": uber[tname]} if tname in uber else {})}
            rows[tname] = {**at, "path": f["path"], "sha256": f["sha256"],
                           "format": f["format"], "width": f["width"], "height": f["height"], "levels": f["levels"],
                           "colour_space": f["colour_space"], "holds": f["holds"], "source": b.source,
                           "generated": b.generated, "sampler": {**b.sampler.as_dict(), "index": samplers(b.sampler)}}
        mentry["textures"] = rows
    manifest.pop("textures", None)
    if files:
        manifest["textures"] = sorted(files.values(), key=lambda r: r["path"])
    _light_samplers(manifest, samplers)
    _table_samplers(manifest, samplers)
    manifest.pop("samplers", None)
    if samplers.rows:
        manifest["samplers"] = samplers.rows


def _file(out: Path, b, key: str, kept: dict | None, count) -> dict:
    """The manifest's row of binding b's artifact: kept from the last build when intact, else made and written."""
    if kept is not None and _intact(out, kept):
        if count is not None:
            count(False)
        return {**kept, "used_by": []}
    art = texture_artifact(b.image, b.holds, b.colour_space, b.source, keep_length=b.keep_length)
    changed = art.write(out)
    if count is not None:
        count(changed)
    d = art.descriptor
    return {k: d[k] for k in ("path", "sha256", "bytes", "format", "width", "height", "levels", "colour_space",
                              "holds", "mip_filter")} | {"input_key": key, "used_by": []}


def _light_samplers(manifest: dict, samplers: _Samplers) -> None:
    """Each platform reflection's sampler descriptors of light textures get ``sampler_state`` (module docstring)."""
    entries = [*manifest.get("permutations", []), manifest.get("ubershader") or {}]
    for e in entries:
        lights = {t["name"]: t for t in _stage_textures(e) if "light" in t}
        if not lights:
            continue
        for refl in ((p or {}).get("reflection") for p in (e.get("platforms") or {}).values()):
            for d in _sampler_descriptors(refl):
                named = _LIGHT_NAME.match(str(d.get("name", "")))  # WebGPU's entries name no parameter
                t = lights.get(d.get("parameter") or (named and named[1]))
                if t is not None:
                    d["sampler_state"] = samplers(_light_state(t))
    # the depth passes' binds name the same rows: one description of each light sampler, the samplers table's
    by_hash = {e.get("hash"): e for e in manifest.get("permutations", [])}
    for light in (manifest.get("lights") or {}).values():
        for b in ((light or {}).get("depth_pass") or {}).get("binds", []):
            t = next((t for t in _stage_textures(by_hash.get(b.get("permutation"), {}))
                      if t.get("light") == b.get("light_index") and t.get("name") == b.get("texture")), None)
            if t is not None:
                b["sampler_state"] = samplers(_light_state(t))
        blur = (((light or {}).get("depth_pass") or {}).get("moments") or {}).get("blur")
        if isinstance(blur, dict):  # the blur's passes read the moments as the renderer's blur does
            blur["sampler_state"] = samplers(SHADOW_SAMPLER)


def _light_state(t: dict) -> Sampler:
    """The state light texture `t` (an interface row) is read with: a comparison sampler where it compares."""
    if t.get("compare") or t.get("sampler") == "comparison" or t.get("compare_op"):
        return replace(SHADOW_COMPARE_SAMPLER, compare=t.get("compare_op") or SHADOW_COMPARE_SAMPLER.compare)
    return SHADOW_SAMPLER


def _table_samplers(manifest: dict, samplers: _Samplers) -> None:
    """Each row of ``tables`` gets ``sampler``, each reflection's sampler descriptor of a table ``sampler_state``
    (module docstring)."""
    tables = [t for t in manifest.get("tables", []) if isinstance(t, dict)]
    if not tables:
        return
    index = samplers(TABLE_SAMPLER)
    for t in tables:
        t["sampler"] = {**TABLE_SAMPLER.as_dict(), "index": index}
    names = {t.get("texture") for t in tables}
    for e in [*manifest.get("permutations", []), manifest.get("ubershader") or {}]:
        bound = {t["name"] for t in _stage_textures(e) if "light" not in t} & names
        if not bound:
            continue
        for refl in ((p or {}).get("reflection") for p in (e.get("platforms") or {}).values()):
            for d in _sampler_descriptors(refl):
                named = _TEXTURE_NAME.match(str(d.get("name", "")))  # WebGPU's entries name no parameter
                if (d.get("parameter") or (named and named[1])) in bound:
                    d["sampler_state"] = index


def _sampler_descriptors(refl) -> list:
    """The entries of a platform reflection that stand for a sampler: Vulkan ``sampler`` descriptors, D3D12
    ``Sampler`` resources, GL's combined samplers, WebGPU ``sampler`` bindings."""
    if not isinstance(refl, dict):
        return []
    rows = [*refl.get("descriptors", []), *refl.get("resources", []), *refl.get("samplers", []),
            *refl.get("bind_groups", [])]
    return [d for d in rows if isinstance(d, dict) and (d.get("type") in ("sampler", "Sampler") or "sampler" in d
                                                        or str(d.get("type", "")).startswith("sampler"))]


def texture_files(manifest: dict) -> dict[str, int]:
    """{path: bytes} of the texture artifacts a manifest lists (the build's record checks them)."""
    return {t["path"]: t["bytes"] for t in manifest.get("textures", []) if isinstance(t, dict)}


def image_files(scene: Scene) -> list[Path]:
    """The image files the scene's materials read (the depfile lists them)."""
    return sorted({b.file for m in scene.materials.values() for b in getattr(m, "images", {}).values()
                   if b.file is not None}, key=str)


def collect_textures(out: Path, manifest: dict) -> int:
    """Remove the files of OUT/textures that the (new, already written) manifest does not name, and an interrupted
    build's temporaries there."""
    keep = set(texture_files(manifest))
    d, gone = out / TEXTURES_DIR, 0
    if not d.is_dir():
        return 0
    for p in d.iterdir():
        if p.is_file() and (f"{TEXTURES_DIR}/{p.name}" not in keep and not p.name.startswith(".")
                            or _OWN_TMP.match(p.name)):
            p.unlink(missing_ok=True)
            gone += 1
    try:
        d.rmdir()  # a build without textures leaves no empty folder
    except OSError:
        pass
    return gone
