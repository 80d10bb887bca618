"""A glTF 2.0 file's container, read and checked: the .gltf's JSON or the .glb's chunks, buffers, accessors.

pygltflib (pinned in requirements.lock) reads the container: the JSON text into its GLTF2 object, a
`.glb`'s chunks (after the strict checks below), data URIs. pygltflib checks nothing, so every value
the import (scene/gltf.py) uses is first checked, on the parsed JSON, through a Reader, and a bad one is
ONE error naming the file and the JSON pointer: `model.gltf: /materials/3/pbrMetallicRoughness/
baseColorTexture/index: ... — what to do` (GltfError, a SourceError: the CLI exits 1). A `.glb` whose
header or chunks are broken is named by byte offset (`model.glb: byte 20 (chunk 0): ...`); a JSON syntax
error by line:col.

Buffers: a relative file path beside the .gltf (percent-encoded), a base64 data URI, or buffer 0 as a
.glb's BIN chunk; each read once, at most MAX_GLTF_BYTES. Accessors are checked against their buffer
view (bounds, alignment, finite values); quantized attributes (KHR_mesh_quantization: normalized or
plain integers) are decoded to float32.
"""
from __future__ import annotations

import binascii
import json
import math
import re
import struct
import warnings
from pathlib import Path

import numpy as np

from ..lang import SourceError
from ..lang.errors import read_bytes
from .jsonpos import pointer

MAX_GLTF_BYTES = 256 << 20  # a .gltf, .glb or .bin larger than this is refused

_COMPONENTS = {5120: ("i1", 127.0), 5121: ("u1", 255.0), 5122: ("<i2", 32767.0), 5123: ("<u2", 65535.0),
               5125: ("<u4", None), 5126: ("<f4", None)}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
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


def open_gltf(path: Path) -> tuple[Reader, str, bytes]:
    """(the Reader of the parsed JSON, the JSON text, the file's bytes) of a .gltf or .glb whose container,
    JSON and asset version are checked."""
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
    rd = Reader(path, raw, binary)
    asset = rd.get(raw, "asset", "", "obj", hint='add "asset": {"version": "2.0"}')
    version = rd.get(asset, "version", "/asset", "str", hint='write "version": "2.0"')
    if not re.fullmatch(r"2\.\d+", version):
        raise rd.err("/asset/version", f"glTF version '{version}' is not 2.x", "convert the file to glTF 2.0")
    return rd, text, data


def pygltf_document(rd: Reader, data: bytes, text: str):
    """The pygltflib.GLTF2 document of the checked file (the typed document the renderer and tools can use)."""
    from pygltflib import GLTF2  # the maintained reader
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            g = GLTF2.load_from_bytes(data) if rd.glb else GLTF2.gltf_from_json(text.lstrip("\ufeff"))
            g._path, g._name = rd.path.parent, rd.path.name
    except Exception as e:  # pygltflib raises whatever its dataclass decoding meets
        raise rd.err("", f"pygltflib cannot read the document: {type(e).__name__}: {e}"[:300],
                     "check the file with the Khronos glTF validator") from None
    return g


class Reader:
    """Checked access to the parsed JSON: every failure is a GltfError at its JSON pointer."""

    def __init__(self, path: Path, raw: dict, binary):
        self.path, self.shown, self.raw, self.binary = path, str(path), raw, binary
        self.glb = binary is not None or path.suffix.lower() == ".glb"  # its errors name byte offsets, not lines
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
                raise self.err(pointer(name, i), "must be a JSON object", f"each entry of '{name}' is an object")
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
        ptr = pointer("buffers", i)
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
        ptr = pointer("accessors", i)
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
        out = self._elements(a, ptr, count, np.dtype(dt), atype)
        if float_only or ctype == 5126:
            out = out.astype(np.float32)
            if normalized and scale is not None:
                out = np.maximum(out / np.float32(scale), -1.0).astype(np.float32)
            if not np.all(np.isfinite(out)):
                raise self.err(ptr, "holds a NaN or infinite value", "export finite values")
        return out

    def _elements(self, a: dict, ptr: str, count: int, dt: np.dtype, atype: str) -> np.ndarray:
        """Accessor `a`'s count rows of components from its buffer view (zeros without one), whose bounds,
        extent and alignment are checked."""
        width = _WIDTH[atype]
        csize = dt.itemsize
        bvi = self.ref(a, "bufferView", ptr, "bufferViews", None)
        if bvi is None:
            return np.zeros((count, width), np.float32)
        bptr = pointer("bufferViews", bvi)
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
        view = np.ndarray((count, width), dtype=dt, buffer=data, offset=boff + aoff, strides=(stride, csize))
        return np.array(view)
