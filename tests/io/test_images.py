"""Images decoded for textures: PNG and JPEG files Pillow writes here, data URIs, KTX2, and every way an image is bad.

Every failure is the caller's located error (a TOML line, a glTF JSON pointer) naming the image; the
files are real ones written by Pillow into tmp dirs, cut short and corrupted byte by byte.
"""
from __future__ import annotations

import base64
import io
import struct
import zlib

import numpy as np
import pytest
from PIL import Image, ImageCms

from generator.io import ktx2
from generator.io.images import (MAX_SIDE, DecodedImage, decode_data_uri, decode_image, generated_image, located,
                                 read_image, read_uri)
from generator.lang.errors import SourceError
from generator.scene.gltf import GltfError

AT = located("scene.toml", 12, 5)


def _rgba(h: int = 5, w: int = 7, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, size=(h, w, 4), dtype=np.uint8)


def _png(array: np.ndarray, mode: str | None = None, **save) -> bytes:
    out = io.BytesIO()
    (Image.fromarray(array, mode) if mode else Image.fromarray(array)).save(out, "PNG", **save)
    return out.getvalue()


def _jpeg(array: np.ndarray, mode: str | None = None, **save) -> bytes:
    out = io.BytesIO()
    (Image.fromarray(array, mode) if mode else Image.fromarray(array)).save(out, "JPEG", quality=95, **save)
    return out.getvalue()


def _chunk(ctype: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + ctype + data + struct.pack(">I", zlib.crc32(ctype + data))


def _raw_png(width: int, height: int, depth: int, colour_type: int, rows: bytes, extra: bytes = b"") -> bytes:
    """A PNG assembled chunk by chunk (for what Pillow does not write: 16-bit RGB, a huge IHDR)."""
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + extra + _chunk(b"IDAT", zlib.compress(rows))
            + _chunk(b"IEND", b""))


def _error(call) -> str:
    with pytest.raises(SourceError) as e:
        call()
    return str(e.value)


# ------------------------------------------------------------------ what decodes


def test_png_file_round_trips_rgba(tmp_path):
    texels = _rgba()
    (tmp_path / "a.png").write_bytes(_png(texels))
    image = read_image(tmp_path / "a.png", AT, shown="textures/a.png")
    assert isinstance(image, DecodedImage)
    assert image.texels.dtype == np.uint8 and image.texels.shape == (5, 7, 4)
    assert np.array_equal(image.texels, texels)
    assert (image.container, image.channels, image.bit_depth, image.source) == ("PNG", 4, 8, "textures/a.png")
    assert (image.width, image.height, image.declared_srgb) == (7, 5, None)


@pytest.mark.parametrize("mode, channels", [("L", 1), ("LA", 2), ("RGB", 3)])
def test_png_grey_and_rgb_become_rgba(mode, channels):
    texels = _rgba()
    source = {"L": texels[..., 0], "LA": texels[..., :2], "RGB": texels[..., :3]}[mode]
    image = decode_image(_png(source, mode), AT, "t.png")
    grey = texels[..., 0]
    want = {"L": np.stack([grey, grey, grey, np.full_like(grey, 255)], -1),
            "LA": np.stack([grey, grey, grey, texels[..., 1]], -1),  # grey replicated, not Vulkan's (R, 0, 0)
            "RGB": np.concatenate([texels[..., :3], np.full_like(grey[..., None], 255)], -1)}[mode]
    assert np.array_equal(image.texels, want) and image.channels == channels


def test_palette_png_with_transparency():
    p = Image.new("P", (3, 2))
    p.putpalette([255, 0, 0, 0, 255, 0] + [0] * 762)
    p.putdata([0, 1, 0, 1, 0, 1])
    out = io.BytesIO()
    p.save(out, "PNG", transparency=1)
    image = decode_image(out.getvalue(), AT, "p.png")
    assert image.texels[0, 0].tolist() == [255, 0, 0, 255] and image.texels[0, 1].tolist() == [0, 255, 0, 0]
    assert image.channels == 4  # three palette channels and tRNS


def test_sixteen_bit_pngs_keep_the_high_byte():
    grey = np.array([[0, 255, 256, 65535, 0x80FF]], np.uint16)
    image = decode_image(_png(grey), AT, "g16.png")  # Pillow writes uint16 as 16-bit grey
    assert image.bit_depth == 16 and image.texels[0, :, 0].tolist() == [0, 0, 1, 255, 128]
    rgb = np.array([[[65535, 0, 32768], [771, 65535, 1]]], ">u2")
    data = _raw_png(2, 1, 16, 2, b"\0" + rgb.tobytes())
    image = decode_image(data, AT, "rgb16.png")
    assert image.bit_depth == 16 and image.channels == 3
    assert image.texels[0].tolist() == [[255, 0, 128, 255], [3, 255, 0, 255]]


