"""KTX 2.0 files: a small writer (`encode`, `encode_levels`) and a checking reader (`decode`, `decode_levels`).

Baked lookup tables are one level of linear RGBA (unorm8, fp16, fp32); textures made from images
(assemble/textures.py) are a full mip chain, colour ones R8G8B8A8_SRGB (srgb8).

Why our own: no maintained pure-Python KTX2 writer exists on PyPI (``pyktx`` binds the C libktx and
builds only against an installed KTX-Software; ``pyktx2`` is a read-only parser last released in 2021;
``alktx2`` wraps Basis Universal). Uncompressed KTX2 is a fixed ~250-byte preamble and the levels'
texels, so it is written here from the specification and read back in the tests by an independent reader.

References: Khronos, *KTX File Format Specification, version 2.0* ("KTX2" below; sections by name),
and Khronos, *Data Format Specification 1.3* ("KDF"), §5 "Khronos Basic Data Format Descriptor Block"
(the descriptor's words are built and compared in io/dfd.py).

Layout written (every integer little-endian, KTX2 "File Structure"; offsets for the files we write
of one level, as a lookup table is; L levels move everything after the level index by 24 (L − 1)):

====== ======= ==================================================================================
offset  bytes   field
====== ======= ==================================================================================
0       12      identifier ``«KTX 20»\\r\\n\\x1A\\n`` (KTX2 "identifier")
12      4 × 9   vkFormat (37 R8G8B8A8_UNORM | 43 R8G8B8A8_SRGB | 97 R16G16B16A16_SFLOAT |
                109 R32G32B32A32_SFLOAT), typeSize (bytes of one component: 1 | 2 | 4, KTX2
                "typeSize"), pixelWidth, pixelHeight, pixelDepth = 0, layerCount = 0 (not an
                array), faceCount (1 | 6), levelCount = L (1: a lookup table is not mipmapped; a
                texture's full chain down to 1 × 1, KTX2 "levelCount"), supercompressionScheme = 0
48      32      index: dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength (u32),
                sgdByteOffset = sgdByteLength = 0 (u64: no supercompression global data)
80      24 × L  level index, level 0 (the largest) first: byteOffset, byteLength,
                uncompressedByteLength (u64; the two lengths are equal without supercompression,
                KTX2 "Level Index"); level i is max(1, W >> i) × max(1, H >> i) (KTX2 "levelCount")
104     92      Data Format Descriptor: dfdTotalSize (u32) + one Basic DFD block of 24 + 16 × 4
                bytes (KDF §5): vendorId 0 / descriptorType 0, versionNumber 2 (KDF 1.3),
                descriptorBlockSize 88; colorModel KHR_DF_MODEL_RGBSDA (1), colorPrimaries
                KHR_DF_PRIMARIES_BT709 (1), transferFunction KHR_DF_TRANSFER_LINEAR (1) or, for
                srgb8, KHR_DF_TRANSFER_SRGB (2), flags KHR_DF_FLAG_ALPHA_STRAIGHT (0);
                texelBlockDimension0..3 = 0 (1 × 1 × 1 × 1 texel blocks); bytesPlane0 = texel size
                (4 | 8 | 16), bytesPlane1..7 = 0; then one sample per channel R, G, B, A
                (channelType 0, 1, 2, 15) at bitOffset 0, n, 2n, 3n with bitLength n − 1 (n = 8 |
                16 | 32 bits), samplePosition 0; unorm8 and srgb8: qualifiers 0, sampleLower 0,
                sampleUpper 255, except srgb8's alpha sample, qualifier KHR_DF_SAMPLE_DATATYPE_LINEAR
                (0x10: alpha is not sRGB-encoded, KTX2 "dataFormatDescriptor" requires the bit);
                fp16/fp32: qualifiers FLOAT | SIGNED, sampleLower −1.0f, sampleUpper 1.0f as
                IEEE-754 binary32 bit patterns (KDF: the float range that maps to the normalized
                [−1, 1]; these are the values Khronos's own libktx writes for every *_SFLOAT
                format, half floats included)
196     52      Key/Value Data, sorted by key (KTX2 "Key/Value Data"), each entry a u32
                keyAndValueByteLength, the key, NUL, the value, then 0-3 NUL bytes of valuePadding:
                ``KTXorientation`` = ``"rd\\0"`` (row 0 of the array is t = 0 and x increases to the
                right: Vulkan's, D3D's and WebGPU's convention, and the only one KTX2 allows for
                cube maps), ``KTXwriter`` = the writer string, NUL-terminated (52 bytes for the
                default ``"shadermatrix"``; the offsets below move with its length)
≥ 248   …       the levels' texels, the smallest level first and level 0 last (KTX2 "Level Index":
                "mip levels are stored in order from smallest to largest", so that a streaming loader
                has the small levels first), each after its mipPadding: zeros up to a multiple of
                lcm(texel block size, 4) = 4 | 8 | 16 bytes (Vulkan copies need texel- and 4-byte-
                aligned sources). Within a level: faces +X, −X, +Y, −Y, +Z, −Z in that order for a
                cube map (KTX2 "faceCount"), each face rows top to bottom, texels left to right,
                RGBA, tightly packed (KTX2 "levelImages"); the file ends with level 0's last texel
====== ======= ==================================================================================

A 1D table (H = 1) is written as a 2D texture of height 1 (pixelHeight = 1), not as a KTX2 1D
texture (pixelHeight = 0): every table is bound as a 2D texture in all three languages, and WGSL's
``textureSampleLevel`` (the only sampling a compute-shader eval kernel has) has no ``texture_1d``
overload. `decode` still reads a 1D file (pixelHeight 0) from another tool, as H = 1, and
`decode_levels` a file of levelCount 0 (KTX2: one level stored, the loader makes the others).

The reader takes the files of this writer and uncompressed RGBA files of another tool in these four
formats; it refuses Basis Universal (BasisLZ supercompression, or vkFormat 0 with an ETC1S or UASTC
descriptor) and every other supercompression, each by name.

The bytes depend only on the texels, the format, cube and the writer string: no time, no path.
"""
from __future__ import annotations

