"""glTF 2.0 scenes (`.gltf`, `.glb`) → the same Scene a TOML scene gives (scene/load.py), through pygltflib.

pygltflib (pinned in requirements.lock) reads the container: the JSON text into its GLTF2 object, a
`.glb`'s chunks (after the strict checks below), data URIs. pygltflib checks nothing, so every value
this module uses is first checked here, on the parsed JSON, and a bad one is ONE error naming the file
and the JSON pointer: `model.gltf: /materials/3/pbrMetallicRoughness/baseColorTexture/index: ... —
what to do` (GltfError, a SourceError: the CLI exits 1). A `.glb` whose header or chunks are broken is
named by byte offset (`model.glb: byte 20 (chunk 0): ...`); a JSON syntax error by line:col.

Mapping:

Materials. Every metallic-roughness material (and the glTF default material, for primitives without
one) has the BRDF `lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)`.
Its packing follows the textures present (each changes the shader, so each changes the key):
  - no baseColorTexture and no metallicRoughnessTexture → `constants`, with the converted values
    rho_d = base·(1−metallic), f0 = mix(0.04, base, metallic), alpha = roughness² (glTF Appendix B);
  - baseColorTexture only and metallicFactor 0 → `albedo_texture` (rho_d = baseColorFactor, scaled by
    the texture; f0 = 0.04; alpha = roughness²): exact for a dielectric, one texture sample;
  - otherwise → `gltf_metallic_roughness` (base_color_map + orm_map; base_color, metallic, roughness =
    the factors); a texture the material lacks is bound to a 1×1 white texture (glTF's own meaning of
    an absent texture: the factor alone), recorded as "white" in GltfMaterial.textures.
  - normalTexture → the packing's normal slot `normal_map`, else `vertex`. normalTexture.scale ≠ 1 is
    not applied (normal_map has no scale): a note.
  - occlusionTexture is not read (it scales indirect light; the light loop has direct lights only): a
    note, and it does not change the key.
  - the surface state (spec/surface.py) is part of the key where it changes the shader: alphaMode →
    alpha opaque | mask | blend (base_alpha = baseColorFactor[3] and alpha_cutoff are material uniforms,
    so other cutoffs share the shader); doubleSided → double_sided (the back-face flip; the renderer culls
    back faces otherwise); emissiveFactor · KHR_materials_emissive_strength ≠ 0 → emissive "factor", with
    an emissiveTexture "texture" (emissive_map); an emissiveTexture under a zero factor is not sampled (a
    note). A primitive with COLOR_0 draws with vertex_color: its material is mapped a second time, as
    `<name>+COLOR_0`, since the shader differs. alphaMode, alphaCutoff and doubleSided stay recorded on
    GltfMaterial and on every object too.
  - KHR_texture_transform → the packing's optional slot `uv=texture_transform` (uv_offset, uv_scale,
    uv_rotation = offset, scale, rotation), one transform for all the textures the material samples; an
    identity transform or none leaves the key as without it; textures with different transforms are an
    error (scene/texture_transform.py).
  - a texCoord ≠ 0 (the textureInfo's, or the KHR_texture_transform one that overrides it) is an error (the
    bricks read one UV set, TEXCOORD_0).
  - every material is mapped and checked, used or not (as a TOML scene's materials); only the ones
    objects use make permutations. Each texture a material binds gets its image and sampler read from the
    file (scene/gltf_images.py): a missing, unreadable or corrupt image is an error at /images/N.
Tangents. A primitive whose material has a normal map and whose mesh has no TANGENT gets per-vertex
tangents generated on import from the UV gradients (Lengyel 2001: per-triangle ∂P/∂u, ∂P/∂v summed
per vertex, Gram-Schmidt against N, w = handedness) — NOT MikkTSpace-exact (MikkTSpace splits vertices
at tangent-space seams and weights by angle). The shader is the same with file or generated tangents,
so the key is too; the object records `tangents` = "file" | "generated". COLOR_0 (VEC3 or VEC4; RGB
gets alpha 1) is read into the mesh (Mesh.colors) and recorded on the object (`vertex_colors`).
A primitive without NORMAL gets flat normals (its triangles unwelded), as glTF requires.
Lights. KHR_lights_punctual lights instanced by nodes become the scene's lights (one Light per node
instance, shadow "none"): directional → `directional` (direction = the node's +Z, towards the light),
point → `point_range` (radius = range) or `point` (no range), spot → `spot` (position, direction = the
node's −Z, radius = range or 1e6 when absent, inner_angle/outer_angle = innerConeAngle/outerConeAngle).
color = color · intensity (the bricks' "game intensity"; candela / lux are taken as is). Each glTF
scene is one light set (its lights in node order), and every mesh node of that scene uses it.
Objects. One per primitive of every node instance in every glTF scene, named from the node (else the
mesh, else `node<i>`), `#<primitive>` when the mesh has several, made unique with `~2`, `~3`, …; each
carries its mesh (runtime/meshes.Mesh: positions, normals, tangents, uvs, uint32 indices; TRIANGLES,
strips and fans unrolled; points and lines skipped with a note) and its world matrix (`model`, 4×4).
Quantized attributes (KHR_mesh_quantization: normalized or plain integers) are decoded to float32.
Origins. Each permutation carries where its first object asked for it (spec/where.py), so an error
resolving or linking it names the glTF object to edit, found in the JSON text by scene/jsonpos.py:
the material (for glTF's default material, the primitive), the primitive's COLOR_0 for the vertex
colours, each light's KHR_lights_punctual definition. In a .gltf that is the object's line and column
with its pointer: `model.gltf:12:5: /materials/2: what is wrong — what to do`. A .glb has no lines to
go to, so its errors are at 1:1 and name the pointer and the object's byte offset in the file:
`model.glb:1:1: /materials/2 (byte 1234): …` (the pointer is what glTF tools and viewers show).
Checked on import: what the mapping reads (materials, textures, images, the scenes' node trees,
the primitives and accessors of the meshes they instance, buffers, lights); meshes no node instances
and animations, skins, cameras are not read, so not checked.
Scene.notes lists, one line each, the accepted extensions and what is not applied; Scene.extra holds
"extensions" (the accepted ones) and "gltf" (the pygltflib.GLTF2 document).
Extensions. A KHR_* extension that changes shading (SHADING_EXTENSIONS) is an error naming it and
where it is used; KHR_* ones that do not (ACCEPTED_EXTENSIONS) are accepted and listed in scene.notes;
an unknown KHR_* one is an error (it cannot be told harmless); another vendor's is ignored with a note
unless extensionsRequired names it (then an error, as the glTF spec requires).
"""
from __future__ import annotations

