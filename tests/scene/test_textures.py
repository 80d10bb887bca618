"""Textures and samplers as TOML scene inputs (generator/scene/textures.py): each material's `textures` and
`samplers` tables against the textures its packing declares, images read relative to the scene (PNG files
Pillow writes here), what each texture holds and its colour space from the brick's declaration, the stated
sampler defaults, and every mistake one located error at the TOML entry that makes it."""
from __future__ import annotations

import io
import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from generator.lang import SourceError
from generator.scene.load import load_scene
from generator.scene.textures import DEFAULT_SAMPLER, Sampler


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library(())


def png(array, **save) -> bytes:
    out = io.BytesIO()
    Image.fromarray(np.asarray(array, np.uint8)).save(out, "PNG", **save)
    return out.getvalue()


def checker(n: int = 8) -> np.ndarray:
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    return np.where(((i + j) % 2 == 0)[..., None], [250, 240, 230], [10, 20, 30]).astype(np.uint8)


def flat_normals(n: int = 4) -> np.ndarray:
    return np.tile(np.array([128, 128, 255], np.uint8), (n, n, 1))


HEAD = '''[scene]
name = "textured"

[lights.sun]
type = "directional"

[light_sets]
s = ["sun"]
'''


def write_scene(tmp_path, materials: str, objects=("wood",), images=None) -> "Path":  # noqa: F821
    """A scene of `materials` (TOML text) drawn by one object each, beside the `images` {relative path: bytes}."""
    for rel, data in (images if images is not None else default_images()).items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_bytes(data)
    objs = "".join(f'\n[[objects]]\nname = "{m}_obj"\nmaterial = "{m}"\nlights = "s"\n' for m in objects)
    path = tmp_path / "scene.toml"
    path.write_text(HEAD + materials + objs)
    return path


def default_images() -> dict:
    return {"tex/wood.png": png(checker()), "tex/wood_n.png": png(flat_normals())}


WOOD = '''
[materials.wood]
brdf = "lambert+phong_normalized"
packing = "albedo_texture(normal=normal_map)"
textures = { albedo_map = "tex/wood.png", normal_map = "tex/wood_n.png" }
samplers = { albedo_map = { filter = "nearest", mipmap = "none", wrap = "clamp", wrap_u = "mirrored" } }
'''


def test_named_images_are_read_with_the_declarations_holds_and_the_stated_defaults(tmp_path, lib):
    scene = load_scene(write_scene(tmp_path, WOOD), lib)
    images = scene.materials["wood"].images
    assert list(images) == ["albedo_map", "normal_map"]
    albedo, normal = images["albedo_map"], images["normal_map"]
    assert (albedo.source, albedo.holds, albedo.colour_space, albedo.generated) == ("tex/wood.png", "color", "srgb", False)
    assert (normal.source, normal.holds, normal.colour_space) == ("tex/wood_n.png", "normal", "linear")
    assert np.array_equal(albedo.image.texels[..., :3], checker()) and albedo.image.texels.shape == (8, 8, 4)
    assert albedo.file == tmp_path / "tex/wood.png"
    # filter sets both filters, wrap both axes, and the axis key wins over it
    assert albedo.sampler == Sampler("nearest", "nearest", "none", "mirrored", "clamp", 1, 0.0)
    # a texture no sampler names reads with the defaults the docs state
    assert normal.sampler == DEFAULT_SAMPLER == Sampler("linear", "linear", "linear", "repeat", "repeat", 1, 0.0, None)


def test_a_texture_with_no_image_named_is_the_generated_one(tmp_path, lib):
    mats = '''
[materials.wood]
brdf = "lambert+phong_normalized"
packing = "albedo_texture(normal=normal_map)"
textures = { albedo_map = "tex/wood.png" }
samplers = { normal_map = { anisotropy = 8 } }
'''
    images = load_scene(write_scene(tmp_path, mats), lib).materials["wood"].images
    normal = images["normal_map"]
    assert normal.generated and normal.source == "generated" and normal.file is None
    assert normal.image.texels.shape == (32, 32, 4)  # io/images.generated_image: the bumps the renderer draws
    assert normal.sampler.anisotropy == 8  # a sampler applies to the generated image too


