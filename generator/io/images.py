"""Images a scene names, decoded to RGBA texels: PNG and JPEG through Pillow, uncompressed KTX2 through io/ktx2.py.

Where an image comes from: a file (`read_image`; a TOML scene's path, a glTF image's relative URI), bytes
(`decode_image`; a glTF buffer view), a ``data:`` URI (`decode_data_uri`), or a glTF image URI of either
kind (`read_uri`). Whatever fails — a missing or unreadable file, bytes that are no image, a truncated or
corrupt PNG (every chunk's CRC is checked and IEND must close the file: Pillow alone decodes a PNG cut
short), a size past MAX_SIDE or MAX_PIXELS, CMYK JPEG, Basis-compressed KTX2 — is raised through the
caller's `fail(message, hint)`, so that the error carries the caller's location (the TOML line of the
`textures` entry, the glTF JSON pointer of the image) and names the image: `located` makes such a `fail`
for a file, line and column; a glTF reader passes its own (its GltfError at a pointer).

Only Pillow's PNG and JPEG plugins ever see the bytes (``formats=``): no other of Pillow's decoders
runs, and none that calls out to a program (EPS runs Ghostscript).

What is returned (`DecodedImage`): texels (H, W, 4) uint8 RGBA — grey replicated into R, G, B (PNG's and
glTF's meaning of a grey image, not Vulkan's R-only expansion), alpha 255 where the file has none,
palette and tRNS transparency applied — or, for a float KTX2, (H, W, 4) float16/float32; and what the file
says: its container, the channels and bits per channel it stores, and whether it declares sRGB (PNG cICP,
iCCP, sRGB or gAMA chunks in the precedence PNG gives them, a JPEG's ICC profile or EXIF ColorSpace, a
KTX2's vkFormat). The declaration is recorded, never obeyed: a packing's texture declaration decides the
colour space (assemble/textures.py). 16-bit PNG channels are reduced to their high byte (the value Pillow
gives 16-bit RGB: at most 1/255 from the rounded one): the textures are 8-bit. EXIF orientation is not
applied (engines upload the stored rows).

`generated_image` gives the images the renderer draws where a packing texture has no image named.
"""
from __future__ import annotations

import base64
import io
import struct
import urllib.parse
import warnings
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..lang.errors import SourceError, read_bytes

MAX_SIDE = 16384           # Vulkan's maxImageDimension2D on current desktop GPUs (4096 is the guaranteed minimum)
MAX_PIXELS = 1 << 26       # 8192²: below Pillow's own bomb warning (89.5 M pixels), ~2 GiB of float64 RGBA to filter
MAX_IMAGE_BYTES = 256 << 20
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
JPEG_SIGNATURE = b"\xff\xd8\xff"
MIME = {"image/png": "PNG", "image/jpeg": "JPEG", "image/ktx2": "KTX2"}

Fail = Callable[[str, str], Exception]  # (message, hint) -> the caller's located error, raised by the callee


def located(path, line: int = 1, col: int = 1) -> Fail:
    """A `fail` raising SourceError at path:line:col (the scene line that names the image)."""
    return lambda message, hint="": SourceError(str(path), line, col, message, hint)


@dataclass(frozen=True)
class DecodedImage:
    """An image's texels and what its file says about them."""

    texels: np.ndarray          # (H, W, 4): uint8 RGBA, or float16 / float32 for a float KTX2
    source: str                 # the image as messages name it: a path, a URI, "buffer view 3", "generated"
    container: str              # "PNG" | "JPEG" | "KTX2" | "generated"
    channels: int               # channels the file stores: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
    bit_depth: int              # bits per channel the file stores (16-bit PNG: reduced to 8 in texels)
    declared_srgb: bool | None  # what the file declares: sRGB, linear, or nothing (None)
    declaration: str = ""       # what declares it: "sRGB chunk", "gAMA 1.0", "ICC profile 'Display P3'", …

    @property
    def width(self) -> int:
        return int(self.texels.shape[1])

    @property
    def height(self) -> int:
        return int(self.texels.shape[0])


def read_image(path, fail: Fail, shown: str | None = None) -> DecodedImage:
    """The image in file `path`, named `shown` (default: the path) in errors raised through `fail`."""
    shown = str(path) if shown is None else shown
    try:
        data = read_bytes(path, "image file", MAX_IMAGE_BYTES)
    except SourceError as e:
        hint = e.hint if e.hint != "check the path" else "check the path (a relative one starts at the scene's folder)"
        raise fail(f"image '{shown}': {e.message}", hint) from None
    return decode_image(data, fail, shown)