import binascii
import json
import math
import re
import struct
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..lang import SourceError
from ..lang.errors import read_bytes
from ..library.bricks import Library
from ..spec.permutation import LightKey, Permutation, SpecError, canonical, parse_brdf, parse_spec
from ..spec.resolve import check_packing, light_params, resolve
from . import texture_transform
from .jsonpos import origins
from .load import Light, Material, Scene, surface_specs
from ..spec.surface import EMISSIVE_MAP, Surface

BRDF = "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"
MAX_GLTF_BYTES = 256 << 20  # a .gltf, .glb or .bin larger than this is refused
MAX_LIGHTS_PER_SET = 32  # as scene/load.py: a specialized shader unrolls its lights
SPOT_NO_RANGE = 1.0e6  # a spot light without `range` (infinite in glTF): the spot brick's largest radius

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

_COMPONENTS = {5120: ("i1", 127.0), 5121: ("u1", 255.0), 5122: ("<i2", 32767.0), 5123: ("<u2", 65535.0),
               5125: ("<u4", None), 5126: ("<f4", None)}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_MODES = {0: "POINTS", 1: "LINES", 2: "LINE_LOOP", 3: "LINE_STRIP", 4: "TRIANGLES", 5: "TRIANGLE_STRIP",
          6: "TRIANGLE_FAN"}
_MISSING = object()


class GltfError(SourceError):
    """An error in a glTF file at a JSON pointer (or, for a .glb container, a byte offset)."""

    def __init__(self, path, pointer: str, message: str, hint: str = ""):
        self.pointer = pointer
        super().__init__(str(path), 1, 1, message, hint)

    def __str__(self) -> str:
        text = f"{self.path}: {self.pointer or '/'}: {self.message}"
        text = f"{text} — {self.hint}" if self.hint else text
        return "".join(c if c.isprintable() else ascii(c)[1:-1] for c in text)


@dataclass
class GltfMaterial(Material):
    """A Material with glTF's own alpha, sidedness and texture bindings (see the module docstring)."""

    alpha_mode: str = "OPAQUE"
    alpha_cutoff: float = 0.5
    double_sided: bool = False
    base_alpha: float = 1.0
    textures: dict = field(default_factory=dict)  # slot texture name -> {"texture": i, "image": j} or "white"
    source: str = ""  # the JSON pointer it came from


def _ptr(*parts) -> str:
    return "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in parts)


def _read_bytes(path: Path, what: str) -> bytes:
    return read_bytes(path, what, MAX_GLTF_BYTES)


def _parse_json(shown: str, text: str, where: str = ""):
    def bad_constant(name):
        raise ValueError(f"{name} is not JSON")

    try:
        return json.loads(text, parse_constant=bad_constant)
    except json.JSONDecodeError as e:
        if where:
            raise GltfError(shown, f"{where} line {e.lineno} column {e.colno}", f"JSON syntax error: {e.msg}",
                            "the JSON chunk must be valid JSON") from None
        raise SourceError(shown, e.lineno, e.colno, f"JSON syntax error: {e.msg}", "fix the glTF file's JSON") from None
    except ValueError as e:
        raise GltfError(shown, where or "/", f"{e}", "write finite numbers") from None
    except RecursionError:
        raise GltfError(shown, where or "/", "the JSON nests too deeply to read", "check the file") from None


_GLB_JSON, _GLB_BIN = 0x4E4F534A, 0x004E4942


def _read_glb(shown: str, data: bytes):
    """(json text, BIN chunk or None), after checking the header and chunks strictly (glTF 2.0 §4.4)."""
    hint = "the .glb is truncated or not a binary glTF file: export it again"
    if len(data) < 12:
        raise GltfError(shown, "byte 0 (header)", f"{len(data)} bytes, shorter than the 12-byte GLB header", hint)
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF":
        raise GltfError(shown, "byte 0 (header)", f"magic is {magic!r}, not b'glTF'", hint)
    if version != 2:
        raise GltfError(shown, "byte 4 (header)", f"GLB version {version}, not 2", "convert the file to glTF 2.0")
    if length != len(data):
        raise GltfError(shown, "byte 8 (header)", f"the header says {length} bytes, the file has {len(data)}", hint)
    chunks, off, i = [], 12, 0
    while off < len(data):
        if off + 8 > len(data):
            raise GltfError(shown, f"byte {off} (chunk {i})", "the chunk header is cut short", hint)
        clen, ctype = struct.unpack_from("<II", data, off)
        if off + 8 + clen > len(data):
            raise GltfError(shown, f"byte {off} (chunk {i})", f"chunk length {clen} runs past the end of the file "
                            f"({len(data) - off - 8} bytes left)", hint)
        if clen % 4:
            raise GltfError(shown, f"byte {off} (chunk {i})", f"chunk length {clen} is not a multiple of 4", hint)
        chunks.append((ctype, data[off + 8:off + 8 + clen], off))
        off += 8 + clen
        i += 1
    if not chunks or chunks[0][0] != _GLB_JSON:
        got = f"type 0x{chunks[0][0]:08x}" if chunks else "none"
        raise GltfError(shown, "byte 12 (chunk 0)", f"the first chunk must be JSON (0x4E4F534A), got {got}", hint)
    binary = None
    if len(chunks) > 1 and chunks[1][0] == _GLB_BIN:
        binary = chunks[1][1]
    for ctype, _, coff in chunks[1:]:
        if ctype == _GLB_JSON:
            raise GltfError(shown, f"byte {coff}", "a second JSON chunk", hint)
    try:
        text = chunks[0][1].decode("utf-8")
    except UnicodeDecodeError as e:
        raise GltfError(shown, f"byte {20 + e.start} (chunk 0)", "the JSON chunk is not UTF-8", hint) from None
    return text, binary