def test_one_file_named_twice_is_read_once_and_shares_its_digest(tmp_path, lib):
    mats = WOOD + '''
[materials.plain]
brdf = "lambert"
packing = "albedo_texture"
textures = { albedo_map = "tex/../tex/wood.png" }
'''
    scene = load_scene(write_scene(tmp_path, mats, objects=("wood", "plain")), lib)
    a, b = scene.materials["wood"].images["albedo_map"], scene.materials["plain"].images["albedo_map"]
    assert a.image is b.image and a.digest == b.digest and a.source != b.source


def test_holds_come_from_the_declaration_and_toksvig_keeps_the_length(tmp_path, lib):
    mats = '''
[materials.rough]
brdf = "lambert+blinn_phong_normalized"
packing = "toksvig_n"
textures = { normal_map = "tex/wood_n.png" }

[materials.xy]
brdf = "lambert+blinn_phong_normalized"
packing = "constants(normal=normal_map_xy)"
textures = { normal_map = "tex/wood_n.png" }
'''
    scene = load_scene(write_scene(tmp_path, mats, objects=("rough", "xy")), lib)
    t, xy = scene.materials["rough"].images["normal_map"], scene.materials["xy"].images["normal_map"]
    assert (t.holds, t.keep_length) == ("normal", True)
    assert (xy.holds, xy.keep_length) == ("normal_xy", False)


def test_a_file_declaring_another_colour_space_is_a_note(tmp_path, lib):
    images = default_images()
    # a gAMA 1.0 chunk (linear) after IHDR (8 + 25 bytes): the declaration's sRGB is what is used
    body = b"gAMA" + struct.pack(">I", 100000)
    gama = struct.pack(">I", 4) + body + struct.pack(">I", zlib.crc32(body))
    images["tex/wood.png"] = images["tex/wood.png"][:33] + gama + images["tex/wood.png"][33:]
    scene = load_scene(write_scene(tmp_path, WOOD, images=images), lib)
    assert scene.materials["wood"].images["albedo_map"].colour_space == "srgb"
    assert any("declares linear (gAMA 1)" in n and "reads it as srgb" in n for n in scene.notes), scene.notes


def _at(text: str, needle: str, nth: int = 0) -> tuple[int, int]:
    """(line, col) of the nth occurrence of needle in text."""
    i = -1
    for _ in range(nth + 1):
        i = text.index(needle, i + 1)
    return text.count("\n", 0, i) + 1, i - (text.rfind("\n", 0, i) + 1) + 1


def _corrupt(data: bytes) -> bytes:
    b = bytearray(data)
    b[45] ^= 0x55  # inside the IDAT chunk: its CRC fails
    return bytes(b)


CASES = {
    "missing-file": (WOOD.replace("tex/wood_n.png", "tex/gone.png"), "normal_map = ",
                     "image 'tex/gone.png': cannot read image file: No such file or directory", "check the path"),
    "corrupt-png": (WOOD, "normal_map = ", "image 'tex/wood_n.png': the PNG is corrupt: chunk", "re-export the image"),
    "truncated-png": (WOOD, "albedo_map = \"", "image 'tex/wood.png': the PNG is truncated", "cut short"),
    "not-an-image": (WOOD, "albedo_map = \"", "image 'tex/wood.png': not a PNG, JPEG or KTX2 image", "give a PNG"),
    "unknown-texture": (WOOD.replace("normal_map = \"", "normal_mapp = \""), "normal_mapp = ",
                        "texture 'normal_mapp': the material binds no such texture", "did you mean 'normal_map'?"),
    "table-texture": (WOOD.replace("normal_map = \"", "fresnel_tex = \""), "fresnel_tex = ",
                      "texture 'fresnel_tex': the material binds no such texture", "albedo_map, normal_map"),
    "unknown-sampler-texture": (WOOD.replace("samplers = { albedo_map", "samplers = { albedo"), "albedo = {",
                                "sampler for texture 'albedo': the material binds no such texture",
                                "did you mean 'albedo_map'?"),
    "unknown-sampler-key": (WOOD.replace('mipmap = "none"', 'mip = "none"'), "mip = ",
                            "unknown key 'mip' in [materials.wood]", "did you mean 'mipmap'?"),
    "bad-wrap": (WOOD.replace('wrap = "clamp"', 'wrap = "tile"'), "wrap = ",
                 "'materials.wood.samplers.albedo_map.wrap' is 'tile', not one of repeat, mirrored, clamp",
                 'write wrap = "repeat"'),
    "anisotropy-range": (WOOD.replace('filter = "nearest", mipmap = "none", ', "anisotropy = 17, "), "anisotropy = ",
                         "anisotropy 17 is not an integer from 1 to 16", "anisotropy = 8"),
    "anisotropy-fraction": (WOOD.replace('filter = "nearest", mipmap = "none", ', "anisotropy = 2.5, "),
                            "anisotropy = ", "anisotropy 2.5 is not an integer", "anisotropy = 8"),
    "anisotropy-nearest": (WOOD.replace('mipmap = "none", ', "anisotropy = 4, "), "anisotropy = ",
                           "anisotropy 4 needs linear filters and linear mipmaps", 'filter = "linear"'),
    "lod-bias": (WOOD.replace('mipmap = "none", ', "lod_bias = 20.0, "), "lod_bias = ",
                 "lod_bias 20.0 is outside [-16, 15.99]", "lod_bias = -0.5"),
    "absolute-path": (WOOD.replace('"tex/wood.png"', '"/srv/wood.png"'), "albedo_map = \"",
                      "texture 'albedo_map': '/srv/wood.png' is an absolute path", "relative to the scene's folder"),
    "path-not-string": (WOOD.replace('"tex/wood.png"', "3"), "albedo_map = 3",
                        "'materials.wood.textures.albedo_map' must be a string, not a number", "give a string"),
}


