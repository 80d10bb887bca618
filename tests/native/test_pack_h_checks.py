"""include/shadermatrix/pack.h agrees with read_pack on every pack, under AddressSanitizer and
UndefinedBehaviorSanitizer: the example's real packs (same key, same entries), the corruptions of the pack
tests, truncation at every byte, and crafted packs for each check (both readers, and the status written
here, must agree)."""
from __future__ import annotations

import hashlib
import json
import random
import re
import struct
import subprocess

import pytest

from tests.assemble.test_pack import META, _corrupt, _entries
from tests.assemble.test_pack import test_a_corrupt_or_truncated_pack_is_refused_with_what_is_wrong as _refused

from .packs import ENTRY, HEADER, c_verdicts, canonical, craft, layout, python_verdict, rekey

pytestmark = pytest.mark.toolchain

HOWS = [how for how, _ in next(m for m in _refused.pytestmark if m.name == "parametrize").args[1]]
A = b"\x03\x02\x23\x07" + bytes(range(12))   # 16 bytes
B = b"\x03\x02\x23\x07\xaa\xbb\xcc\xdd"       # 8 bytes


def small_pack() -> bytes:
    from generator.assemble.pack import encode_pack
    return encode_pack(META, _entries())[0]


def agree(pack_check, env, tmp_path, cases: dict[str, bytes], expect: dict[str, str] | None = None) -> dict:
    """Both readers' verdicts on every case must agree (and equal `expect`'s where given), and every refusal
    of the C reader must name a byte or an entry; {name: status}."""
    names = list(cases)
    c = c_verdicts(pack_check, [cases[n] for n in names], env)
    wrong = []
    for name, (c_status, c_message) in zip(names, c):
        py_status, py_message = python_verdict(cases[name], tmp_path / "case.smpack")
        want = (expect or {}).get(name, py_status)
        where = c_status == "SMPACK_OK" or re.search(r"\d+ bytes?|\bbytes? \d+|\bentry \d+", c_message)
        if not c_status == py_status == want or (c_status == "SMPACK_OK") != (c_message == "") or not where:
            wrong.append(f"{name}: C {c_status} ({c_message}) · Python {py_status} ({py_message}) · expected {want}")
    assert not wrong, "\n".join(wrong)
    return {n: s for n, (s, _) in zip(names, c)}


def patch(data: bytes, i: int, *, offset=None, length=None, sha=None, key=True) -> bytes:
    """`data` with index entry i's fields replaced (absolute offset, length, raw sha256), rekeyed."""
    b = bytearray(data)
    at = layout(data)["index_at"] + 104 * i
    perm, stage, ik, old_sha, old_offset, old_length = ENTRY.unpack_from(b, at)
    ENTRY.pack_into(b, at, perm, stage, ik, old_sha if sha is None else sha,
                    old_offset if offset is None else offset % 2**64, old_length if length is None else length % 2**64)
    return rekey(bytes(b)) if key else bytes(b)


def header(data: bytes, **fields) -> bytes:
    lay = layout(data)
    values = {"version": lay["version"], "count": lay["count"], "key": lay["key"], "meta_len": lay["meta_len"],
              "reserved": lay["reserved"], **fields}
    return HEADER.pack(data[:8], values["version"], values["count"], values["key"], values["meta_len"],
                       values["reserved"]) + data[56:]


# ------------------------------------------------------------------ SHA-256 and the real packs

def test_its_sha256_is_hashlibs(pack_check, sanitizer_env):
    rng = random.Random(7)
    messages = [rng.randbytes(n) for n in [*range(0, 140), 191, 192, 1000, 4099, 65536 + 7]] + [b"abc", b"\0" * 64]
    stdin = b"".join(struct.pack("<Q", len(m)) + m for m in messages)
    r = subprocess.run([str(pack_check), "--sha256"], input=stdin, capture_output=True, env=sanitizer_env, timeout=60)
    assert r.returncode == 0 and not r.stderr, r.stderr.decode()[-3000:]
    assert r.stdout.decode().split() == [hashlib.sha256(m).hexdigest() for m in messages]


def _opened(pack_check, env, *args, stdin=None) -> list[str]:
    r = subprocess.run([str(pack_check), *args], input=stdin, capture_output=True, env=env, timeout=60)
    assert r.returncode == 0 and not r.stderr, f"exit {r.returncode}: {r.stderr.decode()[-3000:]}"
    return r.stdout.decode().splitlines()


