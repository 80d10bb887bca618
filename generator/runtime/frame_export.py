"""The frame export (`render --export DIR`): what an engine takes from its own scene, as `render` used it.

The build's manifest is the material contract: blocks, textures, samplers, render state, depth passes,
bindings. What it cannot hold is what an engine gets from its own assets — the meshes, where each object
stands, the camera, and each shadowed light's matrix fitted to the objects — so a render writes those beside
its frames, and an engine (examples/engine-c) that reads the manifest and this export draws the same picture
without running any of our Python. The layout is stated once, in the JSON Schema beside this module
(frame.schema.json; docs/reference/frame.md is generated from it), and checked when the export is written:

- ``DIR/frame.json``: the size, the colour attachment drawn into, the clear values, the camera (eye and
  view_proj), the meshes, the objects in the manifest's order (mesh, model matrix, mirrored), the order the
  draws were made in, and per shadowed light its shadow_matrix (a point light's: face 0's, with the six faces'
  face_matrices, drawn into the six layers of its map in that order), the pcf tap spacing the render wrote (or
  null: the scene's own value is in the build's blocks), its map's size, the depth pass's camera_pos and its
  casters (the objects whose light set holds it: they alone are drawn into its map and fitted);
- ``DIR/meshes/<name>.<sha12>.bin``: one file per distinct mesh, its vertex attributes back to back
  (little-endian float32, tightly packed, each starting at a multiple of 16 bytes), then its uint32 indices
  (a triangle list, counter-clockwise front faces: a mirrored object's mesh has its winding reversed).

Matrices are the 16 numbers of a mat4 in column-major order (std140's), float64 as the renderer held them;
the renderer rounds them to float32 when it uploads them, and so should an engine. Written atomically, in a
fixed order, with no times or absolute paths: the same render gives the same bytes.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

FORMAT = "shadermatrix-frame"
FORMAT_VERSION = 1
SCHEMA = Path(__file__).with_name("frame.schema.json")
# the float formats of the mesh attributes, by their number of components (Vulkan's names without VK_FORMAT_)
_FORMATS = {1: "R32_SFLOAT", 2: "R32G32_SFLOAT", 3: "R32G32B32_SFLOAT", 4: "R32G32B32A32_SFLOAT"}


@dataclass
class FrameExport:
    """What render_scene collects for the export while it sets the frame up (see render_scene)."""

    scene: str
    size: tuple[int, int]
    color_attachment: str
    clear: tuple
    eye: list
    view_proj: list  # column-major, 16
    meshes: list = field(default_factory=list)  # [(name, Mesh)]
    objects: list = field(default_factory=list)  # [{"name", "mesh", "model", "mirrored"}]
    draw_order: list = field(default_factory=list)
    lights: dict = field(default_factory=dict)


def placed_meshes(objects, key_of, meshes: dict) -> tuple[list, list]:
    """(FrameExport.meshes, FrameExport.objects) of placed objects (runtime/placement.Placed), `key_of` each one's key
    into `meshes` ({(mesh name or id, mirrored): the Mesh drawn}, in order of first use)."""
    keys = list(meshes)
    named = [(_mesh_name(k, objects[key_of.index(k)]), m) for k, m in meshes.items()]
    rows = [{"name": o.name, "mesh": keys.index(k), "model": _columns(o.model), "mirrored": o.mirrored}
            for o, k in zip(objects, key_of)]
    return named, rows


def _mesh_name(key, placed) -> str:
    """A mesh's name in the export: the placement's mesh name, or the glTF primitive's, '_mirrored' when so."""
    base = key[0] if isinstance(key[0], str) else (getattr(placed.mesh, "name", None) or placed.name)
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in str(base)) + ("_mirrored" if key[1] else "")


def _columns(m) -> list[float]:
    from .camera import column_major
    return column_major(m)


def _floats(xs) -> list[float]:
    return [float(x) for x in np.asarray(xs, np.float64).reshape(-1)]


