"""KTX 2.0 files for baked lookup tables: a small writer (`encode`) and a checking reader (`decode`).

Why our own: no maintained pure-Python KTX2 writer exists on PyPI (``pyktx`` binds the C libktx and
builds only against an installed KTX-Software; ``pyktx2`` is a read-only parser last released in 2021;
``alktx2`` wraps Basis Universal). Uncompressed, one-level KTX2 is a fixed ~250-byte preamble, so it is
written here from the specification and read back in the tests by an independent reader.

References: Khronos, *KTX File Format Specification, version 2.0* ("KTX2" below; sections by name),
and Khronos, *Data Format Specification 1.3* ("KDF"), §5 "Khronos Basic Data Format Descriptor Block".

Layout written (every integer little-endian, KTX2 "File Structure"; offsets for the files we write):

====== ======= ==================================================================================
offset  bytes   field
====== ======= ==================================================================================
0       12      identifier ``«KTX 20»\\r\\n\\x1A\\n`` (KTX2 "identifier")
12      4 × 9   vkFormat (37 R8G8B8A8_UNORM | 97 R16G16B16A16_SFLOAT | 109 R32G32B32A32_SFLOAT),
                typeSize (bytes of one component: 1 | 2 | 4, KTX2 "typeSize"), pixelWidth,
                pixelHeight, pixelDepth = 0, layerCount = 0 (not an array), faceCount (1 | 6),
                levelCount = 1 (the base level only: a lookup table is not mipmapped, KTX2
                "levelCount"), supercompressionScheme = 0
48      32      index: dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength (u32),
                sgdByteOffset = sgdByteLength = 0 (u64: no supercompression global data)
80      24      level index, one level: byteOffset, byteLength, uncompressedByteLength (u64; the
                two lengths are equal without supercompression, KTX2 "Level Index")
104     92      Data Format Descriptor: dfdTotalSize (u32) + one Basic DFD block of 24 + 16 × 4
                bytes (KDF §5): vendorId 0 / descriptorType 0, versionNumber 2 (KDF 1.3),
                descriptorBlockSize 88; colorModel KHR_DF_MODEL_RGBSDA (1), colorPrimaries
                KHR_DF_PRIMARIES_BT709 (1), transferFunction KHR_DF_TRANSFER_LINEAR (1), flags
                KHR_DF_FLAG_ALPHA_STRAIGHT (0); texelBlockDimension0..3 = 0 (1 × 1 × 1 × 1 texel
                blocks); bytesPlane0 = texel size (4 | 8 | 16), bytesPlane1..7 = 0; then one
                sample per channel R, G, B, A (channelType 0, 1, 2, 15) at bitOffset 0, n, 2n, 3n
                with bitLength n − 1 (n = 8 | 16 | 32 bits), samplePosition 0; unorm8: qualifiers
                0, sampleLower 0, sampleUpper 255; fp16/fp32: qualifiers FLOAT | SIGNED,
                sampleLower −1.0f, sampleUpper 1.0f as IEEE-754 binary32 bit patterns (KDF: the
                float range that maps to the normalized [−1, 1]; these are the values Khronos's own
                libktx writes for every *_SFLOAT format, half floats included)
196     52      Key/Value Data, sorted by key (KTX2 "Key/Value Data"), each entry a u32
                keyAndValueByteLength, the key, NUL, the value, then 0-3 NUL bytes of valuePadding:
                ``KTXorientation`` = ``"rd\\0"`` (row 0 of the array is t = 0 and x increases to the
                right: Vulkan's, D3D's and WebGPU's convention, and the only one KTX2 allows for
                cube maps), ``KTXwriter`` = the writer string, NUL-terminated (52 bytes for the
                default ``"shadermatrix"``; the offsets below move with its length)
248     0-15    mipPadding: zeros up to a multiple of lcm(texel block size, 4) = 4 | 8 | 16 bytes
                (KTX2 "mipPadding": Vulkan copies need texel- and 4-byte-aligned sources)
≥ 248   …       the level's texels, faces +X, −X, +Y, −Y, +Z, −Z in that order for a cube map
                (KTX2 "faceCount"), each face rows top to bottom, texels left to right, RGBA,
                tightly packed (KTX2 "levelImages"); the file ends with the last texel
====== ======= ==================================================================================

A 1D table (H = 1) is written as a 2D texture of height 1 (pixelHeight = 1), not as a KTX2 1D
texture (pixelHeight = 0): every table is bound as a 2D texture in all three languages, and WGSL's
``textureSampleLevel`` (the only sampling a compute-shader eval kernel has) has no ``texture_1d``
overload. `decode` still reads a 1D file (pixelHeight 0) from another tool, as H = 1.

The bytes depend only on the texels, the format, cube and the writer string: no time, no path.
"""
from __future__ import annotations

