"""Texture artifacts: mip chains filtered by what a texture holds, their KTX2 bytes and descriptors.

The KTX2 files are read back with tests/io/test_ktx2.py's independent reader (struct only, from the
specification), not with the writer's own decoder.
"""
from __future__ import annotations

import hashlib

import numpy as np
import pytest

from generator.assemble.textures import (TextureArtifact, colour_note, generated_artifact, mip_chain, srgb_tables,
                                         texture_artifact)
from generator.io import ktx2
from generator.io.images import DecodedImage, decode_image, generated_image, located
from tests.io.test_ktx2 import _read_independently


def _image(texels: np.ndarray, source: str = "t.png", srgb=None) -> DecodedImage:
    return DecodedImage(texels, source, "PNG", 4, 8, srgb)


def _checker(size: int = 8) -> np.ndarray:
    """Black and white texels alternating, opaque."""
    i, j = np.indices((size, size))
    out = np.zeros((size, size, 4), np.uint8)
    out[..., :3] = np.where((i + j) % 2 == 0, 255, 0)[..., None]
    out[..., 3] = 255
    return out


def _t(texels: np.ndarray) -> np.ndarray:
    return texels[..., :3].astype(np.float64) * (2.0 / 255.0) - 1.0


def _length(t: np.ndarray) -> np.ndarray:
    return np.sqrt((t * t).sum(axis=-1))


def _bumps(size: int = 16) -> np.ndarray:
    """Unit normals tilting every texel in another direction, stored as (t + 1) / 2."""
    v, u = np.meshgrid((np.arange(size) + 0.5) / size, (np.arange(size) + 0.5) / size, indexing="ij")
    t = np.stack([0.7 * np.sin(2 * np.pi * 5 * u), 0.7 * np.cos(2 * np.pi * 3 * v), np.ones_like(u)], -1)
    t /= np.sqrt((t * t).sum(-1, keepdims=True))
    out = np.full((size, size, 4), 255, np.uint8)
    out[..., :3] = np.floor((t + 1.0) * 127.5 + 0.5)
    return out


# ------------------------------------------------------------------ the chain


def test_srgb_checker_averages_in_linear_light():
    """Black/white averages to linear 0.5: sRGB 188, not the 128 of averaging the codes."""
    levels = mip_chain(_checker(), "color", "srgb")
    assert [lv.shape for lv in levels] == [(8, 8, 4), (4, 4, 4), (2, 2, 4), (1, 1, 4)]
    for lv in levels[1:]:
        assert (lv[..., :3] == 188).all() and (lv[..., 3] == 255).all()
    assert abs(srgb_tables()[0][188] - 0.5) < 0.003
    assert (mip_chain(_checker(), "data")[1][..., :3] == 128).all()  # linear data: the plain average
    assert (mip_chain(_checker(), "color", "linear")[1][..., :3] == 128).all()


def test_srgb_round_trip_is_exact():
    """Every code decodes and encodes back to itself: a flat image keeps its value down the chain."""
    codes = np.arange(256, dtype=np.uint8)
    flat = np.stack([codes, codes, codes, codes], -1).reshape(16, 16, 4)
    uniform = np.repeat(np.repeat(flat, 2, 0), 2, 1)  # each code on a 2 × 2 block
    assert np.array_equal(mip_chain(uniform, "color", "srgb")[1], flat)


def test_odd_sizes_floor_and_cover_every_texel():
    """5 × 3 → 2 × 1 → 1 × 1; each texel averages the area it covers: (1, 1, ½) and (½, 1, 1) over 2.5 texels."""
    row = np.array([0, 10, 20, 30, 40], np.uint8)
    texels = np.zeros((3, 5, 4), np.uint8)
    texels[...] = row[None, :, None]
    levels = mip_chain(texels, "data")
    assert [lv.shape[:2] for lv in levels] == [(3, 5), (1, 2), (1, 1)]
    assert levels[1][0, :, 0].tolist() == [8, 32]      # (0 + 10 + 5) / 2.5, (5 + 30 + 40) / 2.5
    assert levels[2][0, 0, 0] == 20                    # the mean of all five: no column dropped or doubled
    column = mip_chain(np.arange(3 * 4, dtype=np.uint8).reshape(3, 1, 4) * 20, "data")
    assert [lv.shape[:2] for lv in column] == [(3, 1), (1, 1)] and column[1][0, 0].tolist() == [80, 100, 120, 140]


