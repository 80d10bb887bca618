"""KTX2 files of baked tables and mipmapped textures: round trip, identical bytes, an independent reader, and
corrupt or compressed files refused.

The independent reader below is written from the KTX 2.0 specification ("File Structure", "Index",
"Level Index", "Key/Value Data", "mipPadding") and the Khronos Data Format 1.3 basic descriptor
block (§5) with ``struct`` alone: it does not call generator.io.ktx2, so a misreading of the
spec shared by our writer and our reader cannot pass unnoticed.
"""
from __future__ import annotations

import hashlib
import struct

import numpy as np
import pytest

from generator.io.ktx2 import FORMATS, Ktx2Error, decode, decode_levels, encode, encode_levels
from generator.lang.errors import UserError

KINDS = {"1d": ((1, 7, 4), False), "2d": ((3, 5, 4), False), "cube": ((6, 4, 4, 4), True)}

# what the independent reader expects of each format (KTX2 "vkFormat", "typeSize"; KDF §5)
# (transfer 1 linear, 2 sRGB; an sRGB format's alpha sample is qualified LINEAR, 0x10, KTX2 "dataFormatDescriptor")
SPEC = {
    "unorm8": dict(vk=37, dtype="<u1", bits=8, qualifiers=0, lower=0, upper=255, transfer=1, alpha=0),
    "fp16": dict(vk=97, dtype="<f2", bits=16, qualifiers=0xC0, lower=0xBF800000, upper=0x3F800000, transfer=1,
                 alpha=0xC0),
    "fp32": dict(vk=109, dtype="<f4", bits=32, qualifiers=0xC0, lower=0xBF800000, upper=0x3F800000, transfer=1,
                 alpha=0xC0),
    "srgb8": dict(vk=43, dtype="<u1", bits=8, qualifiers=0, lower=0, upper=255, transfer=2, alpha=0x10),
}


def _texels(fmt: str, shape: tuple[int, ...]) -> np.ndarray:
    rng = np.random.default_rng(sum(shape) + len(fmt))
    if FORMATS[fmt][1] == np.uint8:
        return rng.integers(0, 256, size=shape, dtype=np.uint8)
    values = rng.standard_normal(shape) * 100.0  # negative, large and small values: the full range is kept
    return values.astype(FORMATS[fmt][1])