def read_uri(uri: str, base: Path, fail: Fail) -> DecodedImage:
    """A glTF image's `uri`: a data: URI, or a percent-encoded path relative to the glTF file's folder `base`."""
    if uri.startswith("data:"):
        return decode_data_uri(uri, fail)
    scheme = urllib.parse.urlsplit(uri).scheme
    if len(scheme) > 1:  # a one-letter "scheme" is a Windows drive letter
        raise fail(f"image '{uri}': a {scheme}: URI is not a file beside the glTF",
                   "download the image and refer to it by a relative path")
    rel = urllib.parse.unquote(uri)
    path = Path(base) / rel
    # a glTF names files beside it: an absolute path or one that leads out of its folder is refused (untrusted
    # input must not make the build read, and ship, any file of the machine it runs on)
    if Path(rel).is_absolute() or len(scheme) == 1 or not path.resolve().is_relative_to(Path(base).resolve()):
        raise fail(f"image '{uri}': the path leads out of the glTF's folder",
                   "copy the image beside the glTF (or below its folder) and refer to it by a relative path")
    return read_image(path, fail, shown=uri)


def decode_data_uri(uri: str, fail: Fail, shown: str | None = None) -> DecodedImage:
    """The image of a base64 ``data:image/png``, ``image/jpeg`` or ``image/ktx2`` URI."""
    shown = shown or (uri[:40] + "…" if len(uri) > 40 else uri)
    head, comma, payload = uri.partition(",")
    params = head[len("data:"):].split(";")
    mime = params[0].strip().lower()
    if not comma or "base64" not in [p.strip().lower() for p in params[1:]]:
        raise fail(f"image '{shown}': a data URI without ';base64,'",
                   "embed the image as data:image/png;base64,… (glTF data URIs are base64)")
    if mime not in MIME:
        raise fail(f"image '{shown}': a data URI of media type '{mime}', not image/png, image/jpeg or image/ktx2",
                   "embed a PNG or JPEG image")
    if len(payload) > MAX_IMAGE_BYTES * 4 // 3 + 4:
        raise fail(f"image '{shown}': the data URI holds more than {MAX_IMAGE_BYTES} bytes",
                   "refer to the image as a file instead")
    try:
        data = base64.b64decode("".join(payload.split()), validate=True)
    except ValueError as e:
        raise fail(f"image '{shown}': the data URI's base64 does not decode ({e})", "re-export the glTF") from None
    return decode_image(data, fail, shown, mime=mime)


def decode_image(data: bytes, fail: Fail, shown: str, mime: str | None = None) -> DecodedImage:
    """The image of PNG, JPEG or KTX2 bytes (told apart by their signature; `mime`, when given, must agree)."""
    from . import ktx2

    data = bytes(data)
    kind = ("PNG" if data.startswith(PNG_SIGNATURE) else "JPEG" if data.startswith(JPEG_SIGNATURE) else
            "KTX2" if data.startswith(ktx2.IDENTIFIER) else None)
    if kind is None:
        what = "empty" if not data else "not a PNG, JPEG or KTX2 image (its first bytes are " + data[:8].hex(" ") + ")"
        raise fail(f"image '{shown}': {what}", "give a PNG, JPEG or uncompressed KTX2 image")
    if mime is not None and MIME.get(mime.lower(), kind) != kind:
        raise fail(f"image '{shown}': the data is {kind} but its mimeType says {mime}",
                   f"set mimeType to image/{kind.lower()}")
    if kind == "KTX2":
        return _decode_ktx2(data, fail, shown)
    return _decode_pillow(data, kind, fail, shown)


def _bound(width: int, height: int, fail: Fail, shown: str) -> None:
    if width > MAX_SIDE or height > MAX_SIDE or width * height > MAX_PIXELS:
        raise fail(f"image '{shown}': {width} × {height} texels, more than the {MAX_SIDE} per side and "
                   f"{MAX_PIXELS} texels ({int(MAX_PIXELS ** 0.5)}²) a texture may have",
                   "scale the image down")


def _decode_ktx2(data: bytes, fail: Fail, shown: str) -> DecodedImage:
    """Level 0 of an uncompressed KTX2 2D image (its own mips are made again, filtered as its use says)."""
    from . import ktx2

    try:
        levels, fmt, cube = ktx2.decode_levels(data, shown)
    except ktx2.Ktx2Error as e:
        raise fail(f"image '{shown}': {e.what}", e.hint) from None
    if cube:
        raise fail(f"image '{shown}': a cube map, not a 2D image", "give a 2D KTX2 image")
    texels = levels[0]
    _bound(texels.shape[1], texels.shape[0], fail, shown)
    if texels.dtype.kind == "f" and not np.isfinite(texels).all():
        raise fail(f"image '{shown}': {np.count_nonzero(~np.isfinite(texels))} texel components are NaN or "
                   "infinite", "fix the image where it is made")
    srgb = fmt == "srgb8"
    return DecodedImage(texels, shown, "KTX2", 4, texels.dtype.itemsize * 8, srgb, f"KTX2 {ktx2.VK_NAMES[fmt]}")


