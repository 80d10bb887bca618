"""Shader packs (`build --pack`): one content-addressed file per platform, its artifacts by permutation.

A pack holds what its platform loads (assemble/platforms.py PLATFORM_TABLE ``blob``): ``vulkan`` the optimized SPIR-V of
the GLSL, ``d3d12`` DXIL where dxc built it and the HLSL text otherwise, ``gl`` the GLSL 4.50 core text,
``webgpu`` the WGSL text; the metadata's ``blob`` says which (``spirv``, ``dxil``, ``hlsl``, ``glsl``,
``wgsl``). The depth passes' units (the manifest's ``depth_shaders``) are packed beside the permutations,
each under its entry's 12-hex ``hash``: an engine loads every shader it draws with from the pack. ``DIR/packs/<platform>.<key16>.smpack``, ``key16`` the first 16 hex digits of the pack key.
The file is named by its key, like every artifact of the tree: a rebuild writes a new file beside the
old one, the manifest (``packs``: platform, language, path, sha256, key, entries, size) is replaced, and
only then is the old pack removed. The ubershader is in the vulkan pack (the other platforms do not build it).

Format, version 1 (all integers little-endian, fixed widths; offsets from the start of the file)::

    header, 56 bytes
      0   8  magic            b"SMPACK\\r\\n"
      8   4  u32 version      1
     12   4  u32 count        N, the number of index entries
     16  32  pack key         raw sha256 (see below)
     48   4  u32 meta_length  M
     52   4  u32 reserved     0
    meta, M bytes at 56       UTF-8 JSON, sorted keys, separators "," ":" — {"format": "smpack",
                              "generator": "shadermatrix X.Y.Z", "language": "glsl", "platform":
                              "vulkan", "blob": "spirv", "spirv_version": "1.3",
                              "target_env": "vulkan1.1", "tools": {tool: exact version}}
    zero padding to a multiple of 8
    index, N entries of 104 bytes, sorted by (permutation, stage), no two alike
      0  16  permutation      ASCII, NUL-padded: the manifest's 12-hex ``hash`` (a permutation's or a depth
                              unit's, ``depth_shaders.<unit>.hash``), or ``ubershader``
     16   8  stage            ASCII, NUL-padded: ``vert``, ``frag``
     24  32  input key        raw sha256: the manifest entry's ``input_key``
     56  32  blob sha256      raw sha256 of the blob
     88   8  u64 offset
     96   8  u64 length
    blobs                     the optimized SPIR-V modules, each distinct module once, in order of first
                              use by the index, back to back from the end of the index to the end of the
                              file (entries with identical SPIR-V share one blob; nothing follows the last)

The pack key is ``sha256`` of the UTF-8 JSON (sorted keys, separators "," ":") of
``["smpack", 1, meta, [[permutation, stage, input_key_hex, blob_sha256_hex], …]]`` (the index order).
The input keys cover the bricks' and templates' contents, the generator's own code and version, the
compilers' exact versions and the toolchain's flags (``build._perm_key``), and the meta holds the tool
versions again: a tool upgrade gives a new key, a new file name, and no entry of the old pack is served
for the new inputs. Only entries whose status is ``ok`` are packed (a stale entry's SPIR-V is that of
older inputs; a failed one has none). No times, sorted entries: two builds give the same bytes.

``read_pack(path)`` checks everything (magic, version, sizes, the metadata in exactly its canonical form,
offsets and lengths in bounds, blobs
contiguous with nothing after the last, every blob's sha256, the key) and raises ``PackError`` (a
``UserError``) naming the file and what is wrong; ``lookup(pack, permutation, stage)`` returns a blob.
"""
from __future__ import annotations

import hashlib
import json
import os
import stat
import struct
from dataclasses import dataclass
from pathlib import Path

from ..io import atomic_write
from ..lang.errors import UserError

MAGIC = b"SMPACK\r\n"
VERSION = 1
HEADER = struct.Struct("<8sII32sII")  # magic, version, count, key, meta length, reserved
ENTRY = struct.Struct("<16s8s32s32sQQ")  # permutation, stage, input key, blob sha256, offset, length
PACKS = "packs"
SUFFIX = ".smpack"


class PackError(UserError):
    """A pack that cannot be trusted (damaged, truncated, not a pack): the message names the file and why."""


@dataclass(frozen=True)
class PackEntry:
    permutation: str  # the manifest's 12-hex hash, or "ubershader"
    stage: str        # "vert", "frag"
    input_key: str    # hex: the manifest entry's input_key
    sha256: str       # hex: sha256 of data
    offset: int
    length: int
    data: bytes