import math
import struct

import numpy as np

from ..lang.errors import UserError

IDENTIFIER = b"\xabKTX 20\xbb\r\n\x1a\n"
KTX1_IDENTIFIER = b"\xabKTX 11\xbb\r\n\x1a\n"

VK_FORMAT_R8G8B8A8_UNORM = 37
VK_FORMAT_R16G16B16A16_SFLOAT = 97
VK_FORMAT_R32G32B32A32_SFLOAT = 109

# fmt -> (vkFormat, numpy dtype of one component). Little-endian on disk whatever the host.
FORMATS = {
    "unorm8": (VK_FORMAT_R8G8B8A8_UNORM, np.dtype(np.uint8)),
    "fp16": (VK_FORMAT_R16G16B16A16_SFLOAT, np.dtype(np.float16)),
    "fp32": (VK_FORMAT_R32G32B32A32_SFLOAT, np.dtype(np.float32)),
}
_BY_VK = {vk: fmt for fmt, (vk, _) in FORMATS.items()}

CHANNELS = 4  # RGBA: the only layouts above; a table with fewer channels pads them (Vulkan's
#               RGB formats are rarely sampleable, so engines load RGBA)

# Khronos Data Format 1.3 constants (KDF §5; khr_df.h)
KHR_DF_VENDORID_KHRONOS = 0
KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT = 0
KHR_DF_VERSIONNUMBER_1_3 = 2
KHR_DF_MODEL_RGBSDA = 1
KHR_DF_PRIMARIES_BT709 = 1
KHR_DF_TRANSFER_LINEAR = 1
KHR_DF_FLAG_ALPHA_STRAIGHT = 0
KHR_DF_CHANNEL_RGBSDA = (0, 1, 2, 15)  # R, G, B, A channel ids
KHR_DF_SAMPLE_DATATYPE_SIGNED = 0x40   # qualifier bits of the 8-bit channelType byte
KHR_DF_SAMPLE_DATATYPE_FLOAT = 0x80
FLOAT_ONE, FLOAT_MINUS_ONE = 0x3F800000, 0xBF800000  # 1.0f, -1.0f as binary32 bit patterns

_HEADER = struct.Struct("<12s9I")     # identifier + 9 u32 (KTX2 "File Structure")
_INDEX = struct.Struct("<4I2Q")       # dfd/kvd offsets and lengths, sgd offset and length
_LEVEL = struct.Struct("<3Q")         # byteOffset, byteLength, uncompressedByteLength
_PREAMBLE = _HEADER.size + _INDEX.size  # 80
_BLOCK_HEADER = 24                    # KDF §5: the basic block before its samples
_SAMPLE = 16                          # KDF §5: one sample's four words
DFD_SIZE = 4 + _BLOCK_HEADER + _SAMPLE * CHANNELS  # 92: dfdTotalSize + one block of four samples

HINT = "the file is truncated or corrupt: rebuild it (shadermatrix build), or re-export it as KTX2"


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