@pytest.mark.parametrize("height, width", [(37, 23), (1, 9), (6, 7), (64, 2)])
def test_a_chain_keeps_the_mean(height, width):
    """The exact box filter partitions the image: every level has the mean of level 0 (float data, no rounding)."""
    texels = np.random.default_rng(height * width).random((height, width, 4)).astype(np.float32)
    levels = mip_chain(texels, "data")
    assert len(levels) == max(height, width).bit_length()
    for lv in levels:
        assert lv.dtype == np.float32
        assert np.allclose(lv.astype(np.float64).mean(axis=(0, 1)), texels.astype(np.float64).mean(axis=(0, 1)),
                           atol=1e-5)
    assert np.allclose(levels[-1][0, 0], texels.astype(np.float64).mean(axis=(0, 1)), atol=1e-5)


def test_normal_maps_are_renormalized():
    levels = mip_chain(_bumps(), "normal")
    for lv in levels[1:]:
        assert np.abs(_length(_t(lv)) - 1.0).max() < 0.01  # unit, to 8-bit rounding
        assert (lv[..., 3] == 255).all()
    # a plain average of the same texels is shorter: the renormalization is what makes them unit
    plain = mip_chain(_bumps(), "data")[2]
    assert _length(_t(plain)).min() < 0.95


def test_keep_length_keeps_the_filtered_length_toksvig_reads():
    """Toksvig's packings read |N_a| = length(sample * 2 - 1): kept, it is the length of the averaged unit normals."""
    base = _bumps()
    kept = mip_chain(base, "normal", keep_length=True)
    t = _t(base)
    t /= _length(t)[..., None]
    want = t.reshape(8, 2, 8, 2, 3).mean(axis=(1, 3))  # 2 × 2 averages of the normalized base normals
    assert np.abs(_t(kept[1]) - want).max() <= 1.0 / 255.0 + 1e-9
    lengths = [_length(_t(lv)).mean() for lv in kept]
    assert lengths[1] < 0.99 and all(a >= b - 0.01 for a, b in zip(lengths[1:], lengths[2:]))  # shorter down the chain
    cancel = np.array([[[255, 128, 128, 255], [0, 127, 127, 255]]], np.uint8)  # t and −t exactly (v, 255 − v)
    assert _length(_t(mip_chain(cancel, "normal", keep_length=True)[1]))[0, 0] < 0.01
    assert mip_chain(cancel, "normal")[1][0, 0, :3].tolist() == [128, 128, 255]  # cancelled: renormalized to +z


def test_normal_xy_reconstructs_z_and_keeps_blue_and_alpha_as_data():
    base = _bumps()
    xy = base.copy()
    xy[..., 2], xy[..., 3] = 200, np.arange(16, dtype=np.uint8)[None, :] * 16  # B, A: data (power, gloss)
    levels = mip_chain(xy, "normal_xy")
    full = mip_chain(base, "normal")
    for a, b in zip(levels[1:], full[1:]):
        assert np.abs(a[..., :2].astype(int) - b[..., :2]).max() <= 1  # the same normals' xy
        assert (a[..., 2] == 200).all()
    assert levels[1][0, :, 3].tolist() == [8 + 32 * i for i in range(8)]  # alpha: the plain average


def test_level_zero_is_the_image_and_the_bytes_are_deterministic():
    texels = np.random.default_rng(7).integers(0, 256, (13, 11, 4), dtype=np.uint8)
    for holds, space in [("color", "srgb"), ("data", "linear"), ("normal", "linear"), ("normal_xy", "linear")]:
        first = mip_chain(texels, holds, space)
        assert first[0].tobytes() == texels.tobytes()
        again = mip_chain(texels.copy(), holds, space)
        assert [a.tobytes() for a in again] == [a.tobytes() for a in first]
    data = ktx2.encode_levels(mip_chain(texels, "color", "srgb"), "srgb8")
    assert hashlib.sha256(data).hexdigest()[:16] == PINNED_SRGB_13X11  # the same bytes on every platform


PINNED_SRGB_13X11 = "b591582e765d4e45"


@pytest.mark.parametrize("kwargs, message", [
    (dict(holds="normal", colour_space="srgb"), "normal texels are linear"),
    (dict(holds="colour"), "not 'colour'"),
    (dict(holds="color", colour_space="rec709"), "not 'rec709'"),
    (dict(holds="data", keep_length=True), "keep_length is for normal maps"),
])
def test_mip_chain_refuses(kwargs, message):
    with pytest.raises(ValueError, match=message):
        mip_chain(_checker(), **kwargs)