def test_jpeg_rgb_and_grey(tmp_path):
    flat = np.full((8, 8, 3), [200, 100, 50], np.uint8)
    (tmp_path / "a.jpg").write_bytes(_jpeg(flat))
    image = read_image(tmp_path / "a.jpg", AT)
    assert (image.container, image.channels, image.texels.shape) == ("JPEG", 3, (8, 8, 4))
    assert np.abs(image.texels[..., :3].astype(int) - flat).max() <= 3 and (image.texels[..., 3] == 255).all()
    grey = decode_image(_jpeg(np.full((4, 4), 90, np.uint8), "L"), AT, "g.jpg")
    assert grey.channels == 1 and np.abs(grey.texels[..., :3].astype(int) - 90).max() <= 2


def test_data_uris_and_relative_uris(tmp_path):
    texels = _rgba(2, 3)
    png = _png(texels)
    uri = "data:image/png;base64," + base64.b64encode(png).decode()
    assert np.array_equal(decode_data_uri(uri, AT).texels, texels)
    jpeg = _jpeg(np.full((4, 4, 3), 128, np.uint8))
    assert decode_data_uri("data:image/jpeg;base64," + base64.b64encode(jpeg).decode(), AT).container == "JPEG"
    (tmp_path / "my image.png").write_bytes(png)
    assert np.array_equal(read_uri("my%20image.png", tmp_path, AT).texels, texels)  # glTF URIs are percent-encoded
    assert read_uri(uri, tmp_path, AT).source.startswith("data:image/png;base64,")


@pytest.mark.parametrize("extra, srgb, declaration", [
    (b"", None, ""),
    (_chunk(b"sRGB", b"\0"), True, "sRGB chunk"),
    (_chunk(b"gAMA", struct.pack(">I", 45455)), True, "gAMA 0.45455"),
    (_chunk(b"gAMA", struct.pack(">I", 100000)), False, "gAMA 1"),
    (_chunk(b"gAMA", struct.pack(">I", 55555)), None, "gAMA 0.55555"),
    (_chunk(b"sRGB", b"\0") + _chunk(b"gAMA", struct.pack(">I", 100000)), True, "sRGB chunk"),  # sRGB first
    (_chunk(b"cICP", bytes([1, 8, 0, 1])), False, "cICP transfer 8"),
])
def test_png_colour_declarations_are_recorded(extra, srgb, declaration):
    image = decode_image(_raw_png(1, 1, 8, 2, b"\0\x10\x20\x30", extra), AT, "c.png")
    assert (image.declared_srgb, image.declaration) == (srgb, declaration)
    assert image.texels[0, 0].tolist() == [16, 32, 48, 255]  # recorded, never applied


def test_icc_profiles_are_described():
    srgb = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
    image = decode_image(_png(_rgba(2, 2), icc_profile=srgb), AT, "icc.png")
    assert image.declared_srgb is True and image.declaration.startswith("ICC profile '") and "sRGB" in image.declaration
    odd = _chunk(b"iCCP", b"odd\0\0" + zlib.compress(b"not a profile"))
    image = decode_image(_raw_png(1, 1, 8, 2, b"\0\x10\x20\x30", odd), AT, "odd.png")
    assert (image.declared_srgb, image.declaration) == (None, "ICC profile")
    jpeg = decode_image(_jpeg(np.zeros((4, 4, 3), np.uint8), icc_profile=srgb), AT, "icc.jpg")
    assert jpeg.declared_srgb is True


def test_ktx2_images():
    texels = _rgba(4, 8)
    srgb = decode_image(ktx2.encode(texels, "srgb8"), AT, "a.ktx2")
    assert (srgb.container, srgb.declared_srgb, srgb.declaration) == ("KTX2", True, "KTX2 R8G8B8A8_SRGB")
    assert np.array_equal(srgb.texels, texels)
    chain = ktx2.encode_levels([texels, texels[:2, :4], texels[:1, :2], texels[:1, :1]], "unorm8")
    image = decode_image(chain, AT, "b.ktx2")  # level 0: the mips are made again, filtered by what it holds
    assert np.array_equal(image.texels, texels) and image.declared_srgb is False
    floats = np.linspace(-2, 8, 4 * 8 * 4, dtype=np.float32).reshape(4, 8, 4)
    hdr = decode_image(ktx2.encode(floats.astype(np.float16), "fp16"), AT, "c.ktx2")
    assert hdr.texels.dtype == np.float16 and hdr.bit_depth == 16


def test_generated_images():
    albedo, normal, grey = generated_image("albedo_map"), generated_image("normal_map"), generated_image("f0_map")
    assert albedo.texels.shape == (16, 16, 4) and albedo.declared_srgb and albedo.texels[0, 0].tolist() == [230, 200, 120, 255]
    assert normal.texels.shape == (32, 32, 4) and normal.declared_srgb is False
    t = normal.texels[..., :3] / 255.0 * 2.0 - 1.0
    assert np.abs(np.sqrt((t * t).sum(-1)) - 1.0).max() < 0.01  # unit normals, to 8-bit rounding
    assert grey.texels.dtype == np.float16 and grey.texels.tolist() == [[[0.5] * 4]]
    assert {i.source for i in (albedo, normal, grey)} == {"generated"}


# ------------------------------------------------------------------ what is refused, located