def _align(n: int, to: int) -> int:
    return -(-n // to) * to


def _dfd(fmt: str) -> bytes:
    """dfdTotalSize and the Basic Data Format Descriptor block of `fmt` (KDF §5)."""
    bits = FORMATS[fmt][1].itemsize * 8
    is_float = FORMATS[fmt][1].kind == "f"
    block_size = _BLOCK_HEADER + _SAMPLE * CHANNELS
    words = [
        DFD_SIZE,
        KHR_DF_VENDORID_KHRONOS | KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT << 17,
        KHR_DF_VERSIONNUMBER_1_3 | block_size << 16,
        KHR_DF_MODEL_RGBSDA | KHR_DF_PRIMARIES_BT709 << 8 | KHR_DF_TRANSFER_LINEAR << 16
        | KHR_DF_FLAG_ALPHA_STRAIGHT << 24,
        0,                      # texelBlockDimension0..3 = 0: 1 × 1 × 1 × 1
        texel_size(fmt), 0,     # bytesPlane0 = bytes of a texel; bytesPlane1..7 = 0 (one plane)
    ]
    qualifiers = KHR_DF_SAMPLE_DATATYPE_FLOAT | KHR_DF_SAMPLE_DATATYPE_SIGNED if is_float else 0
    lower, upper = (FLOAT_MINUS_ONE, FLOAT_ONE) if is_float else (0, (1 << bits) - 1)
    for i, channel in enumerate(KHR_DF_CHANNEL_RGBSDA):
        words += [i * bits | (bits - 1) << 16 | (channel | qualifiers) << 24, 0, lower, upper]
    return struct.pack(f"<{len(words)}I", *words)


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


def encode(texels: np.ndarray, fmt: str, *, cube: bool = False, writer: str = "shadermatrix") -> bytes:
    """The KTX2 file of one level of RGBA texels: (H, W, 4), or (6, S, S, 4) faces +X −X +Y −Y +Z −Z."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown KTX2 table format {fmt!r}: one of {', '.join(FORMATS)}")
    vk_format, dtype = FORMATS[fmt]
    if not isinstance(texels, np.ndarray):
        raise ValueError(f"texels are a numpy array, not {type(texels).__name__}")
    if texels.dtype.base.newbyteorder("=") != dtype.newbyteorder("="):
        raise ValueError(f"{fmt} texels are {dtype.name}, not {texels.dtype.name}: convert (and round) "
                         "them where the table is baked, where the error is measured")
    problem = _shape_error(texels, cube)
    if problem:
        raise ValueError(problem)
    if dtype.kind == "f" and not np.isfinite(texels).all():
        # a NaN or infinity in a baked table is a baking bug; filtering would spread it to neighbours
        raise ValueError(f"{fmt} texels contain NaN or infinity ({np.count_nonzero(~np.isfinite(texels))} "
                         "components): fix the table where it is baked")
    if "\0" in writer:
        raise ValueError("the KTXwriter string cannot contain NUL (it is NUL-terminated)")

    faces, height, width = (6, texels.shape[1], texels.shape[2]) if cube else (1,) + texels.shape[:2]
    data = np.ascontiguousarray(texels, dtype=dtype.newbyteorder("<")).tobytes()
    dfd = _dfd(fmt)
    kvd = _kvd([(b"KTXorientation", b"rd\0"), (b"KTXwriter", writer.encode("utf-8") + b"\0")])
    dfd_offset = _PREAMBLE + _LEVEL.size
    kvd_offset = dfd_offset + len(dfd)
    level_offset = _align(kvd_offset + len(kvd), level_alignment(fmt))
    header = _HEADER.pack(IDENTIFIER, vk_format, dtype.itemsize, width, height, 0, 0, faces, 1, 0)
    index = _INDEX.pack(dfd_offset, len(dfd), kvd_offset, len(kvd), 0, 0)
    level = _LEVEL.pack(level_offset, len(data), len(data))
    out = header + index + level + dfd + kvd
    return out + b"\0" * (level_offset - len(out)) + data


def _check_dfd(data: bytes, offset: int, fmt: str, shown: str) -> None:
    """The DFD is the one `fmt` has (KDF §5), field by field, the first difference named."""
    want = struct.unpack(f"<{DFD_SIZE // 4}I", _dfd(fmt))
    got = struct.unpack_from(f"<{DFD_SIZE // 4}I", data, offset)
    names = ["dfdTotalSize", "vendorId/descriptorType", "versionNumber/descriptorBlockSize",
             "colorModel/colorPrimaries/transferFunction/flags", "texelBlockDimension0..3",
             "bytesPlane0..3", "bytesPlane4..7"]
    for channel in "RGBA":
        names += [f"sample {channel} bitOffset/bitLength/channelType/qualifiers",
                  f"sample {channel} samplePosition0..3", f"sample {channel} sampleLower",
                  f"sample {channel} sampleUpper"]
    model = got[3]
    if got[1] == want[1] and model & 0xFF != KHR_DF_MODEL_RGBSDA:
        raise Ktx2Error(shown, f"the Data Format Descriptor's colorModel is {model & 0xFF}, not "
                        f"RGBSDA ({KHR_DF_MODEL_RGBSDA})")
    if got[1] == want[1] and (model >> 16) & 0xFF != KHR_DF_TRANSFER_LINEAR:
        raise Ktx2Error(shown, f"the transfer function is {(model >> 16) & 0xFF}, not linear "
                        f"({KHR_DF_TRANSFER_LINEAR}): a lookup table holds linear values",
                        "re-export the table without sRGB encoding")
    for i, (g, w, name) in enumerate(zip(got, want, names)):
        if i == 3:  # colorPrimaries do not change a table's numbers: any is read
            g, w = g & 0xFFFF00FF, w & 0xFFFF00FF
        if g != w:
            raise Ktx2Error(shown, f"the Data Format Descriptor's {name} (byte {offset + 4 * i}) is "
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


def decode(data: bytes, shown: str = "<ktx2>") -> tuple[np.ndarray, str, bool]:
    """(texels, fmt, cube) of a one-level, uncompressed KTX2 file of one of FORMATS; Ktx2Error otherwise."""
    data = bytes(data)
    size = len(data)
    if size < _PREAMBLE:
        if data[:len(IDENTIFIER)] != IDENTIFIER[:min(size, len(IDENTIFIER))]:
            raise Ktx2Error(shown, "not a KTX 2.0 file (wrong identifier)", "give a .ktx2 file")
        raise Ktx2Error(shown, f"truncated: {size} bytes, less than the {_PREAMBLE}-byte header and index")
    (ident, vk_format, type_size, width, height, depth, layers, faces, levels,
     scheme) = _HEADER.unpack_from(data)
    if ident != IDENTIFIER:
        what = ("a KTX 1 file; this reader takes KTX 2.0" if ident == KTX1_IDENTIFIER
                else f"not a KTX 2.0 file: the identifier is {ident!r}, not {IDENTIFIER!r}")
        raise Ktx2Error(shown, what, "convert it to KTX 2.0 (KTX-Software's ktx2ktx2)" if ident == KTX1_IDENTIFIER
                        else "give a .ktx2 file")
    if vk_format not in _BY_VK:
        known = ", ".join(f"{vk} ({fmt})" for vk, fmt in _BY_VK.items())
        raise Ktx2Error(shown, f"vkFormat {vk_format} is not a table format: one of {known}",
                        "export the table as RGBA unorm8, fp16 or fp32")
    fmt = _BY_VK[vk_format]
    dtype = FORMATS[fmt][1]
    if type_size != dtype.itemsize:
        raise Ktx2Error(shown, f"typeSize is {type_size}, not {dtype.itemsize} as vkFormat {vk_format} requires")
    if scheme != 0:
        raise Ktx2Error(shown, f"supercompressionScheme is {scheme}; baked tables are not supercompressed",
                        "re-export the table without supercompression")
    if width == 0 or depth != 0 or layers != 0 or faces not in (1, 6):
        raise Ktx2Error(shown, f"pixelWidth {width}, pixelDepth {depth}, layerCount {layers}, faceCount {faces}: "
                        "a table is a 1D or 2D texture or a cube map (width > 0, depth 0, no layers, 1 or 6 faces)")
    if faces == 6 and height != width:
        raise Ktx2Error(shown, f"a cube map's faces are square, not {width} × {height}")
    if levels > 1:
        raise Ktx2Error(shown, f"levelCount is {levels}; a baked table has one level",
                        "re-export the table without mipmaps")
    height = max(height, 1)  # pixelHeight 0: a 1D texture, read as one row
    dfd_offset, dfd_length, kvd_offset, kvd_length, sgd_offset, sgd_length = _INDEX.unpack_from(data, _HEADER.size)
    index_end = _PREAMBLE + _LEVEL.size
    if size < index_end:
        raise Ktx2Error(shown, f"truncated: {size} bytes end inside the level index (bytes {_PREAMBLE}–{index_end})")
    level_offset, level_length, level_raw = _LEVEL.unpack_from(data, _PREAMBLE)

    if sgd_offset or sgd_length:
        raise Ktx2Error(shown, f"supercompression global data at {sgd_offset} ({sgd_length} bytes) without "
                        "supercompression")
    if dfd_length != DFD_SIZE:
        raise Ktx2Error(shown, f"dfdByteLength is {dfd_length}, not {DFD_SIZE} (one basic descriptor block "
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

    expected = faces * height * width * texel_size(fmt)
    align = level_alignment(fmt)
    if level_length != expected or level_raw != expected:
        raise Ktx2Error(shown, f"the level is {level_length} bytes ({level_raw} uncompressed), not the "
                        f"{expected} of {faces} face(s) × {height} × {width} {fmt} texels")
    if level_offset + level_length > size:
        raise Ktx2Error(shown, f"the level's texels (byte {level_offset}, {level_length} bytes) run past the "
                        f"end of the {size}-byte file")
    if level_offset < header_end:
        raise Ktx2Error(shown, f"the level's texels (byte {level_offset}) overlap the descriptors, which end at "
                        f"byte {header_end}")
    if level_offset % align:
        raise Ktx2Error(shown, f"the level's texels start at byte {level_offset}, not at a multiple of {align} "
                        f"(KTX2 mipPadding: lcm(texel block size {texel_size(fmt)}, 4))")
    if level_offset + level_length != size:
        raise Ktx2Error(shown, f"{size - level_offset - level_length} bytes follow the level's texels")

    flat = np.frombuffer(data, dtype=dtype.newbyteorder("<"), count=expected // dtype.itemsize,
                         offset=level_offset).astype(dtype)
    shape = (6, height, width, CHANNELS) if faces == 6 else (height, width, CHANNELS)
    return flat.reshape(shape), fmt, faces == 6
