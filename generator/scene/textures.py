"""A material's textures as scene inputs: the image each binds, what it holds, and the sampler that reads it.

Which textures a material binds: every texture its packing's bricks declare (the packing and its normal
filler; a baked table is the generator's, never the scene's), and ``emissive_map`` when its surface has
``emissive = "texture"``. Each gets a `TextureBinding`: the decoded image (io/images.py) — the one the scene
names, or, where it names none, the generated one the renderer draws (io/images.generated_image), marked
generated — with what it holds and its colour space, both from the brick's declaration, never from the file
(`holds_of`), and its `Sampler`.

What a texture holds decides how the build filters its mip chain (assemble/textures.py): a declaration's
``"holds"`` is ``color``, ``data``, ``normal`` or ``normal_xy`` (default: ``color`` when it is sRGB, else
``data``), and ``"keep_length": True`` marks a normal map whose filtered length the packing reads (the
Toksvig packings compute the normals' spread from it), so its levels are not renormalized.

Samplers (`Sampler`): mag and min filter ``linear`` | ``nearest``; mipmap ``linear`` | ``nearest`` | ``none``
(``none``: level 0 only); wrap per axis ``repeat`` | ``mirrored`` | ``clamp`` (to the edge); anisotropy 1 … 16;
LOD bias in [−16, 16]; a comparison op for a shadow map's comparison sampler. The defaults, for a texture no
sampler names (glTF's sampler-less texture too): linear, linear mipmaps, repeat, anisotropy 1, bias 0 —
glTF leaves the filter to the implementation ("auto filtering"): this is ours. Anisotropy above 1 needs
linear filters and linear mipmaps (WebGPU and D3D12 allow it only so).

The TOML side is here (`toml_bindings`: per material ``textures = { NAME = "path" }`` and ``samplers = { NAME =
{ … } }``, paths relative to the scene's folder); the glTF side in scene/gltf_images.py. Every error is located:
a TOML entry's line, a glTF object's JSON pointer.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath

import numpy as np

from ..io import sha256
from ..io.images import DecodedImage, generated_image, located, read_image
from ..spec.surface import EMISSIVE_MAP

FILTERS = ("linear", "nearest")
MIPMAPS = ("linear", "nearest", "none")
WRAPS = ("repeat", "mirrored", "clamp")
HOLDS = ("color", "data", "normal", "normal_xy")
MAX_ANISOTROPY = 16  # the largest maxSamplerAnisotropy of Vulkan, D3D12 and WebGPU implementations
MAX_LOD_BIAS = 16.0  # D3D12's range is [-16, 15.99]; Vulkan clamps to maxSamplerLodBias (at least 2)
MAX_LOD_BIAS_UP = 15.99  # the top of D3D12's range (D3D12_MIP_LOD_BIAS_MAX)
SAMPLER_KEYS = ("filter", "mag_filter", "min_filter", "mipmap", "wrap", "wrap_u", "wrap_v", "anisotropy", "lod_bias")
# the declaration of emissive = "texture"'s texture, which no brick declares (the glue samples it: link/glue.py)
EMISSIVE_DECLARATION = {"srgb": True, "holds": "color", "doc": "sRGB RGB: emitted radiance, scaled by emissive"}


@dataclass(frozen=True)
class Sampler:
    """How a texture is read (module docstring: the values and defaults)."""

    mag_filter: str = "linear"
    min_filter: str = "linear"
    mipmap: str = "linear"
    wrap_u: str = "repeat"
    wrap_v: str = "repeat"
    anisotropy: int = 1
    lod_bias: float = 0.0
    compare: str | None = None  # a comparison sampler's op ("less_or_equal"), or None

    def as_dict(self) -> dict:
        return {"mag_filter": self.mag_filter, "min_filter": self.min_filter, "mipmap": self.mipmap,
                "wrap_u": self.wrap_u, "wrap_v": self.wrap_v, "anisotropy": self.anisotropy,
                "lod_bias": self.lod_bias, "compare": self.compare}

    def problem(self) -> str | None:
        """What makes this state impossible on some platform, or None."""
        if self.anisotropy > 1 and (self.mag_filter, self.min_filter, self.mipmap) != ("linear",) * 3:
            return (f"anisotropy {self.anisotropy} needs linear filters and linear mipmaps (WebGPU and D3D12 "
                    "filter anisotropically only so)")
        return None


DEFAULT_SAMPLER = Sampler()


@dataclass(frozen=True)
class TextureBinding:
    """One texture of a material: its image, what it holds, its colour space and its sampler.

    `digest` (the sha256 of the texels, their shape and type) names the image in the build's keys, so a changed
    image rebuilds what lists it; `file` (the file read, for the depfile) and `image` are left out of the repr:
    the keys hold no absolute path and no texels."""

    name: str
    source: str        # the path as the scene wrote it, the glTF JSON pointer of the image, or "generated"
    holds: str
    colour_space: str  # "srgb" | "linear": the declaration's
    keep_length: bool
    sampler: Sampler
    digest: str
    image: DecodedImage = field(compare=False, repr=False)
    file: Path | None = field(default=None, compare=False, repr=False)

    @property
    def generated(self) -> bool:
        return self.source == "generated"


def holds_of(decl: dict) -> tuple[str, str, bool]:
    """(holds, colour space, keep_length) of a texture declaration."""
    srgb = bool(decl.get("srgb"))
    return decl.get("holds") or ("color" if srgb else "data"), "srgb" if srgb else "linear", bool(decl.get("keep_length"))


def declared(packing_node, surface) -> dict[str, dict]:
    """{texture name: declaration} a material binds: its packing's (first declaration first), then emissive_map."""
    out = {n: d for n, d in packing_node.textures.items() if "table" not in d}
    if surface.emissive == "texture":
        out.setdefault(EMISSIVE_MAP, EMISSIVE_DECLARATION)
    return out