@dataclass(frozen=True)
class _PngHeader:
    width: int
    height: int
    bit_depth: int
    colour_type: int
    chunks: dict  # chunk type -> data of its first occurrence (the colour chunks are read from it)


_PNG_CHANNELS = {0: 1, 2: 3, 3: 3, 4: 2, 6: 4}  # PNG colour type -> channels stored


def _png_chunks(data: bytes, fail: Fail, shown: str) -> _PngHeader:
    """Every chunk of a PNG walked with its CRC checked, IHDR first and IEND last (PNG §5.3, §11.2)."""
    pos, chunks, order = len(PNG_SIGNATURE), {}, []
    while True:
        if pos + 8 > len(data):
            raise fail(f"image '{shown}': the PNG is truncated at byte {len(data)} (no IEND chunk)",
                       "re-export the image; the file was cut short")
        length, ctype = struct.unpack_from(">I4s", data, pos)
        end = pos + 12 + length
        if end > len(data):
            raise fail(f"image '{shown}': the PNG is truncated: chunk {ctype!r} at byte {pos} needs {length} "
                       f"bytes, the file ends at {len(data)}", "re-export the image; the file was cut short")
        (crc,) = struct.unpack_from(">I", data, end - 4)
        if zlib.crc32(data[pos + 4:end - 4]) != crc:
            raise fail(f"image '{shown}': the PNG is corrupt: chunk {ctype!r} at byte {pos} fails its CRC",
                       "re-export the image")
        chunks.setdefault(ctype, data[pos + 8:end - 4])
        order.append(ctype)
        pos = end
        if ctype == b"IEND":
            break
    if order[0] != b"IHDR" or len(chunks[b"IHDR"]) != 13 or b"IDAT" not in chunks:
        raise fail(f"image '{shown}': the PNG has no IHDR chunk first or no IDAT chunk", "re-export the image")
    width, height, depth, ctype = struct.unpack_from(">IIBB", chunks[b"IHDR"])
    if ctype not in _PNG_CHANNELS:
        raise fail(f"image '{shown}': PNG colour type {ctype} does not exist", "re-export the image")
    return _PngHeader(width, height, depth, ctype, chunks)


def _decode_pillow(data: bytes, kind: str, fail: Fail, shown: str) -> DecodedImage:
    from PIL import Image, UnidentifiedImageError

    png = _png_chunks(data, fail, shown) if kind == "PNG" else None
    if png is not None:
        _bound(png.width, png.height, fail, shown)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            im = Image.open(io.BytesIO(data), formats=[kind])
            _bound(im.width, im.height, fail, shown)
            im.load()
    except (Image.DecompressionBombError, Image.DecompressionBombWarning):
        raise fail(f"image '{shown}': more texels than {MAX_PIXELS}", "scale the image down") from None
    except UnidentifiedImageError:
        raise fail(f"image '{shown}': Pillow does not read it as {kind}", "re-export the image") from None
    except (OSError, SyntaxError, ValueError, EOFError, struct.error, zlib.error) as e:
        raise fail(f"image '{shown}': the {kind} data is truncated or corrupt ({e})", "re-export the image") from None
    if im.mode == "CMYK":
        raise fail(f"image '{shown}': a CMYK JPEG", "save it as an RGB (or greyscale) JPEG or PNG")
    texels = _rgba(im)
    if png is not None:
        channels = _PNG_CHANNELS[png.colour_type] + (1 if b"tRNS" in png.chunks else 0)
        srgb, declaration = _png_declaration(png.chunks, im.info.get("icc_profile"))
        return DecodedImage(texels, shown, kind, channels, png.bit_depth, srgb, declaration)
    srgb, declaration = _jpeg_declaration(im)
    return DecodedImage(texels, shown, kind, len(im.getbands()), 8, srgb, declaration)


def _rgba(im) -> np.ndarray:
    """(H, W, 4) uint8 RGBA of a loaded Pillow image; 16-bit grey reduced to its high byte as Pillow does RGB."""
    if im.mode in ("I;16", "I;16B", "I;16L", "I"):
        grey = (np.asarray(im, dtype=np.uint32) >> 8).astype(np.uint8)
        alpha = np.full(grey.shape, 255, np.uint8)
        key = im.info.get("transparency")
        if isinstance(key, int):  # PNG tRNS of a grey image: the one transparent grey level
            alpha[np.asarray(im, dtype=np.uint32) == key] = 0
        return np.ascontiguousarray(np.stack([grey, grey, grey, alpha], axis=-1))
    return np.ascontiguousarray(np.asarray(im.convert("RGBA"), dtype=np.uint8))