def test_the_example_packs_open_with_read_packs_key_and_entries(pack_check, sanitizer_env, example_packs):
    from generator.assemble.pack import read_pack
    assert len(example_packs) == 4
    for path in example_packs:
        pack = read_pack(path)
        raw = path.read_bytes()
        want = ["SMPACK_OK\t", f"key {pack['key']} meta {layout(raw)['meta_len']}"]
        want += [f"{e.permutation} {e.stage} {e.input_key} {e.sha256} {e.offset} {e.length}"
                 for e in pack["entries"].values()]  # in index order
        assert _opened(pack_check, sanitizer_env, str(path)) == want, path.name  # smpack_open_file
        assert _opened(pack_check, sanitizer_env, "-", stdin=raw) == want, path.name  # smpack_open_memory
        assert len(want) - 2 == len(pack["entries"]) >= 9


def test_a_missing_file_and_a_directory_are_io_errors(pack_check, sanitizer_env, tmp_path):
    assert _opened(pack_check, sanitizer_env, str(tmp_path / "missing.smpack")) == \
        ["SMPACK_ERR_IO\tcannot open the shader pack: No such file or directory"]
    assert _opened(pack_check, sanitizer_env, str(tmp_path)) == ["SMPACK_ERR_IO\tcannot read the shader pack: Is a directory"]
    (tmp_path / "empty.smpack").write_bytes(b"")
    assert _opened(pack_check, sanitizer_env, str(tmp_path / "empty.smpack"))[0].startswith("SMPACK_ERR_MAGIC\t")


# ------------------------------------------------------------------ the pack tests' corruptions, truncations

def test_every_corruption_of_the_pack_tests_is_refused_alike(pack_check, sanitizer_env, tmp_path, example_packs):
    assert len(HOWS) >= 9
    bases = {"format": small_pack(), **{p.name: p.read_bytes() for p in example_packs}}
    cases = {f"{how} of {name}": _corrupt(data, how) for name, data in bases.items() for how in HOWS}
    got = agree(pack_check, sanitizer_env, tmp_path, cases)
    assert "SMPACK_OK" not in got.values()


def test_a_pack_cut_at_any_byte_or_boundary_is_refused_alike(pack_check, sanitizer_env, tmp_path, example_packs):
    """The format-only pack cut at every byte; the real vulkan pack at every field's boundary (header, metadata,
    each index entry's fields, each blob), a byte either side."""
    small, real = small_pack(), example_packs[0].read_bytes()
    lay = layout(real)
    bounds = [*range(9), 12, 16, 48, 52, 56, 56 + lay["meta_len"], lay["index_at"]]
    for i in range(lay["count"]):
        at = lay["index_at"] + 104 * i
        _, _, _, _, offset, length = ENTRY.unpack_from(real, at)
        bounds += [at + f for f in (0, 16, 24, 56, 88, 96)] + [offset, offset + length]
    cuts = {f"format pack cut at {n}": small[:n] for n in range(len(small))}
    cuts |= {f"vulkan pack cut at {n}": real[:n] for n in sorted({b + d for b in bounds for d in (-1, 0, 1)})
             if 0 <= n < len(real)}
    assert len(cuts) > len(small) + 200
    got = agree(pack_check, sanitizer_env, tmp_path, cuts)
    assert "SMPACK_OK" not in got.values()


# ------------------------------------------------------------------ crafted packs, check by check

META_OK = canonical({"format": "smpack", "generator": "test", "tools": {}})


def _meta(raw: bytes, entries=(("aaaa", "frag", 0, 16),)) -> bytes:
    return craft(entries, A, meta=raw)


def _nested(depth: int) -> bytes:  # the top object is 1 deep
    return b'{"d":' + b"[" * (depth - 1) + b"]" * (depth - 1) + b',"format":"smpack"}'