def image_digest(image: DecodedImage) -> str:
    t = np.ascontiguousarray(image.texels)
    return sha256(f"{t.shape}:{t.dtype.str}:".encode() + t.tobytes())


def binding(name: str, decl: dict, image: DecodedImage, source: str, sampler: Sampler = DEFAULT_SAMPLER,
            file: Path | None = None) -> TextureBinding:
    holds, colour_space, keep = holds_of(decl)
    return TextureBinding(name, source, holds, colour_space, keep, sampler, image_digest(image), image, file)


def generated(name: str, decl: dict, sampler: Sampler = DEFAULT_SAMPLER) -> TextureBinding:
    """The generated image for a texture no image is named for (io/images.generated_image), marked generated."""
    return binding(name, decl, generated_image(name), "generated", sampler)


def white(name: str, decl: dict, sampler: Sampler = DEFAULT_SAMPLER) -> TextureBinding:
    """A 1 × 1 white image: glTF's meaning of a texture a material leaves out (the factor alone)."""
    image = DecodedImage(np.full((1, 1, 4), 255, np.uint8), "generated", "generated", 4, 8, None, "generated")
    return binding(name, decl, image, "generated", sampler)


def read_file(path: Path, shown: str, fail) -> DecodedImage:
    """The image in file `path`, named `shown` in errors raised through `fail`."""
    return read_image(path, fail, shown)


def _suggest(name: str, names) -> str:
    close = difflib.get_close_matches(name, list(names), n=1)
    known = ", ".join(names) or "none"
    return (f"did you mean '{close[0]}'? " if close else "") + f"the material's textures: {known}"


