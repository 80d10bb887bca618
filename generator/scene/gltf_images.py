"""glTF images and samplers → the texture bindings of the mapped materials (scene/textures.py).

Each texture a mapped material binds (scene/gltf_materials.py: base_color_map, orm_map, albedo_map, normal_map,
emissive_map) is read from the file: its texture's image — by URI (a percent-encoded path relative to the
glTF file's folder, or a base64 data URI) or by buffer view (with its mimeType) — PNG, JPEG, or an
uncompressed KTX2 (io/images.py), each image once, whichever materials bind it; and its sampler. A texture
of the packing the material leaves out is glTF's 1 × 1 white (`textures.white`), one the mapping has no
glTF texture for the generated image, both marked generated.

KHR_texture_basisu: a texture whose extension names a KTX2 image uses its core ``source`` when it has one
(the fallback the extension asks files to keep: a note says so); without one it reads the extension's image,
and a Basis Universal KTX2 — which needs a transcoder there is none of here — is refused, located.

Samplers (glTF 2.0 §5.26): magFilter 9728 NEAREST, 9729 LINEAR; minFilter 9728 / 9729 (no mipmaps: level
0 only), 9984 NEAREST_MIPMAP_NEAREST, 9985 LINEAR_MIPMAP_NEAREST, 9986 NEAREST_MIPMAP_LINEAR, 9987
LINEAR_MIPMAP_LINEAR; wrapS / wrapT 33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT, 10497 REPEAT (the default).
A filter the file leaves out is ours (glTF: "auto filtering"): linear, with linear mipmaps for minFilter; a
texture without a sampler has all the defaults.

Every error is at the glTF object's position and JSON pointer (scene/jsonpos.py): a missing, unreadable or
corrupt image reads `model.gltf:L:C: /images/N: image 'wood.png': …`, a bad sampler value
`model.gltf:L:C: /samplers/N/wrapS: …`; in a .glb at 1:1 with the object's byte offset.
"""
from __future__ import annotations

from pathlib import Path

from ..io.images import decode_image, read_uri
from ..spec.permutation import parse_spec
from .jsonpos import origins, pointer
from .textures import DEFAULT_SAMPLER, Sampler, binding, colour_note, declared, generated, white

MAG_FILTERS = {9728: "nearest", 9729: "linear"}
MIN_FILTERS = {9728: ("nearest", "none"), 9729: ("linear", "none"), 9984: ("nearest", "nearest"),
               9985: ("linear", "nearest"), 9986: ("nearest", "linear"), 9987: ("linear", "linear")}
WRAPS = {33071: "clamp", 33648: "mirrored", 10497: "repeat"}
BASISU = "KHR_texture_basisu"