def mesh_bytes(mesh) -> tuple[bytes, dict, dict]:
    """(the mesh file's bytes, its attributes' rows, its indices' row) of a scene Mesh."""
    chunks, attributes, at = [], {}, 0
    for name, arr in mesh.attributes().items():
        a = np.ascontiguousarray(arr, "<f4")
        n = a.shape[1] if a.ndim == 2 else 1
        attributes[name] = {"offset": at, "format": _FORMATS[n], "stride": 4 * n}
        chunks.append(a.tobytes())
        at += a.nbytes
        pad = -at % 16
        chunks.append(b"\0" * pad)
        at += pad
    idx = np.ascontiguousarray(mesh.indices, "<u4")
    chunks.append(idx.tobytes())
    return b"".join(chunks), attributes, {"offset": at, "format": "uint32", "count": int(idx.size)}


def frame_document(export: FrameExport, mesh_rows: list[dict]) -> dict:
    """frame.json's content (mesh_rows: the meshes' rows, as write_export makes them)."""
    return {"format": FORMAT, "format_version": FORMAT_VERSION, "scene": export.scene, "platform": "vulkan",
            "size": list(export.size), "color_attachment": export.color_attachment,
            "clear": {"color": _floats(export.clear), "depth": 1.0},
            "camera": {"eye": _floats(export.eye), "view_proj": _floats(export.view_proj)},
            "meshes": mesh_rows,
            "objects": [{"name": o["name"], "mesh": o["mesh"], "model": _floats(o["model"]),
                         "mirrored": bool(o["mirrored"])} for o in export.objects],
            "draw_order": [int(i) for i in export.draw_order],
            "lights": {ln: {"shadow_matrix": _floats(v["shadow_matrix"]),
                            "pcf_texel": None if v["pcf_texel"] is None else float(v["pcf_texel"]),
                            "size": [int(x) for x in v["size"]], "eye": _floats(v["eye"]),
                            "casters": [int(i) for i in v["casters"]],
                            **({"face_matrices": [_floats(m) for m in v["faces"]]} if v.get("faces") else {})}
                       for ln, v in sorted(export.lights.items())}}


def check_document(doc: dict) -> None:
    """Raise ValueError where `doc` breaks frame.schema.json (the writer's own check: a field the schema
    does not describe is a bug here, not something an engine should meet)."""
    import jsonschema

    schema = json.loads(SCHEMA.read_text())
    errors = sorted(jsonschema.Draft202012Validator(schema).iter_errors(doc), key=lambda e: list(e.path))
    if errors:
        e = errors[0]
        raise ValueError(f"frame export breaks its schema at /{'/'.join(map(str, e.path))}: {e.message}")


def write_export(directory, export: FrameExport) -> Path:
    """Write frame.json and the mesh files into `directory`; returns frame.json's path."""
    from ..io import atomic_write

    d = Path(directory)
    if d.exists() and not d.is_dir():
        from ..lang.errors import UserError
        raise UserError(f"{d} is a file — give --export a directory")
    rows, files = [], {}
    for name, mesh in export.meshes:
        data, attributes, indices = mesh_bytes(mesh)
        sha = hashlib.sha256(data).hexdigest()
        rel = f"meshes/{name}.{sha[:12]}.bin"
        files[rel] = data
        rows.append({"name": name, "path": rel, "sha256": sha, "bytes": len(data), "vertex_count": int(mesh.vertex_count),
                     "attributes": attributes, "indices": indices})
    doc = frame_document(export, rows)
    check_document(doc)  # before anything is written: a document the schema refuses leaves the folder as it was
    (d / "meshes").mkdir(parents=True, exist_ok=True)
    for rel, data in files.items():  # the meshes first, so that frame.json never names a file not there yet
        atomic_write(d / rel, data)
    atomic_write(d / "frame.json", (json.dumps(doc, indent=1, sort_keys=True) + "\n").encode())
    for old in (d / "meshes").glob("*.bin"):  # then an earlier export's meshes, which frame.json no longer names
        if f"meshes/{old.name}" not in files:
            old.unlink(missing_ok=True)
    return d / "frame.json"