def toml_bindings(loc, header: str, m: dict, decls: dict, base: Path, cache: dict,
                  notes: list) -> dict[str, TextureBinding]:
    """The texture bindings of TOML material table `m` (at [`header`]): its ``textures`` and ``samplers``
    against `decls` (the textures it binds); images read relative to `base`, each file once per `cache`."""
    textures, samplers = m.get("textures", {}), m.get("samplers", {})
    for key, table in (("textures", textures), ("samplers", samplers)):
        for tname in table:
            if tname not in decls:
                what = "texture" if key == "textures" else "sampler for texture"
                raise loc.error(loc.find(header, key, tname), f"{what} '{tname}': the material binds no such texture",
                                _suggest(tname, decls))
    out = {}
    for tname, decl in decls.items():
        sampler = toml_sampler(loc, header, tname, samplers.get(tname, {}))
        if tname not in textures:  # the generated image: made and digested once per texture name, not per
            if ("generated", tname) not in cache:  # material (10,000 materials left 10,000 equal images)
                image = generated_image(tname)
                cache[("generated", tname)] = (image, image_digest(image))
            image, digest = cache[("generated", tname)]
            out[tname] = TextureBinding(tname, "generated", *holds_of(decl), sampler, digest, image)
            continue
        where = loc.find(header, "textures", tname)
        text = textures[tname]
        if PurePosixPath(text).is_absolute() or PureWindowsPath(text).is_absolute():
            raise loc.error(where, f"texture '{tname}': '{text}' is an absolute path",
                            "write a path relative to the scene's folder (outputs name it as written)")
        path = Path(base) / text
        key = str(path.resolve())
        if key not in cache:  # one file read and decoded once, whichever materials name it
            cache[key] = read_file(path, text, located(loc.path, *where))
        b = binding(tname, decl, cache[key], text, sampler, path)
        note = colour_note(b)
        if note:
            notes.append(f"[{header}] texture '{tname}': {note}")
        out[tname] = b
    return out


def colour_note(b: TextureBinding) -> str | None:
    """A note where the file declares another colour space than the declaration's (which is the one used); the
    scene stage's copy of assemble/textures.colour_note, which comes after it."""
    image = b.image
    if image.declared_srgb is None or image.texels.dtype != np.uint8:
        return None
    if image.declared_srgb != (b.colour_space == "srgb"):
        said = "sRGB" if image.declared_srgb else "linear"
        return (f"image '{image.source}' declares {said} ({image.declaration}); the packing reads it as "
                f"{b.colour_space}, as its texture declaration says")
    return None


def toml_sampler(loc, header: str, tname: str, s: dict) -> Sampler:
    """A TOML ``samplers`` entry (keys and enum values already checked by scene/schema.py) as a Sampler."""
    def at(key):
        return loc.find(header, "samplers", tname, key)

    mag = s.get("mag_filter", s.get("filter", DEFAULT_SAMPLER.mag_filter))
    mn = s.get("min_filter", s.get("filter", DEFAULT_SAMPLER.min_filter))
    wrap = s.get("wrap", DEFAULT_SAMPLER.wrap_u)
    aniso = s.get("anisotropy", 1)
    if isinstance(aniso, float) and aniso.is_integer():
        aniso = int(aniso)
    if not isinstance(aniso, int) or not 1 <= aniso <= MAX_ANISOTROPY:
        raise loc.error(at("anisotropy"), f"sampler '{tname}': anisotropy {aniso!r} is not an integer from 1 to "
                        f"{MAX_ANISOTROPY}", "write e.g. anisotropy = 8 (1: no anisotropic filtering)")
    bias = float(s.get("lod_bias", 0.0))
    if not -MAX_LOD_BIAS <= bias <= MAX_LOD_BIAS_UP:
        raise loc.error(at("lod_bias"), f"sampler '{tname}': lod_bias {bias} is outside [-{MAX_LOD_BIAS:g}, "
                        f"{MAX_LOD_BIAS_UP:g}]", "write a bias in levels, e.g. lod_bias = -0.5")
    sampler = Sampler(mag, mn, s.get("mipmap", DEFAULT_SAMPLER.mipmap), s.get("wrap_u", wrap), s.get("wrap_v", wrap),
                      aniso, bias)
    problem = sampler.problem()
    if problem:
        raise loc.error(at("anisotropy"), f"sampler '{tname}': {problem}",
                        'set filter = "linear" and mipmap = "linear", or anisotropy = 1')
    return sampler