class _Reader:
    """Checked access to the parsed JSON: every failure is a GltfError at its JSON pointer."""

    def __init__(self, path: Path, raw: dict, binary):
        self.path, self.shown, self.raw, self.binary = path, str(path), raw, binary
        self._buffers: dict[int, bytes] = {}
        self.quantized = False  # KHR_mesh_quantization declared: integer attributes that are not normalized too

    def err(self, ptr, message, hint=""):
        return GltfError(self.shown, ptr, message, hint)

    def get(self, d: dict, key: str, ptr: str, kind: str, default=_MISSING, hint: str = ""):
        here = f"{ptr}/{key}"
        if key not in d:
            if default is _MISSING:
                raise self.err(here, f"'{key}' is required here", hint or "see the glTF 2.0 specification")
            return default
        v = d[key]
        ok = {"int": lambda x: isinstance(x, int) and not isinstance(x, bool),
              "num": lambda x: isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x),
              "str": lambda x: isinstance(x, str), "bool": lambda x: isinstance(x, bool),
              "obj": lambda x: isinstance(x, dict), "arr": lambda x: isinstance(x, list)}[kind](v)
        if not ok:
            names = {"int": "an integer", "num": "a finite number", "str": "a string", "bool": "true or false",
                     "obj": "a JSON object", "arr": "an array"}
            raise self.err(here, f"must be {names[kind]}, got {json.dumps(v)[:40]}", hint or f"write {names[kind]}")
        return v

    def nums(self, d, key, ptr, n, default=_MISSING, lo=None, hi=None):
        v = self.get(d, key, ptr, "arr", default)
        if v is default and default is not _MISSING:
            return list(default)
        here = f"{ptr}/{key}"
        finite = all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)
        if len(v) != n or not finite:
            raise self.err(here, f"must be {n} finite numbers, got {json.dumps(v)[:60]}", f"write {n} numbers")
        for j, x in enumerate(v):
            if (lo is not None and x < lo) or (hi is not None and x > hi):
                raise self.err(f"{here}/{j}", f"{x} is outside [{lo}, {hi}]", f"write a value in [{lo}, {hi}]")
        return [float(x) for x in v]

    def num(self, d, key, ptr, default=_MISSING, lo=None, hi=None):
        v = self.get(d, key, ptr, "num", default)
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise self.err(f"{ptr}/{key}", f"{v} is outside [{lo}, {hi}]", f"write a value in [{lo}, {hi}]")
        return float(v)

    def array(self, name: str) -> list:
        v = self.get(self.raw, name, "", "arr", [])
        for i, x in enumerate(v):
            if not isinstance(x, dict):
                raise self.err(_ptr(name, i), "must be a JSON object", f"each entry of '{name}' is an object")
        return v

    def ref(self, d, key, ptr, target: str, default=_MISSING) -> int | None:
        i = self.get(d, key, ptr, "int", default)
        if i is None:
            return None
        n = len(self.array(target))
        if not 0 <= i < n:
            raise self.err(f"{ptr}/{key}", f"{target} index {i} does not exist (the file has {n} {target})",
                           f"use an index from 0 to {n - 1}" if n else f"add the {target} it refers to")
        return i

    # buffers and accessors ------------------------------------------------------------------------
    def buffer(self, i: int) -> bytes:
        if i in self._buffers:
            return self._buffers[i]
        ptr = _ptr("buffers", i)
        b = self.array("buffers")[i]
        length = self.get(b, "byteLength", ptr, "int")
        uri = self.get(b, "uri", ptr, "str", None)
        if uri is None:
            if self.binary is None:
                raise self.err(ptr, "has no uri, and the file has no GLB BIN chunk to stand for it",
                               "give the buffer a uri, or store its data in a .glb's BIN chunk")
            if i != 0:
                raise self.err(ptr, "has no uri: only buffer 0 may be a .glb's BIN chunk", "give the buffer a uri")
            data = self.binary
        elif uri.startswith("data:"):
            from pygltflib import GLTF2
            if ";base64," not in uri:
                raise self.err(f"{ptr}/uri", "a data URI that is not base64",
                               "write data:application/octet-stream;base64,…")
            try:
                data = GLTF2.decode_data_uri(uri)
            except (binascii.Error, ValueError, IndexError):
                raise self.err(f"{ptr}/uri", "the data URI is not valid base64", "export the file again") from None
        else:
            if re.match(r"^[A-Za-z][A-Za-z0-9+.-]*:", uri) or uri.startswith("/"):
                raise self.err(f"{ptr}/uri", f"'{uri[:60]}' is not a relative file path",
                               "keep buffers beside the .gltf (a relative uri) or embed them")
            from urllib.parse import unquote
            try:
                data = _read_bytes(self.path.parent / unquote(uri), "glTF buffer")
            except SourceError as e:
                raise self.err(f"{ptr}/uri", f"{e.path}: {e.message}",
                               "keep the buffer file beside the .gltf") from None
        if len(data) < length:
            raise self.err(f"{ptr}/byteLength", f"says {length} bytes, the data has {len(data)}",
                           "the buffer is truncated: export the file again")
        self._buffers[i] = data
        return data

    def accessor(self, i: int, ptr_use: str, types: tuple, float_only=False) -> np.ndarray:
        """Accessor i as float32 (or uint32 for integer SCALAR indices) rows; checked against its buffer view."""
        ptr = _ptr("accessors", i)
        a = self.array("accessors")[i]
        ctype = self.get(a, "componentType", ptr, "int")
        if ctype not in _COMPONENTS:
            raise self.err(f"{ptr}/componentType", f"{ctype} is not a glTF component type",
                           f"use one of {', '.join(map(str, _COMPONENTS))}")
        atype = self.get(a, "type", ptr, "str")
        if atype not in _WIDTH:
            raise self.err(f"{ptr}/type", f"'{atype}' is not an accessor type", f"use one of {', '.join(_WIDTH)}")
        if atype not in types:
            raise self.err(f"{ptr}/type", f"is {atype}, but {ptr_use} needs {' or '.join(types)}",
                           "point at the right accessor")
        count = self.get(a, "count", ptr, "int")
        if count < 1:
            raise self.err(f"{ptr}/count", f"{count}: an accessor has at least one element", "write count ≥ 1")
        normalized = self.get(a, "normalized", ptr, "bool", False)
        if "sparse" in a:
            raise self.err(f"{ptr}/sparse", "sparse accessors are not supported", "export without sparse accessors")
        dt, scale = _COMPONENTS[ctype]
        if float_only and ctype != 5126 and not normalized and not self.quantized:
            raise self.err(f"{ptr}/componentType", f"{ptr_use} needs floats or normalized integers, got {ctype}",
                           "export float attributes (or use KHR_mesh_quantization's normalized forms)")
        width = _WIDTH[atype]
        csize = np.dtype(dt).itemsize
        bvi = self.ref(a, "bufferView", ptr, "bufferViews", None)
        if bvi is None:
            out = np.zeros((count, width), np.float32)
        else:
            bptr = _ptr("bufferViews", bvi)
            bv = self.array("bufferViews")[bvi]
            bi = self.ref(bv, "buffer", bptr, "buffers")
            data = self.buffer(bi)
            boff = self.get(bv, "byteOffset", bptr, "int", 0)
            blen = self.get(bv, "byteLength", bptr, "int")
            stride = self.get(bv, "byteStride", bptr, "int", 0) or csize * width
            if boff < 0 or blen < 1 or boff + blen > len(data):
                raise self.err(bptr, f"bytes {boff}…{boff + blen} lie outside buffer {bi} ({len(data)} bytes)",
                               "fix byteOffset / byteLength")
            aoff = self.get(a, "byteOffset", ptr, "int", 0)
            need = aoff + stride * (count - 1) + csize * width
            if aoff < 0 or need > blen:
                raise self.err(ptr, f"{count} elements of {atype} need {need} bytes of buffer view {bvi}, "
                               f"which has {blen}", "fix count, byteOffset or the buffer view")
            if aoff % csize or (boff + aoff) % csize or stride % csize:
                raise self.err(f"{ptr}/byteOffset", f"not aligned to its {csize}-byte components",
                               "align accessor and buffer view offsets (glTF 2.0 §3.6.2.4)")
            view = np.ndarray((count, width), dtype=np.dtype(dt), buffer=data, offset=boff + aoff,
                              strides=(stride, csize))
            out = np.array(view)
        if float_only or ctype == 5126:
            out = out.astype(np.float32)
            if normalized and scale is not None:
                out = np.maximum(out / np.float32(scale), -1.0).astype(np.float32)
            if not np.all(np.isfinite(out)):
                raise self.err(ptr, "holds a NaN or infinite value", "export finite values")
        return out


