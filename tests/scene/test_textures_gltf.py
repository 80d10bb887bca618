"""glTF images and samplers as texture bindings (generator/scene/gltf_images.py): images by relative,
percent-encoded URI, by buffer view with its mimeType and by data URI (PNG, JPEG, plain KTX2), glTF samplers
mapped (REPEAT, MIRRORED_REPEAT, CLAMP_TO_EDGE, the mipmap filters), glTF's white for a texture the material
leaves out, and every bad image or sampler one error at the glTF object's line, column and JSON pointer."""
from __future__ import annotations

import base64
import io
import json
import struct

import numpy as np
import pytest
from PIL import Image

from generator.io import ktx2
from generator.lang import SourceError
from generator.scene.load import load_scene
from generator.scene.textures import DEFAULT_SAMPLER, Sampler
from tests.scene.test_gltf import Doc, png_bytes, png_data_uri


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def jpeg_bytes() -> bytes:
    out = io.BytesIO()
    Image.fromarray(np.full((4, 4, 3), 120, np.uint8)).save(out, "JPEG", quality=95)
    return out.getvalue()


def textured_doc(tmp_path) -> Doc:
    """Three materials: a floor whose base colour is a file beside the .gltf (a space in its name, percent-encoded)
    read with REPEAT × MIRRORED_REPEAT, a metal whose base colour lives in a buffer view (PNG) and whose normal
    map is a JPEG data URI, and a decal of the floor's image clamped, without mipmaps."""
    g = Doc()
    (tmp_path / "floor tiles.png").write_bytes(png_bytes())
    g.d["images"] = [{"uri": "floor%20tiles.png"}, {"uri": "data:image/jpeg;base64," + base64.b64encode(jpeg_bytes()).decode()}]
    data = png_bytes(texels=((1, 2, 3, 255),) * 4)
    while len(g.bin) % 4:
        g.bin.append(0)
    g.d["bufferViews"].append({"buffer": 0, "byteOffset": len(g.bin), "byteLength": len(data)})
    g.bin += data
    g.d["images"].append({"bufferView": len(g.d["bufferViews"]) - 1, "mimeType": "image/png"})
    g.d["samplers"] = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33648},
                       {"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071},
                       {"minFilter": 9986}]
    g.d["textures"] = [{"source": 0, "sampler": 0}, {"source": 1}, {"source": 2, "sampler": 2},
                       {"source": 0, "sampler": 1}]
    floor = g.material(name="floor", pbrMetallicRoughness={"baseColorTexture": {"index": 0}, "metallicFactor": 0.0})
    metal = g.material(name="metal", normalTexture={"index": 1},
                       pbrMetallicRoughness={"baseColorTexture": {"index": 2}, "metallicFactor": 1.0})
    decal = g.material(name="decal", pbrMetallicRoughness={"baseColorTexture": {"index": 3}, "metallicFactor": 0.0})
    g.node(name="floor", mesh=g.quad_mesh("floor_mesh", floor))
    g.node(name="statue", mesh=g.quad_mesh("statue_mesh", metal))
    g.node(name="decal", mesh=g.quad_mesh("decal_mesh", decal))
    return g


def test_images_by_uri_buffer_view_and_data_uri_with_their_samplers(tmp_path, lib):
    path = textured_doc(tmp_path).write_gltf(tmp_path / "model.gltf")
    scene = load_scene(path, lib)
    floor = scene.materials["floor"].images["albedo_map"]
    assert (floor.source, floor.holds, floor.colour_space) == ("/images/0", "color", "srgb")
    assert floor.file == tmp_path / "floor tiles.png" and floor.image.texels.shape == (2, 2, 4)
    assert floor.sampler == Sampler("linear", "linear", "linear", "repeat", "mirrored")
    metal = scene.materials["metal"].images
    assert set(metal) == {"base_color_map", "orm_map", "normal_map"}
    assert metal["base_color_map"].source == "/images/2" and metal["base_color_map"].file is None
    assert metal["base_color_map"].image.texels[0, 0].tolist() == [1, 2, 3, 255]
    # minFilter NEAREST_MIPMAP_LINEAR, the mag filter left to us: linear
    assert metal["base_color_map"].sampler == Sampler("linear", "nearest", "linear", "repeat", "repeat")
    assert metal["normal_map"].source == "/images/1" and metal["normal_map"].image.container == "JPEG"
    assert metal["normal_map"].sampler == DEFAULT_SAMPLER  # a texture without a sampler: the defaults
    assert (metal["normal_map"].holds, metal["normal_map"].colour_space) == ("normal", "linear")
    # the ORM texture the material leaves out: glTF's 1 × 1 white, generated
    orm = metal["orm_map"]
    assert orm.generated and orm.image.texels.tolist() == [[[255, 255, 255, 255]]]
    decal = scene.materials["decal"].images["albedo_map"]
    assert decal.sampler == Sampler("nearest", "nearest", "none", "clamp", "clamp")
    assert decal.image is floor.image  # one image, read once, bound twice with two samplers


def test_a_plain_ktx2_image_is_read(tmp_path, lib):
    g = textured_doc(tmp_path)
    texels = np.random.default_rng(3).integers(0, 256, (4, 2, 4), dtype=np.uint8)
    (tmp_path / "t.ktx2").write_bytes(ktx2.encode(texels, "srgb8"))
    g.d["images"][0] = {"uri": "t.ktx2"}
    b = load_scene(g.write_gltf(tmp_path / "model.gltf"), lib).materials["floor"].images["albedo_map"]
    assert b.image.container == "KTX2" and np.array_equal(b.image.texels, texels)