@pytest.mark.parametrize("case", CASES)
def test_every_mistake_is_one_located_error(tmp_path, lib, case):
    mats, needle, message, hint = CASES[case]
    images = default_images()
    if case == "corrupt-png":
        images["tex/wood_n.png"] = _corrupt(images["tex/wood_n.png"])
    if case == "truncated-png":
        images["tex/wood.png"] = images["tex/wood.png"][:-12]  # no IEND
    if case == "not-an-image":
        images["tex/wood.png"] = b"GIF89a" + bytes(40)
    path = write_scene(tmp_path, mats, images=images)
    text = path.read_text()
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    line, col = _at(text, needle)
    head = f"{path}:{line}:{col}: "
    assert str(e.value).startswith(head) and message in str(e.value) and hint in e.value.hint, (str(e.value), head)


def test_holds_must_agree_with_the_declarations_colour_space(tmp_path):
    """A brick that marks a normal map sRGB, or keeps the length of colour, is refused when loaded."""
    from generator.library.bricks import load_brick
    text = ('"""A packing."""\nBRICK = {"kind": "packing", "cite": "x", "slots": {"normal": {"kind": "normal", '
            '"default": "vertex"}}, "textures": {"t": {"srgb": True, "holds": "normal"}}}\n\n\n'
            'def get_rho_d(uv: vec2, t: texture2d) -> vec3:\n    return sample(t, uv).xyz\n')
    with pytest.raises(SourceError) as e:
        load_brick(tmp_path / "p.py", text)
    assert "texture 't' is marked sRGB but holds 'normal'" in str(e.value), str(e.value)
    with pytest.raises(SourceError) as e:
        load_brick(tmp_path / "p.py", text.replace('"srgb": True, "holds": "normal"', '"keep_length": True'))
    assert "marked keep_length but holds 'data'" in str(e.value), str(e.value)


def test_sub_tables_are_located_at_their_own_lines(tmp_path, lib):
    """`[materials.m.textures]` and `[materials.m.samplers.t]` tables: errors at the key, not the material."""
    mats = '''
[materials.wood]
brdf = "lambert+phong_normalized"
packing = "albedo_texture(normal=normal_map)"

[materials.wood.textures]
albedo_map = "tex/wood.png"
normal_map = "tex/gone.png"

[materials.wood.samplers.albedo_map]
wrap = "clamp"
anisotropy = 2
'''
    path = write_scene(tmp_path, mats)
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert str(e.value).startswith(f"{path}:{_at(path.read_text(), 'normal_map = ')[0]}:1: image 'tex/gone.png'"), \
        str(e.value)
    path.write_text(path.read_text().replace("tex/gone.png", "tex/wood_n.png").replace("anisotropy = 2", "anisotropy = 99"))
    with pytest.raises(SourceError) as e:
        load_scene(path, lib)
    assert str(e.value).startswith(f"{path}:{_at(path.read_text(), 'anisotropy = 99')[0]}:1: sampler 'albedo_map'"), \
        str(e.value)
    path.write_text(path.read_text().replace("anisotropy = 99", "anisotropy = 2"))
    s = load_scene(path, lib).materials["wood"].images["albedo_map"].sampler
    assert (s.wrap_u, s.wrap_v, s.anisotropy) == ("clamp", "clamp", 2)