def _quat_matrix(q) -> np.ndarray:
    x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def generate_tangents(p: np.ndarray, n: np.ndarray, uv: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Per-vertex tangents (n, 4) from UV gradients (Lengyel 2001), w = handedness so that B = cross(N, T) w
    points along +v (runtime/meshes.py). Not MikkTSpace-exact. Degenerate UVs fall back to any unit T ⊥ N."""
    tri = idx.reshape(-1, 3).astype(np.int64)
    p, n, uv = p.astype(np.float64), n.astype(np.float64), uv.astype(np.float64)
    e1, e2 = p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]
    d1, d2 = uv[tri[:, 1]] - uv[tri[:, 0]], uv[tri[:, 2]] - uv[tri[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    r = np.where(np.abs(det) > 1e-20, 1.0 / np.where(det == 0, 1.0, det), 0.0)[:, None]
    sdir = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r
    tdir = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r
    ts, bs = np.zeros_like(p), np.zeros_like(p)
    for k in range(3):
        np.add.at(ts, tri[:, k], sdir)
        np.add.at(bs, tri[:, k], tdir)
    t = ts - n * np.sum(n * ts, axis=1, keepdims=True)
    length = np.linalg.norm(t, axis=1, keepdims=True)
    # fallback: any unit vector perpendicular to N
    helper = np.where(np.abs(n[:, 0:1]) < 0.9, np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
    alt = np.cross(helper, n)
    alt /= np.maximum(np.linalg.norm(alt, axis=1, keepdims=True), 1e-30)
    t = np.where(length > 1e-12, t / np.maximum(length, 1e-30), alt)
    w = np.where(np.sum(np.cross(n, t) * bs, axis=1) < 0.0, -1.0, 1.0)
    return np.concatenate([t, w[:, None]], axis=1).astype(np.float32)


def load_gltf(path, lib: Library) -> Scene:
    """Read, check and map a glTF 2.0 file (.gltf or .glb) to a Scene (module docstring: the mapping)."""
    path = Path(path)
    shown = str(path)
    if path.is_dir():
        raise SourceError(shown, 1, 1, "is a directory, not a scene file", "pass a .gltf or .glb file")
    data = _read_bytes(path, "glTF file")
    binary = None
    if path.suffix.lower() == ".glb":
        text, binary = _read_glb(shown, data)
        raw = _parse_json(shown, text, "JSON chunk")
    else:
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError as e:
            line = data.count(b"\n", 0, e.start) + 1
            raise SourceError(shown, line, e.start - (data.rfind(b"\n", 0, e.start) + 1) + 1,
                              f"byte 0x{data[e.start]:02x} is not UTF-8", "save the .gltf as UTF-8") from None
        raw = _parse_json(shown, text)
    if not isinstance(raw, dict):
        raise GltfError(shown, "", "a glTF file is a JSON object", "export the file again")
    rd = _Reader(path, raw, binary)
    asset = rd.get(raw, "asset", "", "obj", hint='add "asset": {"version": "2.0"}')
    version = rd.get(asset, "version", "/asset", "str", hint='write "version": "2.0"')
    if not re.fullmatch(r"2\.\d+", version):
        raise rd.err("/asset/version", f"glTF version '{version}' is not 2.x", "convert the file to glTF 2.0")
    notes: list[str] = []
    accepted = _check_extensions(rd, notes)
    rd.quantized = "KHR_mesh_quantization" in accepted

    from pygltflib import GLTF2  # the maintained reader: the typed document the renderer and tools can use
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            g = GLTF2.load_from_bytes(data) if binary is not None or path.suffix.lower() == ".glb" \
                else GLTF2.gltf_from_json(text.lstrip("\ufeff"))
            g._path, g._name = path.parent, path.name
    except Exception as e:  # pygltflib raises whatever its dataclass decoding meets
        raise rd.err("", f"pygltflib cannot read the document: {type(e).__name__}: {e}"[:300],
                     "check the file with the Khronos glTF validator") from None

    # scene.notes: accepted extensions and what is not applied, one line each; scene.extra: "extensions"
    # (the accepted ones, sorted) and "gltf" (the pygltflib.GLTF2 document: images, samplers, animation, ...)
    scene = Scene(path, path.stem, "linear", "fp32", {}, {}, {}, [], head_at=(1, 1), notes=notes,
                  extra={"extensions": accepted, "gltf": g})
    materials = rd.array("materials")
    for name in ("textures", "images", "samplers", "meshes", "nodes", "accessors", "bufferViews", "buffers", "scenes"):
        rd.array(name)
    mat_names = _unique_names([m.get("name") if isinstance(m.get("name"), str) else "" for m in materials], "material")
    mapped: dict[tuple, GltfMaterial] = {}

    def material(i, colors=False):  # i None: the glTF default material; colors: drawn on primitives with COLOR_0
        if (i, colors) not in mapped:
            name = mat_names[i] if i is not None else _free_name("default", mat_names)
            if colors:  # another shader (vertex_color), so another material: "<name>+COLOR_0"
                name = _free_name(f"{name}+COLOR_0", set(mat_names) | set(scene.materials))
            mapped[(i, colors)] = _material(rd, lib, i, materials[i] if i is not None else {}, name, notes, colors)
            scene.materials[name] = mapped[(i, colors)]
        return mapped[(i, colors)]

    for i in range(len(materials)):  # every material is checked, used or not; unused ones build nothing
        material(i)
    lptr = "/extensions/KHR_lights_punctual"
    lights_def = rd.get(rd.get(raw, "extensions", "", "obj", {}), "KHR_lights_punctual", "/extensions", "obj", {})
    klights = rd.get(lights_def, "lights", lptr, "arr", [])

    nodes = rd.array("nodes")
    scenes = rd.array("scenes")
    if not scenes and rd.array("meshes"):
        notes.append("the file has no scenes: its meshes are not instanced, so no objects")
    set_names = _unique_names([s.get("name") if isinstance(s.get("name"), str) else "" for s in scenes], "scene")
    obj_names: set[str] = set()
    light_names: set[str] = set()
    light_ptrs: dict[str, str] = {}  # light name -> the pointer of its KHR_lights_punctual definition
    asks: dict[str, tuple] = {}  # permutation hash -> (part, pointer) pairs: where its first object asked for it
    hashes: dict[Permutation, str] = {}
    skipped_modes: set[str] = set()
    mesh_cache: dict[tuple, tuple] = {}
    for si, s in enumerate(scenes):
        sptr = _ptr("scenes", si)
        roots = rd.get(s, "nodes", sptr, "arr", [])
        instances = []  # (node index, world matrix) in depth-first order
        seen_here: set[int] = set()

        # depth first, parents before children, without recursion (a deep hierarchy is no stack overflow)
        stack = [(_elem_ref(rd, roots, j, f"{sptr}/nodes", "nodes"), np.eye(4), f"{sptr}/nodes/{j}")
                 for j in reversed(range(len(roots)))]
        while stack:
            ni, parent, ptr = stack.pop()
            if ni in seen_here:
                raise rd.err(ptr, f"node {ni} is reached twice (the nodes must form trees)",
                             "give each node one parent")
            seen_here.add(ni)
            node = nodes[ni]
            world = parent @ _local_matrix(rd, node, _ptr("nodes", ni))
            instances.append((ni, world))
            children = rd.get(node, "children", _ptr("nodes", ni), "arr", [])
            stack += [(_child(rd, node, ni, j), world, _ptr("nodes", ni, "children", j))
                      for j in reversed(range(len(children)))]
        # lights of this scene
        members = []
        for ni, world in instances:
            ext = nodes[ni].get("extensions")
            if not isinstance(ext, dict) or "KHR_lights_punctual" not in ext:
                continue
            nptr = _ptr("nodes", ni, "extensions", "KHR_lights_punctual")
            li = rd.get(ext, "KHR_lights_punctual", _ptr("nodes", ni, "extensions"), "obj")
            k = rd.get(li, "light", nptr, "int")
            if not 0 <= k < len(klights):
                raise rd.err(f"{nptr}/light", f"light {k} does not exist ({len(klights)} lights in {lptr}/lights)",
                             f"use an index from 0 to {len(klights) - 1}" if klights else f"define it in {lptr}/lights")
            base = (klights[k].get("name") if isinstance(klights[k], dict) and isinstance(klights[k].get("name"), str)
                    and klights[k].get("name") else nodes[ni].get("name") if isinstance(nodes[ni].get("name"), str)
                    and nodes[ni].get("name") else f"light{k}")
            lname = _free_name(_clean(base), light_names)
            light_names.add(lname)
            scene.lights[lname] = _light(rd, lib, klights[k], f"{lptr}/lights/{k}", lname, world)
            light_ptrs[lname] = f"{lptr}/lights/{k}"
            members.append(lname)
        if len(members) > MAX_LIGHTS_PER_SET:
            raise rd.err(sptr, f"scene {si} has {len(members)} lights, more than the {MAX_LIGHTS_PER_SET} a "
                         "specialized shader takes (its lights are unrolled)", f"split it into scenes of at most "
                         f"{MAX_LIGHTS_PER_SET} lights")
        lset = set_names[si]
        scene.light_sets[lset] = members
        keys = tuple(LightKey(scene.lights[n].type, scene.lights[n].shadow) for n in members)
        for ni, world in instances:
            node = nodes[ni]
            mi = rd.ref(node, "mesh", _ptr("nodes", ni), "meshes", None)
            if mi is None:
                continue
            mesh = rd.array("meshes")[mi]
            mptr = _ptr("meshes", mi)
            prims = rd.get(mesh, "primitives", mptr, "arr")
            if not prims:
                raise rd.err(f"{mptr}/primitives", "a mesh has at least one primitive", "remove the mesh or add one")
            nname = node.get("name") if isinstance(node.get("name"), str) and node.get("name") else \
                mesh.get("name") if isinstance(mesh.get("name"), str) and mesh.get("name") else f"node{ni}"
            for pi, prim in enumerate(prims):
                pptr = f"{mptr}/primitives/{pi}"
                if not isinstance(prim, dict):
                    raise rd.err(pptr, "must be a JSON object", "each primitive is an object")
                mode = rd.get(prim, "mode", pptr, "int", 4)
                if mode not in _MODES:
                    raise rd.err(f"{pptr}/mode", f"{mode} is not a primitive mode", "use 0 … 6 (4: TRIANGLES)")
                mat_i = rd.ref(prim, "material", pptr, "materials", None)
                attrs = prim.get("attributes")
                m = material(mat_i, isinstance(attrs, dict) and "COLOR_0" in attrs)
                if mode < 4:
                    skipped_modes.add(_MODES[mode])
                    continue
                key = (mi, pi)
                if key not in mesh_cache:
                    mesh_cache[key] = _mesh(rd, prim, pptr, mode, m)
                mesh_obj, tangents, colors = mesh_cache[key]
                oname = _free_name(_clean(nname + (f"#{pi}" if len(prims) > 1 else "")), obj_names)
                obj_names.add(oname)
                perm = Permutation(m.brdf, keys, m.packing, scene.output, scene.precision, m.surface)
                h = hashes.get(perm)
                if h is None:
                    h = hashes[perm] = perm.hash
                    scene.permutations.setdefault(h, perm)
                    asks[h] = ((("brdf", m.source if mat_i is not None else pptr),)
                               + ((("vertex_color", f"{pptr}/attributes/COLOR_0"),) if m.surface.vertex_color else ())
                               + tuple((f"light{k}", light_ptrs[n]) for k, n in enumerate(members)))
                scene.users.setdefault(h, []).append(oname)
                scene.objects.append({"name": oname, "material": m.name, "light_set": lset, "lights": list(members),
                                      "permutation": h, "node": ni, "mesh_index": mi, "primitive": pi,
                                      "source": pptr, "mesh": mesh_obj, "model": world.tolist(),
                                      "alpha_mode": m.alpha_mode, "alpha_cutoff": m.alpha_cutoff,
                                      "double_sided": m.double_sided, "tangents": tangents, "vertex_colors": colors})
    for h, origin in origins(shown, text, asks, binary is not None or path.suffix.lower() == ".glb").items():
        scene.permutations[h] = replace(scene.permutations[h], origin=origin)
        scene.where.setdefault(h, (origin.parts[0][1].line, origin.parts[0][1].col))
    if skipped_modes:
        notes.append(f"primitives drawn as {', '.join(sorted(skipped_modes))} are not shaded: skipped")
    gen = sorted({o["name"] for o in scene.objects if o["tangents"] == "generated"})
    if gen:
        notes.append(f"tangents generated from UV gradients (Lengyel; not MikkTSpace-exact) for: {', '.join(gen)}")
    from .gltf_images import bind_images  # every material's texture images and samplers, read and checked
    bind_images(rd, lib, scene, text, binary is not None or path.suffix.lower() == ".glb", notes)
    scene.notes = list(dict.fromkeys(notes))
    return scene


def _child(rd: _Reader, node: dict, ni: int, j: int) -> int:
    return _elem_ref(rd, node["children"], j, _ptr("nodes", ni, "children"), "nodes")


def _elem_ref(rd: _Reader, arr: list, j: int, ptr: str, target: str) -> int:
    v = arr[j]
    n = len(rd.array(target))
    if not isinstance(v, int) or isinstance(v, bool) or not 0 <= v < n:
        raise rd.err(f"{ptr}/{j}", f"{json.dumps(v)[:30]} is not an index of {target} (the file has {n})",
                     f"use an index from 0 to {n - 1}" if n else f"add the {target} it refers to")
    return v


def _local_matrix(rd: _Reader, node: dict, ptr: str) -> np.ndarray:
    if "matrix" in node:
        for k in ("translation", "rotation", "scale"):
            if k in node:
                raise rd.err(f"{ptr}/{k}", "a node has either matrix or translation/rotation/scale, not both",
                             "keep one")
        return np.array(rd.nums(node, "matrix", ptr, 16), dtype=np.float64).reshape(4, 4).T  # column-major
    t = rd.nums(node, "translation", ptr, 3, [0.0, 0.0, 0.0])
    r = rd.nums(node, "rotation", ptr, 4, [0.0, 0.0, 0.0, 1.0])
    s = rd.nums(node, "scale", ptr, 3, [1.0, 1.0, 1.0])
    m = np.eye(4)
    m[:3, :3] = _quat_matrix(r) @ np.diag(s)
    m[:3, 3] = t
    return m


def _clean(name: str) -> str:
    name = "".join(c for c in name if c.isprintable()).strip() or "unnamed"
    return name[:200]


def _free_name(base: str, taken) -> str:
    if base not in taken:
        return base
    k = 2
    while f"{base}~{k}" in taken:
        k += 1
    return f"{base}~{k}"


def _unique_names(names: list[str], prefix: str) -> list[str]:
    out: list[str] = []
    for i, n in enumerate(names):
        out.append(_free_name(_clean(n) if n else f"{prefix}{i}", set(out)))
    return out


def _check_extensions(rd: _Reader, notes: list) -> list[str]:
    """Every extension used, by where: errors for the shading ones and unknown KHR_ ones, notes for the rest."""
    used: dict[str, str] = {}

    def walk(x, ptr):
        if isinstance(x, dict):
            ext = x.get("extensions")
            if ext is not None and not isinstance(ext, dict):
                raise rd.err(f"{ptr}/extensions", "must be a JSON object", "write \"extensions\": {…}")
            for name in (ext or {}):
                used.setdefault(name, f"{ptr}/extensions/{_ptr(name)[1:]}")
            for k, v in x.items():
                walk(v, f"{ptr}/{_ptr(k)[1:]}")
        elif isinstance(x, list):
            for i, v in enumerate(x):
                walk(v, f"{ptr}/{i}")

    try:
        walk(rd.raw, "")
    except RecursionError:
        raise rd.err("", "the JSON nests too deeply to read", "check the file") from None
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


def _texture_info(rd: _Reader, d: dict, key: str, ptr: str) -> dict | None:
    info = rd.get(d, key, ptr, "obj", None)
    if info is None:
        return None
    here = f"{ptr}/{key}"
    ti = rd.ref(info, "index", here, "textures")
    texture_transform.check_texcoord(rd, info, here)  # TEXCOORD_0 (KHR_texture_transform may choose the set)
    tex = rd.array("textures")[ti]
    src = rd.ref(tex, "source", _ptr("textures", ti), "images", None)
    if "sampler" in tex:
        rd.ref(tex, "sampler", _ptr("textures", ti), "samplers")
    out = {"texture": ti, "image": src}
    if src is not None:
        img = rd.array("images")[src]
        uri = rd.get(img, "uri", _ptr("images", src), "str", None)
        if uri is not None and not uri.startswith("data:"):
            out["uri"] = uri
        if "bufferView" in img:
            out["bufferView"] = rd.ref(img, "bufferView", _ptr("images", src), "bufferViews")
    return out


def _material(rd: _Reader, lib: Library, i, m: dict, name: str, notes: list, colors: bool = False) -> GltfMaterial:
    """Material i (None: glTF's default material) mapped to a GltfMaterial; colors: the primitives drawn with it
    carry COLOR_0 (the vertex_color part of the surface state)."""
    ptr = _ptr("materials", i) if i is not None else "/materials (default material)"
    pbr = rd.get(m, "pbrMetallicRoughness", ptr, "obj", {})
    pptr = f"{ptr}/pbrMetallicRoughness"
    base = rd.nums(pbr, "baseColorFactor", pptr, 4, [1.0, 1.0, 1.0, 1.0], 0.0, 1.0)
    metallic = rd.num(pbr, "metallicFactor", pptr, 1.0, 0.0, 1.0)
    roughness = rd.num(pbr, "roughnessFactor", pptr, 1.0, 0.0, 1.0)
    tex_base = _texture_info(rd, pbr, "baseColorTexture", pptr)
    tex_mr = _texture_info(rd, pbr, "metallicRoughnessTexture", pptr)
    tex_n = _texture_info(rd, m, "normalTexture", ptr)
    tex_o = _texture_info(rd, m, "occlusionTexture", ptr)
    tex_e = _texture_info(rd, m, "emissiveTexture", ptr)
    emissive = rd.nums(m, "emissiveFactor", ptr, 3, [0.0, 0.0, 0.0], 0.0, 1.0)
    strength = _emissive_strength(rd, m, ptr)
    alpha_mode = rd.get(m, "alphaMode", ptr, "str", "OPAQUE")
    if alpha_mode not in ("OPAQUE", "MASK", "BLEND"):
        raise rd.err(f"{ptr}/alphaMode", f"'{alpha_mode}' is not an alpha mode", "use OPAQUE, MASK or BLEND")
    cutoff = rd.num(m, "alphaCutoff", ptr, 0.5, 0.0, None)
    double = rd.get(m, "doubleSided", ptr, "bool", False)
    if tex_n is not None:
        scale = rd.num(m["normalTexture"], "scale", f"{ptr}/normalTexture", 1.0)
        if scale != 1.0:
            notes.append(f"material '{name}': normalTexture.scale {scale} is not applied (normal_map has no scale)")
    if tex_o is not None:
        notes.append(f"material '{name}': occlusionTexture is not read (it scales indirect light; "
                     "the light loop has direct lights only)")
    normal = "normal_map" if tex_n is not None else "vertex"
    sampled = [(pbr, "baseColorTexture", pptr), (pbr, "metallicRoughnessTexture", pptr), (m, "normalTexture", ptr)]
    sampled += [(m, "emissiveTexture", ptr)] if any(c * strength for c in emissive) else []
    uv, uv_params = texture_transform.of_material(rd, sampled)  # KHR_texture_transform: the packing's uv slot
    r2 = roughness * roughness
    textures: dict = {}
    if tex_n is not None:
        textures["normal_map"] = tex_n
    if tex_base is None and tex_mr is None:
        packing = f"constants(normal={normal}{uv})"
        params = {"rho_d": [c * (1.0 - metallic) for c in base[:3]],
                  "f0": [0.04 + (c - 0.04) * metallic for c in base[:3]], "alpha": r2}
    elif tex_mr is None and metallic == 0.0:
        packing = f"albedo_texture(normal={normal}{uv})"
        params = {"rho_d": base[:3], "f0": [0.04, 0.04, 0.04], "alpha": r2}
        textures["albedo_map"] = tex_base
    else:
        packing = f"gltf_metallic_roughness(normal={normal}{uv})"
        params = {"base_color": base[:3], "metallic": metallic, "roughness": roughness}
        textures["base_color_map"] = tex_base or "white"
        textures["orm_map"] = tex_mr or "white"
    params.update(uv_params)
    # the surface state (spec/surface.py): each part only where it changes what the shader computes
    lit = [c * strength for c in emissive]
    surface = Surface(alpha=alpha_mode.lower(), double_sided=double, vertex_color=colors,
                      emissive="texture" if tex_e is not None and any(lit) else "factor" if any(lit) else "none")
    if alpha_mode != "OPAQUE":
        params["base_alpha"] = base[3]
    if alpha_mode == "MASK":
        params["alpha_cutoff"] = cutoff
    if surface.emissive != "none":
        params["emissive"] = lit
    if surface.emissive == "texture":
        textures[EMISSIVE_MAP] = tex_e
    elif tex_e is not None:
        notes.append(f"material '{name}': emissiveTexture is not sampled (emissiveFactor is 0)")
    try:
        brdf = canonical(parse_brdf(BRDF, lib))
        packing = canonical(parse_spec(packing, lib, ("packing",)))
        r = resolve(Permutation(brdf, (), packing, "linear", surface=surface), lib)
    except (SpecError, SourceError) as e:
        raise rd.err(ptr, f"the bricks this material maps to are missing: {e}",
                     "use the standard brick library (or --bricks with lambert, microfacet, ggx, …)") from None
    # outside the try: its own located error (a GltfError is a SourceError) is not "missing bricks"
    specs = surface_specs(r, lambda key, msg, todo: rd.err(ptr, msg, todo))
    for k, v in params.items():
        problem = specs[k].check(v) if k in specs else f"no parameter '{k}'"
        if problem:
            raise rd.err(ptr, f"maps to parameter '{k}' = {v}: {problem}", "fix the material's factors")
    problem, todo = check_packing(r)
    if problem:
        raise rd.err(ptr, problem, todo)
    return GltfMaterial(name, brdf, packing, params, surface, alpha_mode=alpha_mode, alpha_cutoff=cutoff,
                        double_sided=double, base_alpha=base[3], textures=textures, source=ptr)


def _emissive_strength(rd: _Reader, m: dict, ptr: str) -> float:
    """KHR_materials_emissive_strength's emissiveStrength (1 without it): it scales emissiveFactor."""
    ext = m.get("extensions")
    if not isinstance(ext, dict) or "KHR_materials_emissive_strength" not in ext:
        return 1.0
    eptr = f"{ptr}/extensions/KHR_materials_emissive_strength"
    e = rd.get(ext, "KHR_materials_emissive_strength", f"{ptr}/extensions", "obj")
    return rd.num(e, "emissiveStrength", eptr, 1.0, 0.0, None)


def _light(rd: _Reader, lib: Library, L, ptr: str, name: str, world: np.ndarray) -> Light:
    if not isinstance(L, dict):
        raise rd.err(ptr, "must be a JSON object", "each light is an object")
    ltype = rd.get(L, "type", ptr, "str")
    color = rd.nums(L, "color", ptr, 3, [1.0, 1.0, 1.0], 0.0, None)
    intensity = rd.num(L, "intensity", ptr, 1.0, 0.0, None)
    rng = rd.num(L, "range", ptr, None, 0.0, None) if "range" in L else None
    if rng is not None and rng <= 0:
        raise rd.err(f"{ptr}/range", "range must be greater than 0", "remove it (infinite) or give a positive range")
    c = [x * intensity for x in color]
    pos = [float(x) for x in world[:3, 3]]
    axis = world[:3, :3] @ np.array([0.0, 0.0, -1.0])  # the light shines along its node's −Z
    norm = float(np.linalg.norm(axis))
    if norm < 1e-12 and ltype in ("directional", "spot"):
        raise rd.err(ptr, f"light '{name}' has a degenerate node transform (its −Z axis has length 0)",
                     "give the light's node a non-zero scale")
    axis = [float(x) / (norm or 1.0) for x in axis]
    if ltype == "directional":
        brick, params = "directional", {"direction": [-a for a in axis], "color": c}
    elif ltype == "point":
        brick, params = ("point", {"position": pos, "color": c}) if rng is None else \
            ("point_range", {"position": pos, "color": c, "radius": rng})
    elif ltype == "spot":
        sp = rd.get(L, "spot", ptr, "obj", {})
        inner = rd.num(sp, "innerConeAngle", f"{ptr}/spot", 0.0, 0.0, math.pi / 2)
        outer = rd.num(sp, "outerConeAngle", f"{ptr}/spot", math.pi / 4, 0.0, math.pi / 2)
        if inner >= outer:
            raise rd.err(f"{ptr}/spot/innerConeAngle", f"innerConeAngle {inner} is not below outerConeAngle {outer}",
                         "make innerConeAngle < outerConeAngle")
        lim = 1.5707963  # the spot brick's range: π/2 rounded down to float32
        brick, params = "spot", {"position": pos, "direction": axis, "color": c,
                                 "radius": rng if rng is not None else SPOT_NO_RANGE,
                                 "inner_angle": min(inner, lim), "outer_angle": min(outer, lim)}
    else:
        raise rd.err(f"{ptr}/type", f"'{ltype}' is not a KHR_lights_punctual type", "use directional, point or spot")
    lb = lib.get("light", brick)
    snode = parse_spec("none", lib, ("shadow",))[0] if lib.get("shadow", "none") is not None else None
    if lb is None or snode is None:
        raise rd.err(ptr, f"light brick '{brick}' (or shadow 'none') is missing from the library",
                     "use the standard bricks")
    specs = light_params(lib, brick, "none")
    for k, v in params.items():
        problem = specs[k].check(v) if k in specs else f"no parameter '{k}'"
        if problem:
            raise rd.err(ptr, f"light '{name}' maps to {brick} parameter '{k}' = {v}: {problem}",
                         "fix the light's color, intensity, range or node transform")
    return Light(name, brick, "none", params)


def _mesh(rd: _Reader, prim: dict, pptr: str, mode: int, m: GltfMaterial):
    """(runtime Mesh, tangents "file" | "generated", has COLOR_0) of one primitive."""
    from .mesh import Mesh

    aptr = f"{pptr}/attributes"
    attrs = rd.get(prim, "attributes", pptr, "obj")
    for k, v in attrs.items():
        rd.ref(attrs, k, pptr + "/attributes", "accessors")
    if "POSITION" not in attrs:
        raise rd.err(f"{aptr}/POSITION", "'POSITION' is required here", "export the mesh with positions")
    pos = rd.accessor(attrs["POSITION"], f"{aptr}/POSITION", ("VEC3",), float_only=True)
    n = len(pos)

    def attr(key, types):
        if key not in attrs:
            return None
        a = rd.accessor(attrs[key], f"{aptr}/{key}", types, float_only=True)
        if len(a) != n:
            raise rd.err(f"{aptr}/{key}", f"{len(a)} elements, but POSITION has {n}",
                         "give every attribute one per vertex")
        return a

    nrm, tan, uv = attr("NORMAL", ("VEC3",)), attr("TANGENT", ("VEC4",)), attr("TEXCOORD_0", ("VEC2",))
    colors = attr("COLOR_0", ("VEC3", "VEC4"))
    if colors is not None and colors.shape[1] == 3:  # RGB: alpha 1 (glTF 3.7.2.1)
        colors = np.concatenate([colors, np.ones((len(colors), 1), np.float32)], axis=1)
    if "indices" in prim:
        ii = rd.ref(prim, "indices", pptr, "accessors")
        a = rd.array("accessors")[ii]
        if a.get("componentType") not in (5121, 5123, 5125):
            raise rd.err(_ptr("accessors", ii, "componentType"), "indices must be unsigned bytes, shorts or ints",
                         "use componentType 5121, 5123 or 5125")
        idx = rd.accessor(ii, f"{pptr}/indices", ("SCALAR",)).reshape(-1).astype(np.int64)
        if idx.size and int(idx.max()) >= n:
            raise rd.err(f"{pptr}/indices", f"index {int(idx.max())} is past the {n} vertices", "fix the index buffer")
    else:
        idx = np.arange(n, dtype=np.int64)
    if mode in (5, 6):  # glTF 2.0 §3.7.2.1: strip triangle i = (v_i, v_i+1+i%2, v_i+2-i%2); fan: (v_i+1, v_i+2, v_0)
        k = np.arange(max(len(idx) - 2, 0))
        if mode == 5:
            odd = k % 2
            idx = np.stack([idx[k], idx[k + 1 + odd], idx[k + 2 - odd]], axis=1).reshape(-1)
        else:
            idx = np.stack([idx[k + 1], idx[k + 2], np.full_like(k, idx[0])], axis=1).reshape(-1)
    if idx.size % 3:
        raise rd.err(f"{pptr}/indices", f"{idx.size} indices do not form whole triangles",
                     "give 3 indices per triangle")
    if textures_need_uv(m) and uv is None:
        raise rd.err(f"{aptr}", f"material '{m.name}' samples textures but the primitive has no TEXCOORD_0",
                     "export the mesh with texture coordinates")
    if nrm is None:  # flat normals: unweld the triangles (glTF 2.0 §3.7.2.1)
        pos, idx_old = pos[idx], idx
        uv = uv[idx_old] if uv is not None else None
        colors = colors[idx_old] if colors is not None else None
        tan = None
        idx = np.arange(len(pos), dtype=np.int64)
        tri = pos.reshape(-1, 3, 3).astype(np.float64)
        fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-30)
        nrm = np.repeat(fn, 3, axis=0).astype(np.float32)
    if uv is None:
        uv = np.zeros((len(pos), 2), np.float32)
    source = "file"
    if tan is None:
        tan = generate_tangents(pos, nrm, uv, idx) if idx.size else np.zeros((len(pos), 4), np.float32)
        source = "generated" if "normal_map" in m.textures else "none"
    f = lambda x: np.ascontiguousarray(x, dtype=np.float32)  # noqa: E731
    mesh = Mesh(f(pos), f(nrm), f(tan), f(uv), np.ascontiguousarray(idx, dtype=np.uint32),
                f(colors) if colors is not None else None)
    return mesh, source, colors is not None


def textures_need_uv(m: GltfMaterial) -> bool:
    return any(v != "white" for v in m.textures.values())