import math
import struct
from typing import NamedTuple

import numpy as np

from ..lang.errors import UserError
from . import dfd
from .dfd import CHANNELS

IDENTIFIER = b"\xabKTX 20\xbb\r\n\x1a\n"
KTX1_IDENTIFIER = b"\xabKTX 11\xbb\r\n\x1a\n"

VK_FORMAT_R8G8B8A8_UNORM = 37
VK_FORMAT_R8G8B8A8_SRGB = 43
VK_FORMAT_R16G16B16A16_SFLOAT = 97
VK_FORMAT_R32G32B32A32_SFLOAT = 109

# fmt -> (vkFormat, numpy dtype of one component). Little-endian on disk whatever the host.
FORMATS = {
    "unorm8": (VK_FORMAT_R8G8B8A8_UNORM, np.dtype(np.uint8)),
    "fp16": (VK_FORMAT_R16G16B16A16_SFLOAT, np.dtype(np.float16)),
    "fp32": (VK_FORMAT_R32G32B32A32_SFLOAT, np.dtype(np.float32)),
    "srgb8": (VK_FORMAT_R8G8B8A8_SRGB, np.dtype(np.uint8)),
}
VK_NAMES = {"unorm8": "R8G8B8A8_UNORM", "fp16": "R16G16B16A16_SFLOAT", "fp32": "R32G32B32A32_SFLOAT",
            "srgb8": "R8G8B8A8_SRGB"}  # the Vulkan names (VK_FORMAT_ dropped) a manifest states
_BY_VK = {vk: fmt for fmt, (vk, _) in FORMATS.items()}
# formats of other tools' files a refusal names (toktx writes RGB PNGs as R8G8B8_SRGB)
_OTHER_VK = {0: "UNDEFINED", 9: "R8_UNORM", 15: "R8_SRGB", 16: "R8G8_UNORM", 22: "R8G8_SRGB", 23: "R8G8B8_UNORM",
             29: "R8G8B8_SRGB", 91: "R16G16B16A16_UNORM", 100: "R32_SFLOAT", 145: "BC7_UNORM_BLOCK",
             146: "BC7_SRGB_BLOCK"}

# dfd.CHANNELS = 4, RGBA: the only layouts above; a table with fewer channels pads them (Vulkan's RGB formats
# are rarely sampleable, so engines load RGBA)

