"""Packs for the C reader's tests: crafted ones (any header, index and blobs, with their hashes and key made
right or left wrong), the two readers' verdicts, and the driver's batch protocol.

The C driver (tests/native/pack_check.c) reads records of (u64 little-endian length, bytes) on stdin and
prints one verdict line per record: "<status name>\\t<message>". Python's verdict is read_pack's: OK, or the
status its message maps to (CATEGORIES: every message read_pack writes maps to exactly one).
"""
from __future__ import annotations

import hashlib
import json
import re
import struct
import subprocess
from pathlib import Path

HEADER = struct.Struct("<8sII32sII")
ENTRY = struct.Struct("<16s8s32s32sQQ")
MAGIC = b"SMPACK\r\n"

_TAIL = r" \(rebuild it with `shadermatrix build --pack`\)$"
CATEGORIES = [  # (C status, read_pack's message after "not a valid shader pack — ")
    ("SMPACK_ERR_MAGIC", r"^bad magic "),
    ("SMPACK_ERR_TRUNCATED", r"^truncated: "),
    ("SMPACK_ERR_VERSION", r"^format version \d+, this reader reads version 1" + _TAIL),
    ("SMPACK_ERR_HEADER", r"^reserved header field is \d+, not 0" + _TAIL),
    ("SMPACK_ERR_META", r"^(the metadata is not |non-zero padding after the metadata)"),
    ("SMPACK_ERR_INDEX", r"^index entry has a (malformed|non-ASCII) (permutation|stage) field" + _TAIL),
    ("SMPACK_ERR_ORDER", r"^index entry \d+ \(.*\) is out of order or repeated" + _TAIL),
    ("SMPACK_ERR_BOUNDS", r"^index entry \d+ \(.*\) points at bytes \d+\.\.\d+, outside the blobs \(\d+\.\.\d+\): "
                          r"the file is truncated or its index damaged" + _TAIL),
    ("SMPACK_ERR_HASH", r"^sha256 mismatch in the blob of .* \(bytes \d+\.\.\d+\): it is damaged" + _TAIL),
    ("SMPACK_ERR_OVERLAP", r"^(index entry \d+ \(.*\) overlaps another blob at byte \d+|the blobs are not contiguous: "
                           r"a gap or an overlap at byte \d+|\d+ bytes of trailing garbage after the last blob "
                           r"\(byte \d+\))" + _TAIL),
    ("SMPACK_ERR_KEY", r"^the pack key does not match its metadata and index"),
]


def category(message: str) -> str:
    why = message.split(": not a valid shader pack — ", 1)[1]
    found = [name for name, pattern in CATEGORIES if re.search(pattern, why, re.S)]
    assert len(found) == 1, f"read_pack's message maps to {found}, not one status: {message}"
    return found[0]


def python_verdict(data: bytes, scratch: Path) -> tuple[str, str]:
    """(status, message) of generator.assemble.pack.read_pack on `data` (written to `scratch`)."""
    from generator.assemble.pack import PackError, read_pack
    scratch.write_bytes(data)
    try:
        read_pack(scratch)
    except PackError as e:
        return category(str(e)), str(e)
    return "SMPACK_OK", ""


def c_verdicts(driver: Path, packs: list[bytes], env: dict, timeout: float = 120) -> list[tuple[str, str]]:
    """(status, message) of smpack_open_memory on each pack, from one run of the driver; the run must end
    with status 0 and print nothing on stderr (a sanitizer's report ends it otherwise)."""
    stdin = b"".join(struct.pack("<Q", len(p)) + p for p in packs)
    r = subprocess.run([str(driver), "--batch"], input=stdin, capture_output=True, env=env, timeout=timeout)
    err = r.stderr.decode(errors="replace")
    assert r.returncode == 0 and not err, f"pack_check --batch exited {r.returncode}:\n{err[-6000:]}"
    lines = r.stdout.decode().splitlines()
    assert len(lines) == len(packs), f"{len(lines)} verdicts for {len(packs)} packs:\n{r.stdout[-2000:]!r}"
    return [tuple(line.split("\t", 1)) for line in lines]


# ------------------------------------------------------------------ reading and making packs

def layout(data: bytes) -> dict:
    """The header's fields and the offsets they imply (the pack must be at least a header long)."""
    _, version, count, key, meta_len, reserved = HEADER.unpack_from(data, 0)
    index_at = 56 + meta_len + (-(56 + meta_len) % 8)
    return {"version": version, "count": count, "key": key, "meta_len": meta_len, "reserved": reserved,
            "index_at": index_at, "blobs_at": index_at + 104 * count}


def key_of(meta_raw: bytes, index: bytes) -> bytes:
    """The pack key from the metadata's bytes as they are and the raw index (the format's definition)."""
    rows = []
    for at in range(0, len(index) - len(index) % 104, 104):
        perm, stage, ik, sha, _, _ = ENTRY.unpack_from(index, at)
        rows.append([perm.rstrip(b"\0").decode("latin-1"), stage.rstrip(b"\0").decode("latin-1"), ik.hex(), sha.hex()])
    doc = b'["smpack",1,' + meta_raw + b"," + json.dumps(rows, separators=(",", ":")).encode() + b"]"
    return hashlib.sha256(doc).digest()


def rekey(data: bytes) -> bytes:
    """`data` with its key made right for its metadata and index, where its header says where they are."""
    if len(data) < 56:
        return data
    lay = layout(data)
    if lay["blobs_at"] > len(data):
        return data
    key = key_of(data[56:56 + lay["meta_len"]], data[lay["index_at"]:lay["blobs_at"]])
    return data[:16] + key + data[48:]


def craft(entries, blobs: bytes = b"", *, meta: bytes | None = None, pad: bytes | None = None,
          version: int = 1, reserved: int = 0, count: int | None = None, key: bool = True) -> bytes:
    """A pack from parts. entries: (permutation, stage, offset from the first blob, length[, sha256]), the
    names str or raw bytes, the sha256 that of the bytes it points at unless given; the key made right
    unless key=False."""
    meta = meta if meta is not None else canonical({"format": "smpack", "generator": "test", "tools": {}})
    pad = pad if pad is not None else b"\0" * (-(56 + len(meta)) % 8)
    blobs_at = 56 + len(meta) + len(pad) + 104 * len(entries)
    index = b""
    for e in entries:
        perm, stage = (x.encode() if isinstance(x, str) else x for x in e[:2])
        offset, length = e[2], e[3]
        sha = e[4] if len(e) > 4 else hashlib.sha256(blobs[offset:offset + length] if offset >= 0 else b"").digest()
        index += ENTRY.pack(perm, stage, hashlib.sha256(perm + stage).digest(), sha, (blobs_at + offset) % 2**64,
                            length % 2**64)
    n = len(entries) if count is None else count
    head = HEADER.pack(MAGIC, version, n, b"\0" * 32, len(meta), reserved)
    data = head + meta + pad + index + blobs
    return rekey(data) if key else data


def canonical(obj) -> bytes:
    return json.dumps(obj, sort_keys=True, separators=(",", ":")).encode()
