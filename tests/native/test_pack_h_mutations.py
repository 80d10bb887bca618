"""Seeded random damage to real packs: bit flips (mostly in the header, metadata and index, where the checks
are), bytes overwritten anywhere, cuts, index fields set to edge values, entries swapped or repeated; half of
the structural ones with the key made right again, so that the checks before the key decide. The C reader
(under AddressSanitizer and UndefinedBehaviorSanitizer) and read_pack must give the same status to each."""
from __future__ import annotations

import random
import struct
from collections import Counter

import pytest

from .packs import layout, rekey
from .test_pack_h_checks import agree, small_pack

pytestmark = pytest.mark.toolchain

SEED = 20240
EDGES = [0, 1, 7, 8, 2**32 - 1, 2**32, 2**63, 2**64 - 1]


def _mutate(base: bytes, rng: random.Random) -> bytes:
    b = bytearray(base)
    lay = layout(base)
    head, count = lay["blobs_at"], lay["count"]
    kind = rng.random()
    if kind < 0.45:  # a few bits of the header, metadata or index
        for _ in range(rng.randint(1, 3)):
            b[rng.randrange(head)] ^= 1 << rng.randrange(8)
        return rekey(bytes(b)) if kind < 0.25 else bytes(b)
    if kind < 0.6:  # bytes anywhere
        for _ in range(rng.randint(1, 4)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        return bytes(b)
    if kind < 0.75:  # a cut, most near the index
        return bytes(b[:rng.randrange(head + 300 if rng.random() < 0.7 else len(b))])
    if kind < 0.9 and count:  # an index field or a header field set to an edge value
        field = rng.choice(["offset", "length", "count", "meta"])
        if field in ("offset", "length"):
            at = lay["index_at"] + 104 * rng.randrange(count) + (88 if field == "offset" else 96)
            value = rng.choice([*EDGES, head, len(b), len(b) - 1, rng.randrange(len(b) + 1),
                                struct.unpack_from("<Q", b, at)[0] + rng.choice([-8, -1, 1, 4])])
            struct.pack_into("<Q", b, at, value % 2**64)
        else:
            struct.pack_into("<I", b, 12 if field == "count" else 48,
                             rng.choice([*EDGES[:5], count + rng.choice([-1, 1]), rng.randrange(2**32)]) % 2**32)
        return rekey(bytes(b)) if rng.random() < 0.5 else bytes(b)
    if count >= 2:  # two entries swapped, or one repeated
        i = rng.randrange(count - 1)
        a, c = lay["index_at"] + 104 * i, lay["index_at"] + 104 * (i + 1)
        first, second = bytes(b[a:c]), bytes(b[c:c + 104])
        b[a:c + 104] = second + first if rng.random() < 0.5 else first + first
        return rekey(bytes(b))
    return bytes(b)


def test_random_damage_gets_the_same_status_from_both_readers(pack_check, sanitizer_env, tmp_path, example_packs):
    rng = random.Random(SEED)
    bases = [("format", small_pack(), 2000), ("vulkan", example_packs[0].read_bytes(), 600),
             ("gl", example_packs[2].read_bytes(), 400)]
    cases = {f"{name} #{k}": _mutate(data, rng) for name, data, n in bases for k in range(n)}
    got = Counter(agree(pack_check, sanitizer_env, tmp_path, cases).values())
    # the damage reaches every check, and some of it (a renamed entry, rekeyed) is a valid pack again
    assert set(got) >= {"SMPACK_OK", "SMPACK_ERR_MAGIC", "SMPACK_ERR_TRUNCATED", "SMPACK_ERR_VERSION", "SMPACK_ERR_HEADER",
                        "SMPACK_ERR_META", "SMPACK_ERR_INDEX", "SMPACK_ERR_ORDER", "SMPACK_ERR_BOUNDS",
                        "SMPACK_ERR_OVERLAP", "SMPACK_ERR_HASH", "SMPACK_ERR_KEY"}, got