def _canonical(obj) -> bytes:
    return json.dumps(obj, sort_keys=True, separators=(",", ":")).encode()


def pack_key(meta: dict, rows) -> str:
    """rows: [(permutation, stage, input_key hex, sha256 hex)] in index order."""
    return hashlib.sha256(_canonical(["smpack", VERSION, meta, [list(r) for r in rows]])).hexdigest()


def _field(text: str, width: int, what: str) -> bytes:
    raw = text.encode("ascii")
    if len(raw) > width or b"\0" in raw:
        raise ValueError(f"{what} {text!r} does not fit the pack's {width}-byte field")
    return raw.ljust(width, b"\0")


def encode_pack(meta: dict, entries) -> tuple[bytes, str]:
    """(the pack's bytes, its key); entries: (permutation, stage, input_key hex, spirv bytes), any order."""
    rows = sorted(entries, key=lambda e: (e[0], e[1]))
    for a, b in zip(rows, rows[1:]):
        if (a[0], a[1]) == (b[0], b[1]):
            raise ValueError(f"two pack entries for {a[0]} {a[1]}")
    shas = [hashlib.sha256(e[3]).hexdigest() for e in rows]
    key = pack_key(meta, [(e[0], e[1], e[2], s) for e, s in zip(rows, shas)])
    meta_bytes = _canonical(meta)
    index_at = HEADER.size + len(meta_bytes) + (-(HEADER.size + len(meta_bytes)) % 8)
    at = index_at + ENTRY.size * len(rows)
    blobs, where, index = [], {}, []
    for (perm, stage, input_key, data), sha in zip(rows, shas):
        if sha not in where:
            where[sha] = at
            blobs.append(data)
            at += len(data)
        index.append(ENTRY.pack(_field(perm, 16, "permutation"), _field(stage, 8, "stage"), bytes.fromhex(input_key),
                                bytes.fromhex(sha), where[sha], len(data)))
    head = HEADER.pack(MAGIC, VERSION, len(rows), bytes.fromhex(key), len(meta_bytes), 0)
    body = head + meta_bytes + b"\0" * (index_at - HEADER.size - len(meta_bytes))
    return body + b"".join(index) + b"".join(blobs), key


def _text(raw: bytes, what: str, fail) -> str:
    text = raw.rstrip(b"\0")
    if b"\0" in text or not text:
        fail(f"index entry has a malformed {what} field")
    try:
        return text.decode("ascii")
    except UnicodeDecodeError:
        fail(f"index entry has a non-ASCII {what} field")


# The metadata is read only in the form encode_pack writes it, json.dumps(sort_keys, separators), so that a
# reader can hash the key from its bytes as they are: include/shadermatrix/pack.h, which cannot re-encode
# JSON, accepts exactly these bytes (no floats: their canonical text is Python's repr; integers in 64 bits).
META_DEPTH = 32


def _meta_int(text: str) -> int:
    value = int(text)
    if not -2**63 <= value < 2**63:
        raise ValueError("an integer past 64 bits")
    return value


def _meta_float(text: str):
    raise ValueError(f"a non-integer number {text[:20]}")


def _depth(value) -> int:
    """How deep `value` nests (an object or array is 1 more than its deepest member); stops past META_DEPTH."""
    deepest, todo = 0, [(value, 1)]
    while todo and deepest <= META_DEPTH:
        v, d = todo.pop()
        if isinstance(v, (dict, list)):
            deepest = max(deepest, d)
            todo += [(x, d + 1) for x in (v.values() if isinstance(v, dict) else v)]
    return deepest