SUPERCOMPRESSION = {1: "BasisLZ (Basis Universal ETC1S)", 2: "Zstandard", 3: "ZLIB"}  # KTX2 "supercompressionScheme"

_HEADER = struct.Struct("<12s9I")     # identifier + 9 u32 (KTX2 "File Structure")
_INDEX = struct.Struct("<4I2Q")       # dfd/kvd offsets and lengths, sgd offset and length
_LEVEL = struct.Struct("<3Q")         # byteOffset, byteLength, uncompressedByteLength
_PREAMBLE = _HEADER.size + _INDEX.size  # 80

HINT = "the file is truncated or corrupt: rebuild it (shadermatrix build), or re-export it as KTX2"
UNCOMPRESSED_HINT = ("give the image as PNG or JPEG, or as uncompressed KTX2 (R8G8B8A8_SRGB, R8G8B8A8_UNORM "
                     "or RGBA float; no Basis encoding, no supercompression)")


class Ktx2Error(UserError):
    """A KTX2 file this reader cannot take: `<file>: what is wrong — what to do`."""

    def __init__(self, shown: str, what: str, hint: str = HINT):
        self.shown, self.what, self.hint = shown, what, hint
        super().__init__(f"{shown}: {what} — {hint}")


def texel_size(fmt: str) -> int:
    """Bytes of one RGBA texel of `fmt` (the texel block size of KTX2 "mipPadding")."""
    return CHANNELS * FORMATS[fmt][1].itemsize


def level_alignment(fmt: str) -> int:
    """KTX2 "mipPadding": level data starts at a multiple of lcm(texel block size, 4)."""
    size = texel_size(fmt)
    return size * 4 // math.gcd(size, 4)


def full_level_count(width: int, height: int) -> int:
    """Levels of a full chain down to 1 × 1: floor(log2(max(W, H))) + 1 (KTX2 "levelCount")."""
    return max(width, height).bit_length()


def level_size(width: int, height: int, level: int) -> tuple[int, int]:
    """(W, H) of mip level `level`: each halved and rounded down, at least 1 (KTX2, Vulkan)."""
    return max(1, width >> level), max(1, height >> level)