class _Images:
    """Checked, located reading of a glTF file's images and samplers (each read once)."""

    def __init__(self, rd, text: str, glb: bool, notes: list):
        self.rd, self.text, self.glb, self.notes = rd, text, glb, notes
        self.images: dict[int, tuple] = {}  # image index -> (DecodedImage, pointer, file or None)
        self.samplers: dict[int, Sampler] = {}

    def fail(self, ptr: str):
        """A `fail` (io/images.py) raising a SourceError at ptr's position, naming the pointer."""
        def error(message: str, hint: str = ""):
            where = origins(self.rd.shown, self.text, {0: (("image", ptr),)}, self.glb)[0].parts[0][1]
            return where.error(message, hint)
        return error

    def image(self, i: int) -> tuple:
        if i in self.images:
            return self.images[i]
        rd, ptr = self.rd, pointer("images", i)
        img = rd.array("images")[i]
        fail = self.fail(ptr)
        uri = rd.get(img, "uri", ptr, "str", None)
        mime = rd.get(img, "mimeType", ptr, "str", None)
        file = None
        if uri is not None and "bufferView" in img:
            raise fail("an image has a uri or a bufferView, not both", "keep one")
        if uri is not None:
            decoded = read_uri(uri, rd.path.parent, fail)
            if not uri.startswith("data:"):
                from urllib.parse import unquote
                file = rd.path.parent / unquote(uri)
        elif "bufferView" in img:
            if mime is None:
                raise fail("an image in a buffer view needs a mimeType", 'add "mimeType": "image/png" (or image/jpeg)')
            decoded = decode_image(self._view(img, ptr), fail, f"bufferView {img['bufferView']}", mime=mime)
        else:
            raise fail("an image has neither a uri nor a bufferView", "give the image a uri or a bufferView")
        self.images[i] = (decoded, ptr, file)
        return self.images[i]

    def _view(self, img: dict, ptr: str) -> bytes:
        rd = self.rd
        bvi = rd.ref(img, "bufferView", ptr, "bufferViews")
        bptr = pointer("bufferViews", bvi)
        bv = rd.array("bufferViews")[bvi]
        data = rd.buffer(rd.ref(bv, "buffer", bptr, "buffers"))
        off, length = rd.get(bv, "byteOffset", bptr, "int", 0), rd.get(bv, "byteLength", bptr, "int")
        if off < 0 or length < 1 or off + length > len(data):
            raise rd.err(bptr, f"bytes {off}…{off + length} lie outside its buffer ({len(data)} bytes)",
                         "fix byteOffset / byteLength")
        return bytes(data[off:off + length])

    def sampler(self, si: int | None) -> Sampler:
        if si is None:
            return DEFAULT_SAMPLER
        if si not in self.samplers:
            self.samplers[si] = self._sampler(si)
        return self.samplers[si]

    def _sampler(self, si: int) -> Sampler:
        rd, ptr = self.rd, pointer("samplers", si)
        s = rd.array("samplers")[si]

        def code(key, table, default):
            v = rd.get(s, key, ptr, "int", None)
            if v is None:
                return default
            if v not in table:
                raise self.fail(f"{ptr}/{key}")(f"{v} is not a glTF {key}",
                                                f"use one of {', '.join(map(str, table))}")
            return table[v]

        mag = code("magFilter", MAG_FILTERS, DEFAULT_SAMPLER.mag_filter)
        mn, mip = code("minFilter", MIN_FILTERS, (DEFAULT_SAMPLER.min_filter, DEFAULT_SAMPLER.mipmap))
        return Sampler(mag, mn, mip, code("wrapS", WRAPS, "repeat"), code("wrapT", WRAPS, "repeat"))

    def source(self, ti: int) -> int:
        """The image texture ti reads: its core source, else KHR_texture_basisu's (which must then decode)."""
        rd, ptr = self.rd, pointer("textures", ti)
        tex = rd.array("textures")[ti]
        ext = tex.get("extensions") if isinstance(tex.get("extensions"), dict) else {}
        src = rd.ref(tex, "source", ptr, "images", None)
        if BASISU in ext:
            eptr = f"{ptr}/extensions/{BASISU}"
            basis = rd.ref(rd.get(ext, BASISU, f"{ptr}/extensions", "obj"), "source", eptr, "images", None)
            if src is not None and basis is not None:
                self.notes.append(f"texture {ti}: its {BASISU} image ({pointer('images', basis)}) is not read "
                                  f"(Basis Universal needs a transcoder); its source {pointer('images', src)} is")
            else:
                src = basis
        if src is None:
            raise self.fail(ptr)("the texture has no source image", 'add "source": the index of its image')
        return src


def bind_images(rd, lib, scene, text: str, glb: bool, notes: list) -> None:
    """Set `images` (texture name -> TextureBinding) on every material of a glTF scene (module docstring)."""
    reader = _Images(rd, text, glb, notes)
    noted: set = set()  # (image, colour space) pairs a colour note was given for
    for m in scene.materials.values():
        decls = declared(parse_spec(m.packing, lib, ("packing",))[0], m.surface)
        images = {}
        for tname, decl in decls.items():
            slot = m.textures.get(tname)
            if slot is None:
                images[tname] = generated(tname, decl)
            elif slot == "white":
                images[tname] = white(tname, decl)
            else:
                ti = slot["texture"]
                tex = rd.array("textures")[ti]
                sampler = reader.sampler(rd.ref(tex, "sampler", pointer("textures", ti), "samplers", None))
                decoded, ptr, file = reader.image(reader.source(ti))
                images[tname] = binding(tname, decl, decoded, ptr, sampler, Path(file) if file else None)
                note = colour_note(images[tname])
                if note and (ptr, images[tname].colour_space) not in noted:
                    noted.add((ptr, images[tname].colour_space))
                    notes.append(f"material '{m.name}', texture '{tname}': {note}")
        m.images = images