def _basis_ktx2() -> bytes:
    """vkFormat 0 with a UASTC descriptor: what basisu writes (tests/io/test_ktx2.py)."""
    data = bytearray(ktx2.encode(np.zeros((4, 4, 4), np.uint8), "unorm8"))
    struct.pack_into("<2I", data, 12, 0, 1)
    struct.pack_into("<I", data, 104 + 12, 166 | 1 << 8)
    return bytes(data)


def test_basisu_uses_the_fallback_source_with_a_note(tmp_path, lib):
    g = textured_doc(tmp_path)
    g.d["images"].append({"uri": "data:image/ktx2;base64," + base64.b64encode(_basis_ktx2()).decode()})
    g.d["textures"][0]["extensions"] = {"KHR_texture_basisu": {"source": 3}}
    g.d["extensionsUsed"] = ["KHR_texture_basisu"]
    scene = load_scene(g.write_gltf(tmp_path / "model.gltf"), lib)
    assert scene.materials["floor"].images["albedo_map"].source == "/images/0"
    assert any("KHR_texture_basisu image (/images/3) is not read" in n for n in scene.notes), scene.notes


def _pos(text: str, ptr: str) -> tuple[int, int]:
    from generator.scene.jsonpos import Lines, locate
    return Lines(text).position(locate(text, [ptr])[ptr])


def _mutate(case: str, g: Doc, tmp_path) -> str:
    """Break `g` as `case` says; the pointer the error is at."""
    if case == "missing-file":
        (tmp_path / "floor tiles.png").unlink()
        return "/images/0"
    if case == "corrupt-buffer-view":
        off = g.d["bufferViews"][g.d["images"][2]["bufferView"]]["byteOffset"]
        g.bin[off + 40] ^= 0xFF  # a byte of the PNG's IDAT chunk
        return "/images/2"
    if case == "no-mime-type":
        del g.d["images"][2]["mimeType"]
        return "/images/2"
    if case == "basis-ktx2":
        g.d["images"].append({"uri": "data:image/ktx2;base64," + base64.b64encode(_basis_ktx2()).decode()})
        g.d["textures"][0] = {"extensions": {"KHR_texture_basisu": {"source": 3}}}
        g.d["extensionsUsed"] = g.d["extensionsRequired"] = ["KHR_texture_basisu"]
        return "/images/3"
    if case == "no-uri-no-view":
        g.d["images"][1] = {"name": "nothing"}
        return "/images/1"
    if case == "bad-wrap":
        g.d["samplers"][0]["wrapS"] = 1234
        return "/samplers/0/wrapS"
    if case == "no-source":
        del g.d["textures"][1]["source"]
        return "/textures/1"
    if case in ("path-out-of-folder", "absolute-path"):  # a real image, outside the glTF's folder
        outside = tmp_path.parent / f"{tmp_path.name}-outside.png"
        outside.write_bytes((tmp_path / "floor tiles.png").read_bytes())
        g.d["images"][0]["uri"] = f"../{outside.name}" if case == "path-out-of-folder" else str(outside)
        return "/images/0"
    raise AssertionError(case)


ERRORS = {
    "missing-file": "image 'floor%20tiles.png': cannot read image file: No such file or directory",
    "corrupt-buffer-view": "image 'bufferView 0': the PNG is corrupt",
    "no-mime-type": "an image in a buffer view needs a mimeType",
    "basis-ktx2": "a Basis Universal UASTC file",
    "no-uri-no-view": "an image has neither a uri nor a bufferView",
    "bad-wrap": "1234 is not a glTF wrapS",
    "no-source": "the texture has no source image",
    "path-out-of-folder": "the path leads out of the glTF's folder",
    "absolute-path": "the path leads out of the glTF's folder",
}


@pytest.mark.parametrize("case", ERRORS)
def test_a_bad_image_or_sampler_is_an_error_at_its_line_and_pointer(tmp_path, lib, case):
    g = textured_doc(tmp_path)
    ptr = _mutate(case, g, tmp_path)
    path = g.write_gltf(tmp_path / "model.gltf")
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    line, col = _pos(path.read_text(), ptr)
    assert str(e.value).startswith(f"{path}:{line}:{col}: {ptr}: ") and ERRORS[case] in str(e.value), str(e.value)


def test_in_a_glb_the_error_names_the_pointer_and_byte_offset(tmp_path, lib):
    g = textured_doc(tmp_path)
    (tmp_path / "floor tiles.png").unlink()
    path = g.write_glb(tmp_path / "model.glb")
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert str(e.value).startswith(f"{path}:1:1: /images/0 (byte "), str(e.value)
    data = path.read_bytes()
    offset = int(str(e.value).split("(byte ")[1].split(")")[0])
    assert data[offset:offset + 1] == b"{", "the offset is the image object's first byte"


def test_an_extension_declared_and_used_nowhere_is_a_note_in_explain(tmp_path, lib):
    from generator.scene.explain import markdown, report
    g = textured_doc(tmp_path)
    g.d["extensionsUsed"] = ["KHR_materials_emissive_strength", "KHR_mesh_quantization"]
    scene = load_scene(g.write_gltf(tmp_path / "model.gltf"), lib)
    text = markdown(report(scene, lib), explain=True)
    assert ("extension KHR_materials_emissive_strength is declared in extensionsUsed (/extensionsUsed/0) but "
            "used nowhere in the file") in text, text
    assert "KHR_mesh_quantization is declared" not in text  # used by accessors' types, not by an object
    g.d["materials"][0]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}}
    scene = load_scene(g.write_gltf(tmp_path / "model.gltf"), lib)
    assert not any("used nowhere" in n for n in scene.notes), scene.notes


def test_data_uri_helper_is_a_png():
    assert base64.b64decode(png_data_uri().split(",", 1)[1]).startswith(b"\x89PNG")
    assert json.dumps(png_data_uri())  # plain ASCII, embeddable
