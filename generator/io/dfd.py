"""The Khronos Basic Data Format Descriptor of the four RGBA formats KTX2 files hold here (io/ktx2.py).

Khronos, *Data Format Specification 1.3* ("KDF"), §5 "Khronos Basic Data Format Descriptor Block";
the constants are khr_df.h's. A descriptor is dfdTotalSize and one basic block of 24 bytes plus one
16-byte sample per channel R, G, B, A; io/ktx2.py's docstring lays out every word.
"""
from __future__ import annotations

import struct

KHR_DF_VENDORID_KHRONOS = 0
KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT = 0
KHR_DF_VERSIONNUMBER_1_3 = 2
KHR_DF_MODEL_RGBSDA = 1
KHR_DF_MODEL_ETC1S = 163   # Basis Universal's two codecs (KDF colorModel)
KHR_DF_MODEL_UASTC = 166
KHR_DF_PRIMARIES_BT709 = 1
KHR_DF_TRANSFER_LINEAR = 1
KHR_DF_TRANSFER_SRGB = 2
KHR_DF_FLAG_ALPHA_STRAIGHT = 0
KHR_DF_CHANNEL_RGBSDA = (0, 1, 2, 15)  # R, G, B, A channel ids
KHR_DF_CHANNEL_ALPHA = 15
KHR_DF_SAMPLE_DATATYPE_LINEAR = 0x10   # qualifier bits of the 8-bit channelType byte
KHR_DF_SAMPLE_DATATYPE_SIGNED = 0x40
KHR_DF_SAMPLE_DATATYPE_FLOAT = 0x80
FLOAT_ONE, FLOAT_MINUS_ONE = 0x3F800000, 0xBF800000  # 1.0f, -1.0f as binary32 bit patterns

CHANNELS = 4
BLOCK_HEADER = 24                     # KDF §5: the basic block before its samples
SAMPLE = 16                           # KDF §5: one sample's four words
DFD_SIZE = 4 + BLOCK_HEADER + SAMPLE * CHANNELS  # 92: dfdTotalSize + one block of four samples
WORDS = DFD_SIZE // 4
MODEL_WORD = 3                        # colorModel, colorPrimaries, transferFunction, flags
ALPHA_WORD = 7 + 4 * 3                # sample A's first word (bit offset, length, channel, qualifiers)

FIELDS = ["dfdTotalSize", "vendorId/descriptorType", "versionNumber/descriptorBlockSize",
          "colorModel/colorPrimaries/transferFunction/flags", "texelBlockDimension0..3",
          "bytesPlane0..3", "bytesPlane4..7"]
for _channel in "RGBA":
    FIELDS += [f"sample {_channel} bitOffset/bitLength/channelType/qualifiers",
               f"sample {_channel} samplePosition0..3", f"sample {_channel} sampleLower",
               f"sample {_channel} sampleUpper"]


def basic(bits: int, is_float: bool, srgb: bool) -> bytes:
    """dfdTotalSize and the basic block of RGBA with `bits` per component, float or unorm, sRGB or linear."""
    words = [
        DFD_SIZE,
        KHR_DF_VENDORID_KHRONOS | KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT << 17,
        KHR_DF_VERSIONNUMBER_1_3 | (BLOCK_HEADER + SAMPLE * CHANNELS) << 16,
        KHR_DF_MODEL_RGBSDA | KHR_DF_PRIMARIES_BT709 << 8
        | (KHR_DF_TRANSFER_SRGB if srgb else KHR_DF_TRANSFER_LINEAR) << 16 | KHR_DF_FLAG_ALPHA_STRAIGHT << 24,
        0,                          # texelBlockDimension0..3 = 0: 1 × 1 × 1 × 1
        CHANNELS * bits // 8, 0,    # bytesPlane0 = bytes of a texel; bytesPlane1..7 = 0 (one plane)
    ]
    qualifiers = KHR_DF_SAMPLE_DATATYPE_FLOAT | KHR_DF_SAMPLE_DATATYPE_SIGNED if is_float else 0
    lower, upper = (FLOAT_MINUS_ONE, FLOAT_ONE) if is_float else (0, (1 << bits) - 1)
    for i, channel in enumerate(KHR_DF_CHANNEL_RGBSDA):
        # alpha is never sRGB-encoded; KTX2 "dataFormatDescriptor" requires the LINEAR bit on its sample
        linear = KHR_DF_SAMPLE_DATATYPE_LINEAR if srgb and channel == KHR_DF_CHANNEL_ALPHA else 0
        words += [i * bits | (bits - 1) << 16 | (channel | qualifiers | linear) << 24, 0, lower, upper]
    return struct.pack(f"<{len(words)}I", *words)


def first_difference(got: tuple[int, ...], want: tuple[int, ...], srgb: bool) -> tuple[int, int, int] | None:
    """(word, got, want) of the first word of a read descriptor that differs from ours, or None. The colour
    primaries do not change the numbers (any is read), nor does an sRGB file's alpha LINEAR bit, which
    other tools may leave unset."""
    for i, (g, w) in enumerate(zip(got, want)):
        if i == MODEL_WORD:
            g, w = g & 0xFFFF00FF, w & 0xFFFF00FF
        if i == ALPHA_WORD and srgb:
            g, w = g & ~(KHR_DF_SAMPLE_DATATYPE_LINEAR << 24), w & ~(KHR_DF_SAMPLE_DATATYPE_LINEAR << 24)
        if g != w:
            return i, g, w
    return None