def _png_declaration(chunks: dict, icc: bytes | None) -> tuple[bool | None, str]:
    """What a PNG's colour chunks declare, in PNG's precedence: cICP, iCCP, sRGB, gAMA (PNG 3rd ed. §4.3)."""
    cicp = chunks.get(b"cICP")
    if cicp and len(cicp) == 4:  # ITU-T H.273 transfer characteristics: 13 sRGB, 8 linear
        return {13: True, 8: False}.get(cicp[1]), f"cICP transfer {cicp[1]}"
    if b"iCCP" in chunks:
        return _icc_declaration(icc)
    if b"sRGB" in chunks:
        return True, "sRGB chunk"
    gama = chunks.get(b"gAMA")
    if gama and len(gama) == 4:
        (g,) = struct.unpack(">I", gama)
        # 45455 is 1/2.2 × 100000, the gamma PNG writers put beside (or for) sRGB; 100000 is linear
        srgb = True if abs(g - 45455) <= 500 else False if g == 100000 else None
        return srgb, f"gAMA {g / 100000:g}"
    return None, ""


def _jpeg_declaration(im) -> tuple[bool | None, str]:
    """A JPEG's ICC profile, else its EXIF ColorSpace (1: sRGB); JFIF itself says nothing."""
    if im.info.get("icc_profile"):
        return _icc_declaration(im.info["icc_profile"])
    try:
        space = im.getexif().get_ifd(0x8769).get(0xA001)  # Exif IFD, ColorSpace
    except (OSError, ValueError, KeyError, TypeError, struct.error):  # a broken EXIF block declares nothing
        space = None
    return (True, "EXIF ColorSpace sRGB") if space == 1 else (None, "")


def _icc_declaration(icc: bytes | None) -> tuple[bool | None, str]:
    """An ICC profile's description ('desc' tag, v2 text or v4 mluc), and whether it names sRGB."""
    desc = _icc_description(icc or b"")
    if desc is None:
        return None, "ICC profile"
    return ("srgb" in desc.lower().replace(" ", "") or None), f"ICC profile '{desc}'"


def _icc_description(icc: bytes) -> str | None:
    try:
        (count,) = struct.unpack_from(">I", icc, 128)
        for i in range(min(count, 256)):
            sig, offset, size = struct.unpack_from(">4sII", icc, 132 + 12 * i)
            if sig != b"desc":
                continue
            tag = icc[offset:offset + size]
            if tag[:4] == b"desc":  # ICC v2 textDescriptionType: count, ASCII with NUL
                (n,) = struct.unpack_from(">I", tag, 8)
                return tag[12:12 + n].split(b"\0")[0].decode("latin-1")
            if tag[:4] == b"mluc":  # ICC v4 multiLocalizedUnicodeType: the first record, UTF-16BE
                n_len, n_off = struct.unpack_from(">II", tag, 16 + 4)
                return tag[n_off:n_off + n_len].decode("utf-16-be", "replace")
    except (struct.error, UnicodeDecodeError):
        pass
    return None


# ------------------------------------------------------------------ generated images

def generated_image(name: str) -> DecodedImage:
    """The image the renderer draws for packing texture `name` where the scene names none: a 16 × 16 sRGB
    checker for ``albedo_map``, a 32 × 32 normal map of bumps for ``normal_map``, else a 1 × 1 linear grey 0.5 (half float)."""
    if name == "albedo_map":
        j, i = np.meshgrid(np.arange(16), np.arange(16))
        rgb = np.where(((i // 4 + j // 4) % 2 == 0)[..., None], [230, 200, 120], [90, 140, 200])
        texels, srgb = np.concatenate([rgb, np.full((16, 16, 1), 255)], axis=-1).astype(np.uint8), True
    elif name == "normal_map":
        v, u = np.meshgrid((np.arange(32) + 0.5) / 32, (np.arange(32) + 0.5) / 32, indexing="ij")
        t = np.stack([0.5 * np.sin(2 * np.pi * 4 * u), 0.5 * np.cos(2 * np.pi * 3 * v), np.ones_like(u)], -1)
        t /= np.linalg.norm(t, axis=-1, keepdims=True)
        rgb = np.round((t + 1.0) / 2.0 * 255.0)
        texels, srgb = np.concatenate([rgb, np.full((32, 32, 1), 255.0)], axis=-1).astype(np.uint8), False
    else:
        texels, srgb = np.full((1, 1, 4), 0.5, np.float16), False  # half: exact, and filterable on WebGPU (float32 needs float32-filterable)
    return DecodedImage(np.ascontiguousarray(texels), "generated", "generated", 4, texels.dtype.itemsize * 8, srgb,
                        "generated")