def read_pack(path) -> dict:
    """A pack, checked whole: {"path", "version", "key", "meta", "language", "tools", "generator",
    "entries": {(permutation, stage): PackEntry}}. Raises PackError naming the file and the defect."""
    path = Path(path)

    def fail(why: str):
        raise PackError(f"{path}: not a valid shader pack — {why} (rebuild it with `shadermatrix build --pack`)")

    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode):
            fail("not a regular file")
        data = path.read_bytes()
    except OSError as e:
        raise PackError(f"{path}: cannot read the shader pack — {e.strerror or e}") from None
    if len(data) < len(MAGIC) or data[:len(MAGIC)] != MAGIC:
        fail(f"bad magic {data[:len(MAGIC)]!r} (expected {MAGIC!r})")
    if len(data) < HEADER.size:
        fail(f"truncated: {len(data)} bytes, shorter than the {HEADER.size}-byte header")
    _, version, count, key_raw, meta_len, reserved = HEADER.unpack_from(data, 0)
    if version != VERSION:
        fail(f"format version {version}, this reader reads version {VERSION}")
    if reserved != 0:
        fail(f"reserved header field is {reserved}, not 0")
    index_at = HEADER.size + meta_len + (-(HEADER.size + meta_len) % 8)
    blobs_at = index_at + ENTRY.size * count
    if blobs_at > len(data):
        fail(f"truncated: the header announces {count} entries and {meta_len} bytes of metadata, ending at byte "
             f"{blobs_at}, but the file has {len(data)} bytes")
    raw_meta = data[HEADER.size:HEADER.size + meta_len]
    try:
        meta = json.loads(raw_meta.decode("utf-8"), parse_int=_meta_int, parse_float=_meta_float,
                          parse_constant=_meta_float)
    except (UnicodeDecodeError, ValueError, RecursionError):
        fail("the metadata is not JSON (or holds a non-integer number, or an integer past 64 bits)")
    if not isinstance(meta, dict) or meta.get("format") != "smpack":
        fail("the metadata is not a shader pack's")
    if _canonical(meta) != raw_meta or _depth(meta) > META_DEPTH:
        fail(f"the metadata is not canonical JSON (sorted keys, no spaces, ASCII, nested at most {META_DEPTH} deep)")
    if any(data[HEADER.size + meta_len:index_at]):
        fail("non-zero padding after the metadata")
    entries: dict = {}
    rows, ranges = [], {}
    previous = None
    for i in range(count):
        perm_raw, stage_raw, ik, sha, offset, length = ENTRY.unpack_from(data, index_at + i * ENTRY.size)
        perm, stage = _text(perm_raw, "permutation", fail), _text(stage_raw, "stage", fail)
        if previous is not None and (perm, stage) <= previous:
            fail(f"index entry {i} ({perm} {stage}) is out of order or repeated")
        previous = (perm, stage)
        if offset < blobs_at or offset + length > len(data):
            fail(f"index entry {i} ({perm} {stage}) points at bytes {offset}..{offset + length}, outside the blobs "
                 f"({blobs_at}..{len(data)}): the file is truncated or its index damaged")
        blob = data[offset:offset + length]
        if hashlib.sha256(blob).digest() != sha:
            fail(f"sha256 mismatch in the blob of {perm} {stage} (bytes {offset}..{offset + length}): it is damaged")
        if ranges.setdefault(offset, length) != length:
            fail(f"index entry {i} ({perm} {stage}) overlaps another blob at byte {offset}")
        rows.append((perm, stage, ik.hex(), sha.hex()))
        entries[(perm, stage)] = PackEntry(perm, stage, ik.hex(), sha.hex(), offset, length, blob)
    end = blobs_at
    for offset in sorted(ranges):
        if offset != end:
            fail(f"the blobs are not contiguous: a gap or an overlap at byte {min(offset, end)}")
        end = offset + ranges[offset]
    if end != len(data):
        fail(f"{len(data) - end} bytes of trailing garbage after the last blob (byte {end})")
    key = key_raw.hex()
    if pack_key(meta, rows) != key:
        fail("the pack key does not match its metadata and index (damaged header or index)")
    return {"path": str(path), "version": version, "key": key, "meta": meta, "language": meta.get("language"),
            "platform": meta.get("platform"), "tools": meta.get("tools"), "generator": meta.get("generator"),
            "entries": entries}


def lookup(pack: dict, permutation: str, stage: str) -> bytes:
    """The SPIR-V of `permutation` (its 12-hex hash, its canonical id, or "ubershader") at `stage`."""
    perm = permutation
    if (perm, stage) not in pack["entries"] and "=" in perm:  # a canonical id: its hash (matrix.permutation)
        perm = hashlib.sha256(perm.encode()).hexdigest()[:12]
    entry = pack["entries"].get((perm, stage))
    if entry is None:
        raise PackError(f"{pack['path']}: no entry for permutation {permutation} stage {stage} "
                        f"({len(pack['entries'])} entries; build it with `shadermatrix build --pack`)")
    return entry.data


# ------------------------------------------------------------------ writing (the build)