def _read_independently(data: bytes) -> dict:
    """Every field of a KTX2 file by the specification's layout, with struct only."""
    out = {"identifier": data[:12]}
    names = ["vkFormat", "typeSize", "pixelWidth", "pixelHeight", "pixelDepth", "layerCount", "faceCount",
             "levelCount", "supercompressionScheme"]
    out.update(zip(names, struct.unpack_from("<9I", data, 12)))
    names = ["dfdByteOffset", "dfdByteLength", "kvdByteOffset", "kvdByteLength"]
    out.update(zip(names, struct.unpack_from("<4I", data, 48)))
    out["sgdByteOffset"], out["sgdByteLength"] = struct.unpack_from("<2Q", data, 64)
    out["levels"] = [struct.unpack_from("<3Q", data, 80 + 24 * i) for i in range(max(1, out["levelCount"]))]
    p = out["dfdByteOffset"]
    total, w0, w1, w2, w3, bp0, bp1 = struct.unpack_from("<7I", data, p)
    out["dfd"] = dict(total=total, vendor=w0 & 0x1FFFF, type=w0 >> 17, version=w1 & 0xFFFF, block_size=w1 >> 16,
                      model=w2 & 0xFF, primaries=(w2 >> 8) & 0xFF, transfer=(w2 >> 16) & 0xFF, flags=w2 >> 24,
                      block_dims=w3, bytes_planes=(bp0, bp1), samples=[])
    for s in range((out["dfd"]["block_size"] - 24) // 16):
        a, pos, lower, upper = struct.unpack_from("<4I", data, p + 28 + 16 * s)
        out["dfd"]["samples"].append(dict(bit_offset=a & 0xFFFF, bit_length=((a >> 16) & 0xFF) + 1,
                                          channel=(a >> 24) & 0xF, qualifiers=(a >> 24) & 0xF0,
                                          position=pos, lower=lower, upper=upper))
    kv, q = {}, out["kvdByteOffset"]
    while q < out["kvdByteOffset"] + out["kvdByteLength"]:
        (n,) = struct.unpack_from("<I", data, q)
        key, _, value = data[q + 4: q + 4 + n].partition(b"\0")
        kv[key.decode()] = value
        out.setdefault("kv_order", []).append(key.decode())
        q += 4 + (n + 3) // 4 * 4
    out["kv"], out["kv_end"] = kv, q
    return out


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip(fmt, kind):
    shape, cube = KINDS[kind]
    texels = _texels(fmt, shape)
    back, got_fmt, got_cube = decode(encode(texels, fmt, cube=cube), "t.ktx2")
    assert (got_fmt, got_cube) == (fmt, cube)
    assert back.dtype == FORMATS[fmt][1] and back.shape == shape
    assert back.tobytes() == texels.tobytes()  # bit for bit, fp16 included


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("fmt", FORMATS)
def test_independent_reader(fmt, kind):
    shape, cube = KINDS[kind]
    texels = _texels(fmt, shape)
    data = encode(texels, fmt, cube=cube)
    f, spec = _read_independently(data), SPEC[fmt]
    assert f["identifier"] == bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
    assert f["vkFormat"] == spec["vk"] and f["typeSize"] == spec["bits"] // 8
    assert (f["pixelWidth"], f["pixelHeight"]) == (shape[-2], shape[-3])  # a 1D table: a 2D texture, height 1
    assert (f["pixelDepth"], f["layerCount"], f["faceCount"]) == (0, 0, 6 if cube else 1)
    assert (f["levelCount"], f["supercompressionScheme"], f["sgdByteOffset"], f["sgdByteLength"]) == (1, 0, 0, 0)

    d = f["dfd"]
    assert f["dfdByteOffset"] == 104 and f["dfdByteLength"] == d["total"] == 4 + d["block_size"]
    assert (d["vendor"], d["type"], d["version"], d["block_size"]) == (0, 0, 2, 24 + 16 * 4)
    # RGBSDA, BT709, linear (sRGB), straight alpha
    assert (d["model"], d["primaries"], d["transfer"], d["flags"]) == (1, 1, spec["transfer"], 0)
    assert d["block_dims"] == 0 and d["bytes_planes"] == (4 * spec["bits"] // 8, 0)
    for i, (s, channel) in enumerate(zip(d["samples"], (0, 1, 2, 15))):
        assert s == dict(bit_offset=i * spec["bits"], bit_length=spec["bits"], channel=channel,
                         qualifiers=spec["alpha"] if channel == 15 else spec["qualifiers"], position=0,
                         lower=spec["lower"], upper=spec["upper"])
    assert f["kvdByteOffset"] == f["dfdByteOffset"] + f["dfdByteLength"]
    assert f["kv"] == {"KTXorientation": b"rd\0", "KTXwriter": b"shadermatrix\0"}
    assert f["kv_order"] == sorted(f["kv_order"]) and f["kv_end"] == f["kvdByteOffset"] + f["kvdByteLength"]

    (offset, length, raw), = f["levels"]
    texel = 4 * spec["bits"] // 8
    assert offset % (texel * 4 // np.gcd(texel, 4)) == 0 and offset >= f["kv_end"]  # lcm(texel block size, 4)
    assert data[f["kv_end"]:offset] == b"\0" * (offset - f["kv_end"])  # mipPadding is zeros
    assert length == raw == texels.size * spec["bits"] // 8 and offset + length == len(data)
    # faces +X..-Z, rows top to bottom, RGBA texels: the array's C order, little-endian
    assert data[offset:] == np.ascontiguousarray(texels, dtype=spec["dtype"]).tobytes()


def test_identical_bytes():
    texels = _texels("fp16", (6, 4, 4, 4))
    first = encode(texels, "fp16", cube=True)
    assert encode(texels.copy(), "fp16", cube=True) == first
    # byte order and memory layout of the input do not show in the file
    swapped = texels.astype(">f2")[:, ::-1][:, ::-1]
    assert encode(swapped, "fp16", cube=True) == first
    # pinned: the format of the files an engine loads changes only on purpose
    tiny = np.arange(2 * 2 * 4, dtype=np.uint8).reshape(2, 2, 4)
    assert hashlib.sha256(encode(tiny, "unorm8")).hexdigest()[:16] == PINNED_UNORM8_2X2


PINNED_UNORM8_2X2 = "2df703b70b8e60d8"


def test_writer_string():
    data = encode(np.zeros((1, 1, 4), np.float32), "fp32", writer="shadermatrix 0.1.0 / test")
    assert _read_independently(data)["kv"]["KTXwriter"] == b"shadermatrix 0.1.0 / test\0"
    assert decode(data)[1] == "fp32"  # the level still lands on a 16-byte boundary


@pytest.mark.parametrize("texels, fmt, cube, message", [
    (np.zeros((2, 2, 4), np.float32), "fp16", False, "fp16 texels are float16, not float32"),
    (np.zeros((2, 2, 4), np.float64), "fp32", False, "not float64"),
    (np.zeros((2, 2, 3), np.uint8), "unorm8", False, "(H, W, 4)"),
    (np.zeros((2, 4), np.uint8), "unorm8", False, "(H, W, 4)"),
    (np.zeros((0, 2, 4), np.uint8), "unorm8", False, "at least one texel"),
    (np.zeros((6, 2, 2, 4), np.uint8), "unorm8", False, "(H, W, 4)"),
    (np.zeros((2, 2, 4), np.uint8), "unorm8", True, "(6, S, S, 4)"),
    (np.zeros((6, 2, 3, 4), np.uint8), "unorm8", True, "faces are square"),
    (np.zeros((2, 2, 4), np.uint8), "rgba8", False, "unknown KTX2 format 'rgba8'"),
    (np.full((2, 2, 4), np.nan, np.float32), "fp32", False, "NaN or infinity"),
    ([[[0, 0, 0, 0]]], "unorm8", False, "numpy array"),
])
def test_encode_refuses(texels, fmt, cube, message):
    with pytest.raises(ValueError) as e:
        encode(texels, fmt, cube=cube)
    assert message in str(e.value)


def _patched(data: bytes, offset: int, fmt: str, *values) -> bytes:
    out = bytearray(data)
    struct.pack_into(fmt, out, offset, *values)
    return bytes(out)


GOOD = encode(_texels("fp32", (3, 5, 4)), "fp32")
LEVEL_OFFSET = struct.unpack_from("<Q", GOOD, 80)[0]


@pytest.mark.parametrize("data, message", [
    (GOOD[:0], "less than the 80-byte header"),
    (GOOD[:11], "less than the 80-byte header"),
    (GOOD[:79], "less than the 80-byte header"),
    (GOOD[:100], "inside the level index"),
    (GOOD[:150], "Data Format Descriptor (byte 104, 92 bytes) is past the end"),
    (GOOD[:-1], "run past the end"),
    (GOOD + b"\0" * 16, "16 bytes follow the level's texels"),
    (b"\x89PNG\r\n\x1a\n" + GOOD[8:], "not a KTX 2.0 file"),
    (b"\xabKTX 11\xbb\r\n\x1a\n" + GOOD[12:], "a KTX 1 file"),
    (_patched(GOOD, 20, "<I", 0), "pixelWidth 0"),
    (_patched(GOOD, 12, "<I", 44), "vkFormat 44 is not a format this reader takes"),
    (_patched(GOOD, 16, "<I", 1), "typeSize is 1"),
    (_patched(GOOD, 44, "<I", 2), "supercompressionScheme is 2"),
    (_patched(GOOD, 40, "<I", 3), "levelCount is 3"),
    (_patched(GOOD, 36, "<I", 6), "faces are square"),
    (_patched(GOOD, 52, "<I", 88), "dfdByteLength is 88, not 92"),
    (_patched(GOOD, 104, "<I", 96), "dfdTotalSize is 96"),
    (_patched(GOOD, 48, "<I", 1 << 20), "is past the end of the"),
    (_patched(GOOD, 48, "<I", 100), "starts at byte 100, not right after the level index (byte 104)"),
    (_patched(GOOD, 104 + 12, "<I", 0x00020101), "transfer function is 2, not linear"),
    (_patched(GOOD, 104 + 28, "<I", 0x1F000000), "sample R bitOffset/bitLength/channelType/qualifiers"),
    (_patched(GOOD, 104 + 20, "<I", 8), "bytesPlane0..3"),
    (_patched(GOOD, 80, "<Q", 1 << 40), "run past the end"),
    (_patched(GOOD, 80, "<Q", LEVEL_OFFSET - 8), "not at a multiple of 16"),
    (_patched(GOOD, 88, "<Q", 4), "the level is 4 bytes"),
    (_patched(GOOD, 60, "<I", 1000), "key/value data (byte 196, 1000 bytes) runs past the end"),
    (_patched(GOOD, 56, "<I", 200), "key/value data starts at byte 200"),
    (_patched(GOOD, 80, "<Q", 192), "overlap the descriptors"),
    (_patched(GOOD, 196, "<I", 1), "keyAndValueByteLength 1"),
])
def test_decode_refuses(data, message):
    with pytest.raises(Ktx2Error) as e:
        decode(data, "out/tables/brdf_lut.ktx2")
    text = str(e.value)
    assert isinstance(e.value, UserError)
    assert text.startswith("out/tables/brdf_lut.ktx2: ") and message in text and " — " in text, text


def test_decode_reads_a_1d_texture():
    """A KTX2 1D texture (pixelHeight 0) from another tool reads as one row."""
    texels = _texels("fp16", (1, 7, 4))
    back, fmt, cube = decode(_patched(encode(texels, "fp16"), 24, "<I", 0))
    assert back.shape == (1, 7, 4) and back.tobytes() == texels.tobytes() and (fmt, cube) == ("fp16", False)


def test_every_truncation_and_byte_flip_is_a_ktx2_error():
    """No cut or single corrupted byte of the preamble escapes as anything but Ktx2Error (or a good decode)."""
    data = encode(_texels("unorm8", (6, 2, 2, 4)), "unorm8", cube=True)
    for n in range(len(data)):
        with pytest.raises(Ktx2Error):
            decode(data[:n])
    level = struct.unpack_from("<Q", data, 80)[0]
    for i in range(level):
        for flip in (0x01, 0x80, 0xFF):
            corrupt = bytearray(data)
            corrupt[i] ^= flip
            try:
                decode(bytes(corrupt))
            except Ktx2Error:
                pass


# ------------------------------------------------------------------ mip chains

def _chain(fmt: str, width: int, height: int, cube: bool = False) -> list[np.ndarray]:
    """Random texels for every level of a full chain, level i of max(1, W >> i) × max(1, H >> i)."""
    out, i = [], 0
    while True:
        w, h = max(1, width >> i), max(1, height >> i)
        out.append(_texels(fmt, (6, h, w, 4) if cube else (h, w, 4)))
        if (w, h) == (1, 1):
            return out
        i += 1


CHAINS = {"5x3": (5, 3, False), "16x4": (16, 4, False), "1x9": (1, 9, False), "cube8": (8, 8, True)}


@pytest.mark.parametrize("chain", CHAINS)
@pytest.mark.parametrize("fmt", FORMATS)
def test_levels_independent_reader(fmt, chain):
    """Level index largest first, level data smallest first, each level aligned and zero-padded, level 0 last."""
    width, height, cube = CHAINS[chain]
    levels = _chain(fmt, width, height, cube)
    data = encode_levels(levels, fmt, cube=cube)
    f, spec = _read_independently(data), SPEC[fmt]
    assert f["levelCount"] == len(levels) == max(width, height).bit_length()
    assert (f["pixelWidth"], f["pixelHeight"], f["faceCount"]) == (width, height, 6 if cube else 1)
    assert f["dfdByteOffset"] == 80 + 24 * len(levels)
    texel = 4 * spec["bits"] // 8
    align = texel * 4 // np.gcd(texel, 4)
    end = f["kv_end"]
    for i in reversed(range(len(levels))):  # the file holds the smallest level first
        offset, length, raw = f["levels"][i]
        assert offset % align == 0 and end <= offset < end + align, (i, offset, end)
        assert data[end:offset] == b"\0" * (offset - end)
        assert length == raw == levels[i].size * spec["bits"] // 8
        assert data[offset:offset + length] == np.ascontiguousarray(levels[i], dtype=spec["dtype"]).tobytes()
        end = offset + length
    assert end == len(data)  # level 0 ends the file
    offsets = [lv[0] for lv in f["levels"]]
    assert offsets == sorted(offsets, reverse=True)  # index order: level 0 first, at the highest offset


@pytest.mark.parametrize("chain", CHAINS)
@pytest.mark.parametrize("fmt", FORMATS)
def test_levels_round_trip(fmt, chain):
    width, height, cube = CHAINS[chain]
    levels = _chain(fmt, width, height, cube)
    back, got_fmt, got_cube = decode_levels(encode_levels(levels, fmt, cube=cube), "t.ktx2")
    assert (got_fmt, got_cube, len(back)) == (fmt, cube, len(levels))
    for a, b in zip(back, levels):
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def test_a_prefix_of_the_chain_and_one_level_agree_with_encode():
    levels = _chain("unorm8", 8, 8)
    assert encode_levels(levels[:1], "unorm8") == encode(levels[0], "unorm8")
    back, _, _ = decode_levels(encode_levels(levels[:2], "unorm8"))
    assert [b.shape for b in back] == [(8, 8, 4), (4, 4, 4)]


@pytest.mark.parametrize("levels, message", [
    ([], "at least one level"),
    ([np.zeros((4, 4, 4), np.uint8), np.zeros((3, 2, 4), np.uint8)], "level 1 is (3, 2, 4), not (2, 2, 4)"),
    ([np.zeros((1, 2, 4), np.uint8), np.zeros((1, 1, 4), np.uint8), np.zeros((1, 1, 4), np.uint8)],
     "3 levels, more than the 2"),
    ([np.zeros((2, 2, 4), np.uint8), np.zeros((1, 1, 4), np.float32)], "level 1: unorm8 texels are uint8"),
])
def test_encode_levels_refuses(levels, message):
    with pytest.raises(ValueError) as e:
        encode_levels(levels, "unorm8")
    assert message in str(e.value)


def _id(value) -> str:
    return value if isinstance(value, str) else "file"


CHAIN = encode_levels(_chain("srgb8", 5, 3), "srgb8")  # levels 5 × 3, 2 × 1, 1 × 1
CHAIN_INDEX = [struct.unpack_from("<3Q", CHAIN, 80 + 24 * i) for i in range(3)]


@pytest.mark.parametrize("data, message", [
    (CHAIN, "levelCount is 3; a baked table has one level"),  # decode: the tables' reader
], ids=_id)
def test_decode_takes_one_level(data, message):
    with pytest.raises(Ktx2Error) as e:
        decode(data, "t.ktx2")
    assert message in str(e.value)


@pytest.mark.parametrize("data, message", [
    (_patched(CHAIN, 40, "<I", 4), "levelCount is 4, more than the 3 levels of a 5 × 3 texture"),
    (_patched(CHAIN, 80, "<Q", CHAIN_INDEX[1][0]), "level 0's texels (byte"),  # level 0 on top of level 1
    (_patched(CHAIN, 104, "<Q", CHAIN_INDEX[0][0]), "level 0's texels (byte 308) overlap level 1"),  # 1 after 0
    (_patched(CHAIN, 128, "<Q", 200), "level 2's texels (byte 200) overlap the descriptors"),
    (_patched(CHAIN, 112, "<Q", 4), "level 1 is 4 bytes (8 uncompressed), not the 8 of 1 face(s) × 1 × 2"),
    (CHAIN + b"\0" * 4, "4 bytes follow level 0's texels"),
], ids=_id)
def test_decode_levels_refuses(data, message):
    with pytest.raises(Ktx2Error) as e:
        decode_levels(data, "t.ktx2")
    assert message in str(e.value), str(e.value)


def test_level_count_zero_is_one_level():
    """levelCount 0 (KTX2: the loader generates the mips) stores one level, read as such."""
    texels = _texels("unorm8", (4, 4, 4))
    back, _, _ = decode_levels(_patched(encode(texels, "unorm8"), 40, "<I", 0))
    assert len(back) == 1 and back[0].tobytes() == texels.tobytes()


def test_srgb_alpha_without_the_linear_bit_is_read():
    """Other tools' sRGB files may leave the alpha sample's LINEAR qualifier unset; the texels are the same."""
    texels = _texels("srgb8", (2, 3, 4))
    data = encode(texels, "srgb8")
    alpha_word = 104 + 28 + 3 * 16
    word = struct.unpack_from("<I", data, alpha_word)[0]
    assert word >> 24 == 0x1F  # channel 15, LINEAR
    assert decode(_patched(data, alpha_word, "<I", word & 0x00FFFFFF | 0x0F << 24))[0].tobytes() == texels.tobytes()
    unorm = encode(texels, "unorm8")
    with pytest.raises(Ktx2Error, match="transfer function is 1, not sRGB"):
        decode(_patched(unorm, 12, "<I", 43))  # vkFormat says sRGB, the descriptor linear


def _basis(model: int) -> bytes:
    """A file of vkFormat 0 whose descriptor's colorModel is `model` (163 ETC1S, 166 UASTC), as basisu writes."""
    data = _patched(encode(_texels("unorm8", (4, 4, 4)), "unorm8"), 12, "<2I", 0, 1)
    return _patched(data, 104 + 12, "<I", model | 1 << 8 | 2 << 16)


@pytest.mark.parametrize("data, message", [
    (_patched(GOOD, 44, "<I", 1), "supercompressionScheme is 1 (BasisLZ (Basis Universal ETC1S))"),
    (_patched(GOOD, 44, "<I", 2), "supercompressionScheme is 2 (Zstandard)"),
    (_patched(GOOD, 44, "<I", 3), "supercompressionScheme is 3 (ZLIB)"),
    (_basis(166), "a Basis Universal UASTC file (vkFormat 0, colorModel 166)"),
    (_basis(163), "a Basis Universal ETC1S file"),
    (_basis(1), "vkFormat 0 (UNDEFINED) is not a format this reader takes"),
    (_patched(GOOD, 12, "<I", 29), "vkFormat 29 (R8G8B8_SRGB) is not a format this reader takes"),
], ids=_id)
def test_compressed_files_are_refused_by_name(data, message):
    with pytest.raises(Ktx2Error) as e:
        decode_levels(data, "albedo.ktx2")
    text = str(e.value)
    assert message in text and ("uncompressed" in text or "re-export it as RGBA" in text), text


def test_every_truncation_of_a_chain_is_a_ktx2_error():
    for n in range(len(CHAIN)):
        with pytest.raises(Ktx2Error):
            decode_levels(CHAIN[:n])
    for i in range(CHAIN_INDEX[2][0]):  # every byte before the texels
        corrupt = bytearray(CHAIN)
        corrupt[i] ^= 0xFF
        try:
            decode_levels(bytes(corrupt))
        except Ktx2Error:
            pass