CRAFTED = {
    # (pack, the status both readers must give)
    "two blobs": (lambda: craft([("aaaa", "frag", 0, 16), ("aaaa", "vert", 16, 8)], A + B), "SMPACK_OK"),
    "a shared blob": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 0, 16), ("bbbb", "vert", 16, 8)], A + B),
                      "SMPACK_OK"),
    "blobs not in order of first use": (lambda: craft([("aaaa", "frag", 8, 16), ("aaaa", "vert", 0, 8)], B + A),
                                        "SMPACK_OK"),
    "one content twice": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 16, 16)], A + A), "SMPACK_OK"),
    "no entries": (lambda: craft([]), "SMPACK_OK"),
    "no entries, trailing bytes": (lambda: craft([], b"\0"), "SMPACK_ERR_OVERLAP"),
    "an empty blob alone": (lambda: craft([("aaaa", "frag", 0, 0)]), "SMPACK_OK"),
    "an empty blob at the end": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 16, 0)], A), "SMPACK_OK"),
    "two empty blobs at one offset": (lambda: craft([("aaaa", "frag", 0, 0), ("bbbb", "frag", 0, 0)]), "SMPACK_OK"),
    "an empty blob, then a blob at its offset": (lambda: craft([("aaaa", "frag", 0, 0), ("bbbb", "frag", 0, 16)], A),
                                                 "SMPACK_ERR_OVERLAP"),
    "an empty blob inside a blob": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 4, 0)], A),
                                    "SMPACK_ERR_OVERLAP"),
    "names filling their fields": (lambda: craft([("0123456789abcdef", "fragment", 0, 16)], A), "SMPACK_OK"),
    "names of any ASCII (escaped in the key)": (lambda: craft([(n, "st\x7f\"", 0, 16) for n in
                                                               sorted(['A"\\', "\x01\t\n\x1f", "Z z/", "~\x7f"])], A),
                                                "SMPACK_OK"),
    "overlapping blobs": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 8, 16)], A + B), "SMPACK_ERR_OVERLAP"),
    "one offset, two lengths": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 0, 8)], A), "SMPACK_ERR_OVERLAP"),
    "one offset, two lengths, the second's hash wrong": (lambda: craft([("aaaa", "frag", 0, 16),
                                                                        ("bbbb", "frag", 0, 8, b"\1" * 32)], A),
                                                         "SMPACK_ERR_HASH"),
    "a gap": (lambda: craft([("aaaa", "frag", 0, 8), ("bbbb", "frag", 16, 8)], B + B + B), "SMPACK_ERR_OVERLAP"),
    "a gap, out of order": (lambda: craft([("aaaa", "frag", 16, 8), ("bbbb", "frag", 0, 8)], B + B + B),
                            "SMPACK_ERR_OVERLAP"),
    "a gap before the first blob": (lambda: craft([("aaaa", "frag", 8, 8)], B + B), "SMPACK_ERR_OVERLAP"),
    "trailing bytes": (lambda: craft([("aaaa", "frag", 0, 8)], B + b"\0\0\0\0"), "SMPACK_ERR_OVERLAP"),
    "a blob inside the index": (lambda: craft([("aaaa", "frag", -8, 8, b"\0" * 32)], B), "SMPACK_ERR_BOUNDS"),
    "offset + length wraps past 2^64": (lambda: craft([("aaaa", "frag", 16, 2**64 - 8, b"\0" * 32)], A + B),
                                        "SMPACK_ERR_BOUNDS"),
    "offset 2^64 - 1": (lambda: patch(craft([("aaaa", "frag", 0, 16)], A), 0, offset=2**64 - 1, length=2),
                        "SMPACK_ERR_BOUNDS"),
    "offset at the end, one byte": (lambda: craft([("aaaa", "frag", 16, 1, b"\0" * 32)], A), "SMPACK_ERR_BOUNDS"),
    "length 2^64 - 1": (lambda: craft([("aaaa", "frag", 0, 2**64 - 1, b"\0" * 32)], A), "SMPACK_ERR_BOUNDS"),
    "a wrong hash": (lambda: craft([("aaaa", "frag", 0, 16, b"\0" * 32)], A), "SMPACK_ERR_HASH"),
    "a shared blob, the second hash wrong": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 0, 16, b"\0" * 32)],
                                                           A), "SMPACK_ERR_HASH"),
    "unsorted": (lambda: craft([("bbbb", "frag", 0, 16), ("aaaa", "frag", 16, 8)], A + B), "SMPACK_ERR_ORDER"),
    "stages unsorted": (lambda: craft([("aaaa", "vert", 0, 16), ("aaaa", "frag", 16, 8)], A + B), "SMPACK_ERR_ORDER"),
    "a repeated entry": (lambda: craft([("aaaa", "frag", 0, 16), ("aaaa", "frag", 0, 16)], A), "SMPACK_ERR_ORDER"),
    "a prefix sorts first": (lambda: craft([("ab", "frag", 0, 16), ("abc", "frag", 0, 16)], A), "SMPACK_OK"),
    "a prefix sorts first, reversed": (lambda: craft([("abc", "frag", 0, 16), ("ab", "frag", 0, 16)], A),
                                       "SMPACK_ERR_ORDER"),
    "an empty permutation": (lambda: craft([(b"", "frag", 0, 16)], A), "SMPACK_ERR_INDEX"),
    "a NUL inside a permutation": (lambda: craft([(b"ab\0c", "frag", 0, 16)], A), "SMPACK_ERR_INDEX"),
    "a non-ASCII permutation": (lambda: craft([(b"caf\xc3\xa9", "frag", 0, 16)], A), "SMPACK_ERR_INDEX"),
    "an empty stage": (lambda: craft([("aaaa", b"", 0, 16)], A), "SMPACK_ERR_INDEX"),
    "a non-ASCII stage": (lambda: craft([("aaaa", b"\xff", 0, 16)], A), "SMPACK_ERR_INDEX"),
    "version 0": (lambda: craft([], version=0), "SMPACK_ERR_VERSION"),
    "version 2^32 - 1": (lambda: craft([], version=2**32 - 1), "SMPACK_ERR_VERSION"),
    "reserved 1": (lambda: craft([], reserved=1), "SMPACK_ERR_HEADER"),
    "count 2^32 - 1": (lambda: craft([("aaaa", "frag", 0, 16)], A, count=2**32 - 1), "SMPACK_ERR_TRUNCATED"),
    "count x 104 past 2^32": (lambda: craft([("aaaa", "frag", 0, 16)], A, count=2**32 // 104 + 1),
                              "SMPACK_ERR_TRUNCATED"),
    "count one more": (lambda: craft([("aaaa", "frag", 0, 16)], A, count=2), "SMPACK_ERR_TRUNCATED"),
    "count one fewer": (lambda: craft([("aaaa", "frag", 0, 16), ("bbbb", "frag", 0, 16)], A, count=1),
                        "SMPACK_ERR_OVERLAP"),
    "meta length 2^32 - 1": (lambda: header(craft([]), meta_len=2**32 - 1), "SMPACK_ERR_TRUNCATED"),
    "meta length 2^32 - 7": (lambda: header(craft([]), meta_len=2**32 - 7), "SMPACK_ERR_TRUNCATED"),
    "meta length 0": (lambda: craft([], meta=b""), "SMPACK_ERR_META"),
    "the key flipped": (lambda: (lambda d: d[:20] + bytes([d[20] ^ 1]) + d[21:])(craft([("aaaa", "frag", 0, 16)], A)),
                        "SMPACK_ERR_KEY"),
    "no key": (lambda: craft([("aaaa", "frag", 0, 16)], A, key=False), "SMPACK_ERR_KEY"),
    "empty": (lambda: b"", "SMPACK_ERR_MAGIC"),
    "the magic's first 7 bytes": (lambda: b"SMPACK\r", "SMPACK_ERR_MAGIC"),
    "a magic one byte off": (lambda: b"SMPACK\r\r" + craft([])[8:], "SMPACK_ERR_MAGIC"),
    "non-zero padding": (lambda: craft([], meta=b'{"format":"smpack"}', pad=b"\0\0\0\0\1"), "SMPACK_ERR_META"),
    # the metadata: canonical JSON, exactly as json.dumps(sort_keys=True, separators=(",", ":")) writes it
    "meta with escapes": (lambda: _meta(canonical({"format": "smpack", "x": "\u00e9\n\"\\\u0001\u007f/\U0001f600"})),
                          "SMPACK_OK"),
    "meta keys by code point": (lambda: _meta(canonical({"format": "smpack", "z": 1, "\u00e9": 2, "\ue000": 3,
                                                         "\U0001f600": 4, "\uffff": 5, "\ud800": 6, "": 7})),
                                "SMPACK_OK"),
    "meta keys in UTF-16 order": (lambda: _meta(b'{"\\ud83d\\ude00":4,"\\ue000":3,"format":"smpack"}'),
                                  "SMPACK_ERR_META"),
    "meta values of each kind": (lambda: _meta(canonical({"format": "smpack", "n": [0, -1, 2**63 - 1, -2**63, True, False,
                                                                                     None, [], {}, [[{}]]], "s": ""})),
                                 "SMPACK_OK"),
    "meta nested 32 deep": (lambda: _meta(_nested(32)), "SMPACK_OK"),
    "meta nested 33 deep": (lambda: _meta(_nested(33)), "SMPACK_ERR_META"),
    "meta nested 3000 deep": (lambda: _meta(_nested(3000)), "SMPACK_ERR_META"),
    "meta with spaces": (lambda: _meta(json.dumps({"format": "smpack", "x": 1}, sort_keys=True).encode()),
                         "SMPACK_ERR_META"),
    "meta keys unsorted": (lambda: _meta(b'{"generator":"test","format":"smpack"}'), "SMPACK_ERR_META"),
    "meta key repeated": (lambda: _meta(b'{"format":"smpack","format":"smpack"}'), "SMPACK_ERR_META"),
    "meta upper-case escape": (lambda: _meta(b'{"format":"smpack","x":"\\u00E9"}'), "SMPACK_ERR_META"),
    "meta needless escape": (lambda: _meta(b'{"format":"smpack","x":"\\u0041"}'), "SMPACK_ERR_META"),
    "meta escaped slash": (lambda: _meta(b'{"format":"smpack","x":"\\/"}'), "SMPACK_ERR_META"),
    "meta \\u000a for \\n": (lambda: _meta(b'{"format":"smpack","x":"\\u000a"}'), "SMPACK_ERR_META"),
    "meta raw UTF-8": (lambda: _meta('{"format":"smpack","x":"é"}'.encode()), "SMPACK_ERR_META"),
    "meta not UTF-8": (lambda: _meta(b'{"format":"smpack","x":"\xff"}'), "SMPACK_ERR_META"),
    "meta raw DEL": (lambda: _meta(b'{"format":"smpack","x":"\x7f"}'), "SMPACK_ERR_META"),
    "meta raw control character": (lambda: _meta(b'{"format":"smpack","x":"\x01"}'), "SMPACK_ERR_META"),
    "meta not an object": (lambda: _meta(b'["format","smpack"]'), "SMPACK_ERR_META"),
    "meta a string": (lambda: _meta(b'"smpack"'), "SMPACK_ERR_META"),
    "meta without format": (lambda: _meta(b'{"generator":"test"}'), "SMPACK_ERR_META"),
    "meta of another format": (lambda: _meta(b'{"format":"smpacks"}'), "SMPACK_ERR_META"),
    "meta format a number": (lambda: _meta(b'{"format":1}'), "SMPACK_ERR_META"),
    "meta format one level down": (lambda: _meta(b'{"x":{"format":"smpack"}}'), "SMPACK_ERR_META"),
    "meta then a space": (lambda: _meta(META_OK + b" "), "SMPACK_ERR_META"),
    "meta then another object": (lambda: _meta(META_OK + b"{}"), "SMPACK_ERR_META"),
    "meta cut short": (lambda: _meta(META_OK[:-1]), "SMPACK_ERR_META"),
    "meta ending in an open object": (lambda: _meta(b'{"format":"smpack","x":{'), "SMPACK_ERR_META"),
    "meta ending in an open array": (lambda: _meta(b'{"format":"smpack","x":['), "SMPACK_ERR_META"),
    "meta ending after a key": (lambda: _meta(b'{"format":"smpack","x":'), "SMPACK_ERR_META"),
    "meta a lone brace": (lambda: _meta(b"{"), "SMPACK_ERR_META"),
    "meta trailing comma": (lambda: _meta(b'{"format":"smpack",}'), "SMPACK_ERR_META"),
    "meta unquoted key": (lambda: _meta(b'{format:"smpack"}'), "SMPACK_ERR_META"),
    **{f"meta number {n}": ((lambda n=n: _meta(b'{"format":"smpack","n":' + n + b"}")), "SMPACK_ERR_META")
       for n in [b"1.5", b"1.0", b"1e5", b"1E5", b"-0", b"01", b"-", b"NaN", b"Infinity", b"-Infinity",
                 b"9223372036854775808", b"-9223372036854775809", b"12345678901234567890123", b"1" * 5000]},
}


def test_crafted_packs_get_the_same_status_from_both_readers(pack_check, sanitizer_env, tmp_path):
    cases = {name: make() for name, (make, _) in CRAFTED.items()}
    agree(pack_check, sanitizer_env, tmp_path, cases, {name: want for name, (_, want) in CRAFTED.items()})