# ------------------------------------------------------------------ artifacts


def test_artifact_is_ktx2_the_independent_reader_reads(tmp_path):
    texels = np.random.default_rng(2).integers(0, 256, (6, 10, 4), dtype=np.uint8)
    art = texture_artifact(_image(texels), "color", "srgb", "textures/wood.png")
    assert isinstance(art, TextureArtifact)
    d = art.descriptor
    assert d == {**d, "format": "R8G8B8A8_SRGB", "width": 10, "height": 6, "levels": 4, "colour_space": "srgb",
                 "holds": "color", "sha256": hashlib.sha256(art.data).hexdigest(), "source": "textures/wood.png",
                 "generated": False, "bytes": len(art.data)}
    assert art.sha256 == d["sha256"] and d["path"] == f"textures/10x6.srgb8.{d['sha256'][:12]}.ktx2"
    f = _read_independently(art.data)
    assert (f["vkFormat"], f["levelCount"], f["pixelWidth"], f["pixelHeight"]) == (43, 4, 10, 6)
    assert f["dfd"]["transfer"] == 2 and f["dfd"]["samples"][3]["qualifiers"] == 0x10
    for (offset, length, _), level in zip(f["levels"], mip_chain(texels, "color", "srgb")):
        assert art.data[offset:offset + length] == level.tobytes()
    assert art.write(tmp_path) is True and art.write(tmp_path) is False
    assert (tmp_path / art.path).read_bytes() == art.data


def test_artifacts_choose_their_format():
    texels = _bumps(4)
    normal = texture_artifact(_image(texels), "normal", "linear", "/images/1").descriptor
    assert (normal["format"], normal["colour_space"], normal["source"]) == ("R8G8B8A8_UNORM", "linear", "/images/1")
    floats = DecodedImage(np.full((2, 2, 4), 0.25, np.float16), "hdr.ktx2", "KTX2", 4, 16, False)
    hdr = texture_artifact(floats, "color", "srgb", "hdr.ktx2").descriptor  # float texels are linear light
    assert (hdr["format"], hdr["colour_space"], hdr["levels"]) == ("R16G16B16A16_SFLOAT", "linear", 2)


def test_same_image_same_artifact_and_a_changed_one_another():
    texels = _checker(4)
    a = texture_artifact(_image(texels, "a.png"), "color", "srgb", "a.png")
    b = texture_artifact(_image(texels.copy(), "b.png"), "color", "srgb", "b.png")
    assert a.data == b.data and a.path == b.path  # content-addressed: the source name is not in the bytes
    texels[0, 0, 0] = 7
    assert texture_artifact(_image(texels), "color", "srgb", "a.png").path != a.path


def test_generated_artifacts_are_marked():
    albedo = generated_artifact("albedo_map", "color").descriptor
    assert (albedo["source"], albedo["generated"], albedo["format"], albedo["levels"]) == (
        "generated", True, "R8G8B8A8_SRGB", 5)
    normal = generated_artifact("normal_map", "normal", keep_length=True)
    assert normal.descriptor["mip_filter"] == "box, normals averaged, length kept"
    f = _read_independently(normal.data)
    offset, length, _ = f["levels"][0]
    assert normal.data[offset:offset + length] == generated_image("normal_map").texels.tobytes()
    grey = generated_artifact("f0_map", "color").descriptor
    assert (grey["format"], grey["colour_space"], grey["width"]) == ("R16G16B16A16_SFLOAT", "linear", 1)


def test_colour_note_when_the_file_disagrees_with_the_packing():
    png = decode_image(_srgb_png(), located("s.toml", 1, 1), "albedo.png")
    assert colour_note(png, "srgb") is None
    note = colour_note(png, "linear")
    assert note and "declares sRGB (sRGB chunk)" in note and "as linear" in note
    assert colour_note(_image(_checker()), "linear") is None  # the file says nothing


def _srgb_png() -> bytes:
    import io
    import struct
    import zlib

    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add(b"sRGB", b"\0")
    out = io.BytesIO()
    Image.fromarray(_checker(2)).save(out, "PNG", pnginfo=info)
    data = out.getvalue()
    assert struct.pack(">I", zlib.crc32(b"sRGB\0")) in data
    return data