def _align(n: int, to: int) -> int:
    return -(-n // to) * to


def _dfd(fmt: str) -> bytes:
    """dfdTotalSize and the Basic Data Format Descriptor block of `fmt` (KDF §5)."""
    dtype = FORMATS[fmt][1]
    return dfd.basic(dtype.itemsize * 8, dtype.kind == "f", fmt == "srgb8")


def _kvd(entries: list[tuple[bytes, bytes]]) -> bytes:
    """Key/Value Data: sorted entries, each length-prefixed and padded to 4 bytes (KTX2 "Key/Value Data")."""
    out = bytearray()
    for key, value in sorted(entries):
        pair = key + b"\0" + value
        out += struct.pack("<I", len(pair)) + pair + b"\0" * (_align(len(pair), 4) - len(pair))
    return bytes(out)


def _shape_error(texels, cube: bool) -> str | None:
    shape = texels.shape
    if cube:
        if len(shape) != 4 or shape[0] != 6 or shape[3] != CHANNELS:
            return f"a cube map's texels are (6, S, S, 4), not {shape}"
        if shape[1] != shape[2]:
            return f"a cube map's faces are square, not {shape[1]} × {shape[2]} (KTX2 faceCount)"
    elif len(shape) != 3 or shape[2] != CHANNELS:
        return f"a 2D (or 1D, H = 1) table's texels are (H, W, 4), not {shape}"
    if 0 in shape:
        return f"a table has at least one texel, not the shape {shape}"
    if max(shape) >= 1 << 32:
        return f"a dimension of {shape} does not fit the header's 32-bit fields"
    return None


def _level_bytes(texels, fmt: str, cube: bool, level: int) -> bytes:
    """One level's texels as the file holds them; ValueError for an array that is not one."""
    dtype = FORMATS[fmt][1]
    where = f"level {level}: " if level else ""
    if not isinstance(texels, np.ndarray):
        raise ValueError(f"{where}texels are a numpy array, not {type(texels).__name__}")
    if texels.dtype.base.newbyteorder("=") != dtype.newbyteorder("="):
        raise ValueError(f"{where}{fmt} texels are {dtype.name}, not {texels.dtype.name}: convert (and round) "
                         "them where the table is baked, where the error is measured")
    problem = _shape_error(texels, cube)
    if problem:
        raise ValueError(where + problem)
    if dtype.kind == "f" and not np.isfinite(texels).all():
        # a NaN or infinity in a baked table is a baking bug; filtering would spread it to neighbours
        raise ValueError(f"{where}{fmt} texels contain NaN or infinity ({np.count_nonzero(~np.isfinite(texels))} "
                         "components): fix the table where it is baked")
    return np.ascontiguousarray(texels, dtype=dtype.newbyteorder("<")).tobytes()


def encode(texels: np.ndarray, fmt: str, *, cube: bool = False, writer: str = "shadermatrix") -> bytes:
    """The KTX2 file of one level of RGBA texels: (H, W, 4), or (6, S, S, 4) faces +X −X +Y −Y +Z −Z."""
    return encode_levels([texels], fmt, cube=cube, writer=writer)


def encode_levels(levels, fmt: str, *, cube: bool = False, writer: str = "shadermatrix") -> bytes:
    """The KTX2 file of a mip chain given level 0 (the largest) first, level i of max(1, W >> i) ×
    max(1, H >> i) texels, each level shaped as `encode` takes it; any prefix of the full chain."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown KTX2 format {fmt!r}: one of {', '.join(FORMATS)}")
    if "\0" in writer:
        raise ValueError("the KTXwriter string cannot contain NUL (it is NUL-terminated)")
    levels = list(levels)
    if not levels:
        raise ValueError("a KTX2 file has at least one level")
    datas = [_level_bytes(t, fmt, cube, i) for i, t in enumerate(levels)]
    base = levels[0].shape
    faces, height, width = (6, base[1], base[2]) if cube else (1,) + base[:2]
    if len(levels) > full_level_count(width, height):
        raise ValueError(f"{len(levels)} levels, more than the {full_level_count(width, height)} of a full chain "
                         f"from {width} × {height} down to 1 × 1")
    for i, t in enumerate(levels[1:], 1):
        w, h = level_size(width, height, i)
        want = (6, h, w, CHANNELS) if cube else (h, w, CHANNELS)
        if t.shape != want:
            raise ValueError(f"level {i} is {t.shape}, not {want}: level i has max(1, W >> i) × max(1, H >> i) "
                             "texels")

    vk_format, dtype = FORMATS[fmt]
    descriptor = _dfd(fmt)
    kvd = _kvd([(b"KTXorientation", b"rd\0"), (b"KTXwriter", writer.encode("utf-8") + b"\0")])
    dfd_offset = _PREAMBLE + _LEVEL.size * len(levels)
    kvd_offset = dfd_offset + len(descriptor)
    offsets, end = [0] * len(levels), kvd_offset + len(kvd)
    for i in reversed(range(len(levels))):  # the smallest level first, level 0 last
        offsets[i] = _align(end, level_alignment(fmt))
        end = offsets[i] + len(datas[i])
    header = _HEADER.pack(IDENTIFIER, vk_format, dtype.itemsize, width, height, 0, 0, faces, len(levels), 0)
    index = _INDEX.pack(dfd_offset, len(descriptor), kvd_offset, len(kvd), 0, 0)
    out = bytearray(header + index)
    for offset, data in zip(offsets, datas):
        out += _LEVEL.pack(offset, len(data), len(data))
    out += descriptor + kvd
    for i in reversed(range(len(levels))):
        out += b"\0" * (offsets[i] - len(out)) + datas[i]
    return bytes(out)


def _check_dfd(data: bytes, offset: int, fmt: str, shown: str) -> None:
    """The DFD is the one `fmt` has (KDF §5), field by field, the first difference named."""
    want = struct.unpack(f"<{dfd.WORDS}I", _dfd(fmt))
    got = struct.unpack_from(f"<{dfd.WORDS}I", data, offset)
    model, transfer = got[dfd.MODEL_WORD] & 0xFF, (got[dfd.MODEL_WORD] >> 16) & 0xFF
    want_transfer = (want[dfd.MODEL_WORD] >> 16) & 0xFF
    if got[1] == want[1] and model != dfd.KHR_DF_MODEL_RGBSDA:
        raise Ktx2Error(shown, f"the Data Format Descriptor's colorModel is {model}, not RGBSDA "
                        f"({dfd.KHR_DF_MODEL_RGBSDA})")
    if got[1] == want[1] and transfer != want_transfer:
        wanted = "sRGB" if want_transfer == dfd.KHR_DF_TRANSFER_SRGB else "linear"
        raise Ktx2Error(shown, f"the transfer function is {transfer}, not {wanted} ({want_transfer}) as vkFormat "
                        f"{FORMATS[fmt][0]} ({VK_NAMES[fmt]}) requires",
                        "re-export the file with the vkFormat of its encoding (an sRGB one for sRGB texels)")
    diff = dfd.first_difference(got, want, fmt == "srgb8")
    if diff:
        i, g, w = diff
        raise Ktx2Error(shown, f"the Data Format Descriptor's {dfd.FIELDS[i]} (byte {offset + 4 * i}) is "
                        f"0x{g:08x}, not 0x{w:08x} as {fmt} (vkFormat {FORMATS[fmt][0]}) requires")


def _check_kvd(data: bytes, offset: int, length: int, shown: str) -> None:
    """Key/Value entries tile kvdByteLength exactly, each key NUL-terminated (KTX2 "Key/Value Data")."""
    pos, end, keys = offset, offset + length, []
    while pos < end:
        if pos + 4 > end:
            raise Ktx2Error(shown, f"a key/value entry at byte {pos} is cut off by kvdByteLength")
        (n,) = struct.unpack_from("<I", data, pos)
        if n < 2 or pos + 4 + n > end:
            raise Ktx2Error(shown, f"the key/value entry at byte {pos} has keyAndValueByteLength {n}, "
                            f"{'less than 2' if n < 2 else f'past the key/value data end {end}'}")
        pair = data[pos + 4: pos + 4 + n]
        if b"\0" not in pair:
            raise Ktx2Error(shown, f"the key at byte {pos + 4} has no NUL terminator")
        keys.append(pair[: pair.index(b"\0")])
        pos += 4 + _align(n, 4)
    if pos != end:
        raise Ktx2Error(shown, f"the key/value entries' padding runs {pos - end} bytes past kvdByteLength {length}")
    if keys != sorted(set(keys)):
        raise Ktx2Error(shown, "the key/value keys are not sorted and unique (KTX2 \"Key/Value Data\")")


def _refuse_compressed(data: bytes, vk_format: int, scheme: int, shown: str) -> None:
    """Basis Universal and supercompressed files, by name: this reader has no transcoder or inflater."""
    if scheme != 0:
        name = SUPERCOMPRESSION.get(scheme, "unknown")
        raise Ktx2Error(shown, f"supercompressionScheme is {scheme} ({name}); this reader takes uncompressed files",
                        UNCOMPRESSED_HINT)
    if vk_format == 0 and len(data) >= _PREAMBLE:
        (dfd_offset,) = struct.unpack_from("<I", data, _HEADER.size)
        if dfd_offset + 16 <= len(data):
            model = struct.unpack_from("<I", data, dfd_offset + 12)[0] & 0xFF
            codec = {dfd.KHR_DF_MODEL_ETC1S: "ETC1S", dfd.KHR_DF_MODEL_UASTC: "UASTC"}.get(model)
            if codec:
                raise Ktx2Error(shown, f"a Basis Universal {codec} file (vkFormat 0, colorModel {model}): this "
                                "reader does not transcode Basis", UNCOMPRESSED_HINT)


def decode(data: bytes, shown: str = "<ktx2>") -> tuple[np.ndarray, str, bool]:
    """(texels, fmt, cube) of a one-level, uncompressed KTX2 file of one of FORMATS; Ktx2Error otherwise."""
    levels, fmt, cube = decode_levels(data, shown, max_levels=1)
    return levels[0], fmt, cube


def decode_levels(data: bytes, shown: str = "<ktx2>", *, max_levels: int | None = None
                  ) -> tuple[list[np.ndarray], str, bool]:
    """(levels, level 0 first; fmt; cube) of an uncompressed KTX2 file of one of FORMATS; Ktx2Error otherwise
    (for more than `max_levels` levels too: a baked table has one)."""
    data = bytes(data)
    size = len(data)
    if size < _PREAMBLE:
        if data[:len(IDENTIFIER)] != IDENTIFIER[:min(size, len(IDENTIFIER))]:
            raise Ktx2Error(shown, "not a KTX 2.0 file (wrong identifier)", "give a .ktx2 file")
        raise Ktx2Error(shown, f"truncated: {size} bytes, less than the {_PREAMBLE}-byte header and index")
    (ident, vk_format, type_size, width, height, depth, layers, faces, count,
     scheme) = _HEADER.unpack_from(data)
    if ident != IDENTIFIER:
        what = ("a KTX 1 file; this reader takes KTX 2.0" if ident == KTX1_IDENTIFIER
                else f"not a KTX 2.0 file: the identifier is {ident!r}, not {IDENTIFIER!r}")
        raise Ktx2Error(shown, what, "convert it to KTX 2.0 (KTX-Software's ktx2ktx2)" if ident == KTX1_IDENTIFIER
                        else "give a .ktx2 file")
    _refuse_compressed(data, vk_format, scheme, shown)
    if vk_format not in _BY_VK:
        known = ", ".join(f"{vk} ({VK_NAMES[fmt]})" for vk, fmt in _BY_VK.items())
        name = f" ({_OTHER_VK[vk_format]})" if vk_format in _OTHER_VK else ""
        raise Ktx2Error(shown, f"vkFormat {vk_format}{name} is not a format this reader takes: one of {known}",
                        "re-export it as RGBA: R8G8B8A8_SRGB, R8G8B8A8_UNORM, R16G16B16A16_SFLOAT or "
                        "R32G32B32A32_SFLOAT")
    fmt = _BY_VK[vk_format]
    dtype = FORMATS[fmt][1]
    if type_size != dtype.itemsize:
        raise Ktx2Error(shown, f"typeSize is {type_size}, not {dtype.itemsize} as vkFormat {vk_format} requires")
    if width == 0 or depth != 0 or layers != 0 or faces not in (1, 6):
        raise Ktx2Error(shown, f"pixelWidth {width}, pixelDepth {depth}, layerCount {layers}, faceCount {faces}: "
                        "a 1D or 2D texture or a cube map is read (width > 0, depth 0, no layers, 1 or 6 faces)")
    if faces == 6 and height != width:
        raise Ktx2Error(shown, f"a cube map's faces are square, not {width} × {height}")
    if max_levels is not None and count > max_levels:
        raise Ktx2Error(shown, f"levelCount is {count}; a baked table has one level",
                        "re-export the table without mipmaps")
    height = max(height, 1)  # pixelHeight 0: a 1D texture, read as one row
    count = max(count, 1)    # levelCount 0: one level stored, the loader generates the rest (KTX2 "levelCount")
    if count > full_level_count(width, height):
        raise Ktx2Error(shown, f"levelCount is {count}, more than the {full_level_count(width, height)} levels of "
                        f"a {width} × {height} texture down to 1 × 1")
    index_end = _PREAMBLE + _LEVEL.size * count
    if size < index_end:
        raise Ktx2Error(shown, f"truncated: {size} bytes end inside the level index (bytes {_PREAMBLE}–{index_end})")
    header_end = _check_descriptors(data, fmt, index_end, shown)
    spans = [_LEVEL.unpack_from(data, _PREAMBLE + _LEVEL.size * i) for i in range(count)]
    levels = []
    for i, (offset, length, raw) in enumerate(spans):
        w, h = level_size(width, height, i)
        # the next smaller level's data comes before this one's (KTX2: stored from smallest to largest)
        floor, after = ((header_end, "the descriptors, which end") if i == count - 1 else
                        (spans[i + 1][0] + spans[i + 1][1], f"level {i + 1}, which ends"))
        span = _Span("the level" if count == 1 else f"level {i}", offset, length, raw,
                     faces * h * w * texel_size(fmt), f"{faces} face(s) × {h} × {w}", floor, after, i == 0)
        _check_level(span, size, fmt, shown)
        flat = np.frombuffer(data, dtype=dtype.newbyteorder("<"), count=span.expected // dtype.itemsize,
                             offset=offset)
        levels.append(flat.astype(dtype).reshape((6, h, w, CHANNELS) if faces == 6 else (h, w, CHANNELS)))
    return levels, fmt, faces == 6


def _check_descriptors(data: bytes, fmt: str, index_end: int, shown: str) -> int:
    """The index's DFD and key/value data, checked; the byte where they end."""
    size = len(data)
    dfd_offset, dfd_length, kvd_offset, kvd_length, sgd_offset, sgd_length = _INDEX.unpack_from(data, _HEADER.size)
    if sgd_offset or sgd_length:
        raise Ktx2Error(shown, f"supercompression global data at {sgd_offset} ({sgd_length} bytes) without "
                        "supercompression")
    if dfd_length != dfd.DFD_SIZE:
        raise Ktx2Error(shown, f"dfdByteLength is {dfd_length}, not {dfd.DFD_SIZE} (one basic descriptor block "
                        f"with {CHANNELS} samples, KDF §5)")
    if dfd_offset + dfd_length > size:
        raise Ktx2Error(shown, f"the Data Format Descriptor (byte {dfd_offset}, {dfd_length} bytes) is past the "
                        f"end of the {size}-byte file")
    if dfd_offset != index_end:  # KTX2 "File Structure": the DFD follows the level index
        raise Ktx2Error(shown, f"the Data Format Descriptor starts at byte {dfd_offset}, not right after the "
                        f"level index (byte {index_end})")
    (total,) = struct.unpack_from("<I", data, dfd_offset)
    if total != dfd_length:
        raise Ktx2Error(shown, f"dfdTotalSize is {total}, not dfdByteLength {dfd_length}")
    _check_dfd(data, dfd_offset, fmt, shown)

    header_end = dfd_offset + dfd_length
    if kvd_length:
        if kvd_offset + kvd_length > size:
            raise Ktx2Error(shown, f"the key/value data (byte {kvd_offset}, {kvd_length} bytes) runs past the end "
                            f"of the {size}-byte file")
        if kvd_offset != header_end:  # KTX2 "dfdTotalSize": it must equal kvdByteOffset - dfdByteOffset
            raise Ktx2Error(shown, f"the key/value data starts at byte {kvd_offset}, not right after the Data "
                            f"Format Descriptor (byte {header_end})")
        _check_kvd(data, kvd_offset, kvd_length, shown)
        header_end = kvd_offset + kvd_length
    elif kvd_offset:
        raise Ktx2Error(shown, f"kvdByteOffset is {kvd_offset} with kvdByteLength 0 (must be 0)")
    return header_end


class _Span(NamedTuple):
    """One level's index entry and what it must be."""

    what: str        # "the level" (a one-level file) or "level i"
    offset: int
    length: int
    raw: int         # uncompressedByteLength
    expected: int    # bytes of its texels
    shape: str       # "faces × H × W"
    floor: int       # where the data before it ends: the next smaller level, or the descriptors
    after: str       # what ends at `floor`
    last: bool       # level 0: the file ends with it


def _check_level(s: _Span, size: int, fmt: str, shown: str) -> None:
    """A level's index entry: its length, inside the file, after what precedes it, aligned; level 0 ends the file."""
    align = level_alignment(fmt)
    if s.length != s.expected or s.raw != s.expected:
        raise Ktx2Error(shown, f"{s.what} is {s.length} bytes ({s.raw} uncompressed), not the {s.expected} of "
                        f"{s.shape} {fmt} texels")
    if s.offset + s.length > size:
        raise Ktx2Error(shown, f"{s.what}'s texels (byte {s.offset}, {s.length} bytes) run past the end of the "
                        f"{size}-byte file")
    if s.offset < s.floor:
        raise Ktx2Error(shown, f"{s.what}'s texels (byte {s.offset}) overlap {s.after} at byte {s.floor}")
    if s.offset % align:
        raise Ktx2Error(shown, f"{s.what}'s texels start at byte {s.offset}, not at a multiple of {align} "
                        f"(KTX2 mipPadding: lcm(texel block size {texel_size(fmt)}, 4))")
    if s.last and s.offset + s.length != size:
        raise Ktx2Error(shown, f"{size - s.offset - s.length} bytes follow {s.what}'s texels")