def test_errors_carry_the_callers_location_and_the_image(tmp_path):
    text = _error(lambda: read_image(tmp_path / "missing.png", AT, shown="textures/missing.png"))
    assert text.startswith("scene.toml:12:5: image 'textures/missing.png': ") and " — " in text, text
    assert "No such file" in text and "scene's folder" in text
    gltf = lambda message, hint="": GltfError("model.gltf", "/images/2/uri", message, hint)  # noqa: E731
    text = _error(lambda: read_uri("missing.png", tmp_path, gltf))
    assert text.startswith("model.gltf: /images/2/uri: image 'missing.png': "), text


@pytest.mark.parametrize("data, message", [
    (b"", "image 'x': empty"),
    (b"hello, world", "not a PNG, JPEG or KTX2 image (its first bytes are 68 65 6c"),
    (b"%!PS-Adobe-3.0 EPSF-3.0\n", "not a PNG, JPEG or KTX2 image"),  # never handed to Pillow's EPS (Ghostscript)
    (b"GIF89a" + bytes(20), "not a PNG, JPEG or KTX2 image"),
    (_raw_png(MAX_SIDE + 1, 1, 8, 0, b"\0\0"), "16385 × 1 texels, more than the 16384 per side"),
    (_raw_png(8192, 8193, 8, 0, b"\0"), "more than the 16384 per side and 67108864 texels (8192²)"),
    (_raw_png(1, 1, 8, 5, b"\0\0"), "PNG colour type 5 does not exist"),
    (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 0, 0, 0, 0)) + _chunk(b"IEND", b""),
     "no IDAT chunk"),
    (_raw_png(2, 1, 8, 0, b"\0\x01"), "truncated or corrupt"),  # IDAT one row byte short
    (_jpeg(np.zeros((4, 4, 4), np.uint8), "CMYK"), "a CMYK JPEG"),
    (ktx2.encode(np.zeros((6, 2, 2, 4), np.uint8), "unorm8", cube=True), "a cube map, not a 2D image"),
    (struct.pack("<12s9I", ktx2.IDENTIFIER, 0, 1, 4, 4, 0, 0, 1, 1, 1) + bytes(200), "supercompressionScheme is 1"),
    (ktx2.encode(np.zeros((2, 2, 4), np.float32), "fp32")[:-4] + np.float32(np.inf).tobytes(), "1 texel components are NaN"),
], ids=lambda v: v if isinstance(v, str) else "data")
def test_bad_bytes_are_located_errors(data, message):
    """Each refusal says what is wrong with the image and what to do, at the caller's line."""
    text = _error(lambda: decode_image(data, AT, "x"))
    assert text.startswith("scene.toml:12:5: image 'x': ") and message in text and " — " in text, text


def test_basis_ktx2_is_refused_by_name():
    data = bytearray(ktx2.encode(np.zeros((4, 4, 4), np.uint8), "unorm8"))
    struct.pack_into("<2I", data, 12, 0, 1)              # vkFormat 0 (UNDEFINED), typeSize 1
    struct.pack_into("<I", data, 104 + 12, 166 | 1 << 8)  # colorModel UASTC
    text = _error(lambda: decode_image(bytes(data), AT, "t.ktx2"))
    assert "a Basis Universal UASTC file" in text and "uncompressed KTX2" in text, text


@pytest.mark.parametrize("uri, message", [
    ("data:image/png,abcd", "without ';base64,'"),
    ("data:image/gif;base64,R0lGODlh", "media type 'image/gif'"),
    ("data:image/png;base64,@@@@", "base64 does not decode"),
    ("data:image/jpeg;base64," + base64.b64encode(_png(np.zeros((1, 1, 4), np.uint8))).decode(),
     "the data is PNG but its mimeType says image/jpeg"),
])
def test_bad_data_uris(uri, message):
    assert message in _error(lambda: decode_data_uri(uri, AT, "/images/0"))


def test_remote_uris_are_refused(tmp_path):
    assert "a https: URI is not a file beside the glTF" in _error(
        lambda: read_uri("https://example.com/a.png", tmp_path, AT))


def test_files_that_are_not_regular_files(tmp_path):
    assert "not a regular file" in _error(lambda: read_image(tmp_path, AT, shown="textures/"))


def test_every_cut_and_flipped_byte_of_a_png_is_a_located_error():
    """A PNG cut anywhere (Pillow alone decodes one without its IEND) or with any byte flipped: an error."""
    data = _png(_rgba(3, 4))
    for n in range(len(data)):
        with pytest.raises(SourceError):
            decode_image(data[:n], AT, "cut.png")
    for i in range(len(data)):
        corrupt = bytearray(data)
        corrupt[i] ^= 0x40
        with pytest.raises(SourceError):
            decode_image(bytes(corrupt), AT, "flip.png")


def test_every_cut_of_a_jpeg_is_a_located_error():
    data = _jpeg(np.random.default_rng(3).integers(0, 256, (16, 16, 3), dtype=np.uint8))
    for n in range(0, len(data), 3):
        with pytest.raises(SourceError):
            decode_image(data[:n], AT, "cut.jpg")