def pack_meta(platform: str, language: str, blob: str, generator: str, tools: dict) -> dict:
    from ..toolchain import SPIRV_VERSION, TARGET_ENV
    return {"format": "smpack", "generator": generator, "language": language, "platform": platform, "blob": blob,
            "spirv_version": SPIRV_VERSION, "target_env": TARGET_ENV, "tools": dict(sorted(tools.items()))}


def _packed(entry: dict, name: str, platform: str):
    """(permutation name, stage, input key, blob kind, path, sha256) of an ok manifest entry on `platform`."""
    return rows_of(entry, name, platform, ok_only=True)


def rows_of(entry: dict, name: str, platform: str, ok_only: bool = False):
    """What the pack of `platform` holds of a manifest entry, as _packed gives it; ok_only: only of an ok entry
    (the pack's rule); else of an entry whatever its status (build --pack-only keeps them as it writes them)."""
    from .platforms import PLATFORM_TABLE
    p = PLATFORM_TABLE[platform]
    if ok_only and entry.get("status") != "ok":
        return
    if name == "ubershader":  # built as SPIR-V only: in the pack of the platform that ships it (vulkan's)
        if p.ubershader:
            for stage, item in entry.get("languages", {}).get(p.made_from, {}).items():
                if "spirv" in item:
                    yield name, stage, entry["input_key"], "spirv", item["spirv"], item["spirv_sha256"]
        return
    for stage, item in entry.get("platforms", {}).get(platform, {}).get("stages", {}).items():
        kind = p.binary if p.binary in item else p.blob  # d3d12: DXIL where dxc built it
        yield name, stage, entry["input_key"], kind, item[kind]["path"], item[kind]["sha256"]


def write_packs(out: Path, manifest: dict, count=None, fetch=None) -> list[dict]:
    """Write one pack per platform of `manifest` (its ok permutations and depth units; the ubershader in vulkan's) into
    out/packs; returns the manifest's ``packs`` list. count(changed): the build's file counter. fetch(rel): an
    artifact's bytes where the tree does not hold it (build --pack-only: spool.py), or None: read from the tree."""
    from .platforms import PLATFORM_TABLE
    out = Path(out)
    listed = []
    for platform in manifest.get("platforms", []):
        rows = [r for e in manifest["permutations"] for r in _packed(e, e["hash"], platform)]
        rows += [r for e in (manifest.get("depth_shaders") or {}).values() for r in _packed(e, e["hash"], platform)]
        rows += list(_packed(manifest.get("ubershader") or {}, "ubershader", platform))
        entries, kinds = [], set()
        for name, stage, input_key, kind, rel, sha in rows:
            data = (out / rel).read_bytes() if fetch is None else fetch(rel)
            if hashlib.sha256(data).hexdigest() != sha:
                raise PackError(f"{out / rel}: its sha256 is not the manifest's — rebuild without --pack first")
            entries.append((name, stage, input_key, data))
            kinds.add(kind)
        blob_kind = "+".join(sorted(kinds)) or PLATFORM_TABLE[platform].blob  # d3d12 without dxc for some: "dxil+hlsl"
        own = next((e["platforms"][platform].get("tools", {}) for e in manifest["permutations"]
                    if platform in (e.get("platforms") or {})), {})  # as the build recorded them: no tool runs
        tools = {**own, **manifest["tools"]}
        meta = pack_meta(platform, PLATFORM_TABLE[platform].language, blob_kind, manifest["generator"], tools)
        blob, key = encode_pack(meta, entries)
        rel = f"{PACKS}/{platform}.{key[:16]}{SUFFIX}"
        changed = atomic_write(out / rel, blob)
        if count is not None:
            count(changed)
        listed.append({"platform": platform, "language": PLATFORM_TABLE[platform].language, "blob": blob_kind,
                       "path": rel, "sha256": hashlib.sha256(blob).hexdigest(), "key": key, "entries": len(entries),
                       "size": len(blob)})
    return listed


def collect_packs(out: Path, manifest: dict) -> int:
    """Remove the packs (and an interrupted build's temporaries) of out/packs the manifest does not name."""
    d = Path(out) / PACKS
    if not d.is_dir():
        return 0
    keep = {p["path"] for p in manifest.get("packs", [])}
    gone = 0
    for p in d.iterdir():
        if p.is_file() and (p.name.endswith(".tmp") or (p.name.endswith(SUFFIX) and f"{PACKS}/{p.name}" not in keep)):
            p.unlink(missing_ok=True)
            gone += 1
    if not keep:
        try:
            d.rmdir()
        except OSError:
            pass
    return gone
