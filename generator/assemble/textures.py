"""Textures as build artifacts: a decoded image's full mip chain, filtered by what it holds, as content-addressed KTX2.

`mip_chain` makes levels 1 … n − 1 down to 1 × 1 (n = floor(log2(max(W, H))) + 1); level i is
max(1, W >> i) × max(1, H >> i), the floor convention of KTX2 and Vulkan. Level 0 is the image's own
texels, unchanged. Each level is filtered from the one above it, kept in float64 (not from the
8-bit level stored, so rounding does not accumulate down the chain), with the exact box filter: a texel
of the smaller level averages the area of the larger it covers. For an even size that is the 2 × 2
average; for an odd one (W = 2k + 1 → k) each texel covers 2 + 1/k source texels, weights (1, 1, 1/2)
and (1/2, 1, 1) over 2.5 texels for 5 → 2, (1, 1, 1) / 3 for 3 → 1, so no edge row or column is dropped
and no texel counts twice (a 2 × 2 box would drop the last column of an odd size). The filter is
separable, rows then columns.

What is averaged depends on what the texture holds (`holds`) and its colour space (the packing's
declaration, never the file's):

- ``color`` in ``srgb``: RGB decoded to linear (the sRGB EOTF, IEC 61966-2-1), averaged, encoded back to
  the nearest 8-bit sRGB code; alpha averaged as stored (it is linear). A black/white checker's level 1
  is linear 0.5, sRGB 188 (averaging the codes would give 128, a darker grey).
- ``color`` in ``linear``, and ``data``: every channel averaged as stored.
- ``normal`` (RGB = (t + 1) / 2, a tangent-space normal; A data): t decoded to [−1, 1] and normalized per
  texel, averaged, and renormalized per level — or, with ``keep_length``, left at the averaged length
  |N_a| ≤ 1, the length Toksvig's packings (toksvig_n, toksvig_alpha) read as the normals' spread. A
  texel whose normals cancel (|N_a| = 0) renormalizes to (0, 0, 1).
- ``normal_xy`` (RG = (t.xy + 1) / 2 with z = sqrt(1 − x² − y²) reconstructed; B, A data, as
  normal_map_xy, normal_power_gloss and normal_twist_map store them): the reconstructed t averaged and
  renormalized, its xy stored.

Determinism: only correctly rounded IEEE operations (+, −, ×, ÷, sqrt) in a fixed order, elementwise —
no BLAS, no reductions whose order numpy may choose, no libm power: the sRGB tables are computed once with
`decimal` (software arithmetic, the same on every platform) and encoding is a comparison against the
decoded midpoints between codes, so the same image gives the same bytes everywhere.

`texture_artifact` writes the chain as KTX2 (io/ktx2.py): colour in sRGB as R8G8B8A8_SRGB, other 8-bit
textures R8G8B8A8_UNORM, float images R16G16B16A16_SFLOAT / R32G32B32A32_SFLOAT (linear: a float format
returns linear values, which is what sampling an sRGB texture returns), named
``textures/<W>x<H>.<format>.<sha12>.ktx2`` after its bytes; `generated_artifact` does the same for the
image the renderer draws where a packing texture has no image named (io/images.generated_image).
"""
from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal, localcontext
from fractions import Fraction
from functools import lru_cache
from pathlib import Path

import numpy as np

from .. import __version__
from ..io import atomic_write, ktx2, sha256
from ..io.images import DecodedImage, generated_image

HOLDS = ("color", "data", "normal", "normal_xy")
COLOUR_SPACES = ("srgb", "linear")
TEXTURES_DIR = "textures"


def _srgb_eotf(c: Decimal) -> Decimal:
    """IEC 61966-2-1: the linear value of sRGB-encoded c in [0, 1]."""
    return c / Decimal("12.92") if c <= Decimal("0.04045") else ((c + Decimal("0.055")) / Decimal("1.055")) ** Decimal("2.4")


@lru_cache(maxsize=1)
def srgb_tables() -> tuple[np.ndarray, np.ndarray]:
    """(linear value of each 8-bit code, 256; linear values of the midpoints between codes k − 1 and k, 255)."""
    with localcontext() as ctx:
        ctx.prec = 40
        decode = [float(_srgb_eotf(Decimal(k) / 255)) for k in range(256)]
        midpoints = [float(_srgb_eotf((Decimal(k) - Decimal("0.5")) / 255)) for k in range(1, 256)]
    return np.array(decode, np.float64), np.array(midpoints, np.float64)


def _encode_srgb(linear: np.ndarray) -> np.ndarray:
    """The nearest 8-bit sRGB code of each linear value (ties up): how many midpoints lie at or below it."""
    return np.searchsorted(srgb_tables()[1], linear, side="right").astype(np.uint8)


def _round_unorm(x: np.ndarray) -> np.ndarray:
    """Values on the 0..255 scale to uint8, halves rounded up (floor(x + 0.5)), clamped."""
    return np.clip(np.floor(x + 0.5), 0.0, 255.0).astype(np.uint8)


@lru_cache(maxsize=64)
def _taps(n_in: int, n_out: int) -> tuple[np.ndarray, np.ndarray]:
    """(source index, weight) of the three taps of each output texel: the exact area each covers."""
    index = np.zeros((3, n_out), np.intp)
    weight = np.zeros((3, n_out), np.float64)
    for i in range(n_out):
        lo, hi = Fraction(i * n_in, n_out), Fraction((i + 1) * n_in, n_out)
        first = int(lo)  # floor: lo ≥ 0
        for k in range(3):
            j = first + k
            overlap = min(hi, j + 1) - max(lo, Fraction(j))
            if j < n_in and overlap > 0:
                index[k, i], weight[k, i] = j, float(overlap / (hi - lo))
            else:
                index[k, i] = first  # a tap of weight 0 (0 × a finite value adds nothing)
    return index, weight


def _box(a: np.ndarray, height: int, width: int) -> np.ndarray:
    """`a` (H, W, C) box-filtered to (height, width, C): rows then columns, three taps each, in a fixed order."""
    for axis, n_out in ((0, height), (1, width)):
        n_in = a.shape[axis]
        if n_in == n_out:
            continue
        index, weight = _taps(n_in, n_out)
        shape = [1, 1, 1]
        shape[axis] = n_out
        taps = [np.take(a, index[k], axis=axis) * weight[k].reshape(shape) for k in range(3)]
        a = (taps[0] + taps[1]) + taps[2]
    return a


def _unit(t: np.ndarray) -> np.ndarray:
    """Vectors (…, 3) scaled to length 1; a zero vector becomes (0, 0, 1)."""
    length = np.sqrt(t[..., 0] * t[..., 0] + t[..., 1] * t[..., 1] + t[..., 2] * t[..., 2])[..., None]
    up = np.broadcast_to(np.array([0.0, 0.0, 1.0]), t.shape)
    return np.where(length > 0.0, t / np.where(length > 0.0, length, 1.0), up)


@dataclass(frozen=True)
class _Filter:
    """How a texture's texels become the float64 values averaged, and back."""

    holds: str
    srgb: bool
    keep_length: bool
    dtype: np.dtype

    def decode(self, texels: np.ndarray) -> np.ndarray:
        """8-bit texels on their 0..255 scale (sRGB RGB as linear 0..1), float ones as they are; normals as t."""
        x = texels.astype(np.float64)
        # a normal is stored as (t + 1) / 2: on 0..255 in 8 bits, on 0..1 in a float format
        to_t = 2.0 / 255.0 if self.dtype == np.uint8 else 2.0
        if self.srgb:
            x[..., :3] = srgb_tables()[0][texels[..., :3]]
        elif self.holds == "normal":
            x[..., :3] = _unit(x[..., :3] * to_t - 1.0)
        elif self.holds == "normal_xy":
            xy = x[..., :2] * to_t - 1.0
            z = np.sqrt(np.maximum(0.0, 1.0 - xy[..., 0] * xy[..., 0] - xy[..., 1] * xy[..., 1]))
            x = np.concatenate([_unit(np.concatenate([xy, z[..., None]], axis=-1)), x[..., 2:]], axis=-1)
        return x

    def settle(self, x: np.ndarray) -> np.ndarray:
        """A filtered level as the next one is filtered from: normals renormalized unless their length is kept."""
        if self.holds in ("normal", "normal_xy") and not self.keep_length:
            x = x.copy()
            x[..., :3] = _unit(x[..., :3])
        return x

    def encode(self, x: np.ndarray) -> np.ndarray:
        """A filtered level back to the texture's dtype (decode's inverse, rounded to the nearest code)."""
        n = {"normal": 3, "normal_xy": 2}.get(self.holds, 0)  # leading channels that hold t
        if self.holds == "normal_xy":  # back to RG = xy, B, A
            x = np.concatenate([x[..., :2], x[..., 3:]], axis=-1)
        if self.dtype.kind == "f":
            x = x.copy()
            x[..., :n] = (x[..., :n] + 1.0) * 0.5
            return x.astype(self.dtype)
        out = np.empty(x.shape, np.uint8)
        if self.srgb:
            out[..., :3] = _encode_srgb(x[..., :3])
            out[..., 3] = _round_unorm(x[..., 3])
        else:
            out[..., :n] = _round_unorm((x[..., :n] + 1.0) * 127.5)
            out[..., n:] = _round_unorm(x[..., n:])
        return out


def _filter_for(texels: np.ndarray, holds: str, colour_space: str, keep_length: bool) -> _Filter:
    if holds not in HOLDS:
        raise ValueError(f"a texture holds one of {', '.join(HOLDS)}, not {holds!r}")
    if colour_space not in COLOUR_SPACES:
        raise ValueError(f"a colour space is one of {', '.join(COLOUR_SPACES)}, not {colour_space!r}")
    if colour_space == "srgb" and holds != "color":
        raise ValueError(f"{holds} texels are linear: only a colour texture is sRGB-encoded")
    if keep_length and holds != "normal":  # normal_xy rebuilds z as a unit vector: a kept length would be lost
        raise ValueError("keep_length is for normal maps stored with z (the Toksvig packings read the filtered "
                         "length)")
    if not isinstance(texels, np.ndarray) or texels.ndim != 3 or texels.shape[2] != 4 or 0 in texels.shape:
        raise ValueError(f"texels are an (H, W, 4) array, not {getattr(texels, 'shape', type(texels).__name__)}")
    if texels.dtype not in (np.uint8, np.float16, np.float32):
        raise ValueError(f"texels are uint8, float16 or float32, not {texels.dtype}")
    srgb = colour_space == "srgb" and texels.dtype == np.uint8  # float texels are linear values
    return _Filter(holds, srgb, keep_length, texels.dtype)


def mip_chain(texels: np.ndarray, holds: str = "data", colour_space: str = "linear", *,
              keep_length: bool = False) -> list[np.ndarray]:
    """Levels 0 (`texels`, (H, W, 4)) to 1 × 1, level i max(1, W >> i) × max(1, H >> i), filtered as `holds`
    and `colour_space` say (module docstring); same dtype as `texels`."""
    f = _filter_for(texels, holds, colour_space, keep_length)
    height, width = texels.shape[:2]
    levels, x = [np.ascontiguousarray(texels)], f.decode(texels)
    for i in range(1, ktx2.full_level_count(width, height)):
        w, h = ktx2.level_size(width, height, i)
        x = f.settle(_box(x, h, w))
        levels.append(np.ascontiguousarray(f.encode(x)))
    return levels


@dataclass(frozen=True)
class TextureArtifact:
    """A texture's KTX2 bytes, their sha256 and the descriptor a manifest lists per material binding."""

    data: bytes
    sha256: str
    descriptor: dict

    @property
    def path(self) -> str:
        """Where it goes in a build's output: named by its bytes, so a changed image never overwrites a file."""
        return self.descriptor["path"]

    def write(self, out: Path) -> bool:
        """Write it under `out` atomically; False (nothing touched) when the file already holds these bytes."""
        return atomic_write(Path(out) / self.path, self.data)


def _format(texels: np.ndarray, srgb: bool) -> str:
    if texels.dtype == np.uint8:
        return "srgb8" if srgb else "unorm8"
    return "fp16" if texels.dtype == np.float16 else "fp32"


def texture_artifact(image: DecodedImage, holds: str, colour_space: str, source: str, *,
                     keep_length: bool = False) -> TextureArtifact:
    """`image` as a mipmapped KTX2 artifact; `source` is what the descriptor names it by (the path relative
    to the scene, a glTF JSON pointer, or "generated")."""
    f = _filter_for(image.texels, holds, colour_space, keep_length)
    levels = mip_chain(image.texels, holds, colour_space, keep_length=keep_length)
    fmt = _format(image.texels, f.srgb)
    data = ktx2.encode_levels(levels, fmt, writer=f"shadermatrix {__version__}")
    digest = sha256(data)
    descriptor = {
        "path": f"{TEXTURES_DIR}/{image.width}x{image.height}.{fmt}.{digest[:12]}.ktx2",
        "format": ktx2.VK_NAMES[fmt],
        "width": image.width,
        "height": image.height,
        "levels": len(levels),
        "colour_space": "srgb" if f.srgb else "linear",
        "holds": holds,
        "mip_filter": _filter_name(f),
        "sha256": digest,
        "bytes": len(data),
        "source": source,
        "generated": image.container == "generated",
    }
    return TextureArtifact(data, digest, descriptor)


def _filter_name(f: _Filter) -> str:
    if f.srgb:
        return "box, sRGB-correct (RGB averaged in linear)"
    if f.holds in ("normal", "normal_xy"):
        return "box, normals averaged, length kept" if f.keep_length else "box, normals averaged and renormalized"
    return "box"


def generated_artifact(name: str, holds: str, *, keep_length: bool = False) -> TextureArtifact:
    """The image the renderer draws for packing texture `name` where none is named, as an artifact marked
    generated (source "generated"): the checker in sRGB, the normal map and the grey linear."""
    image = generated_image(name)
    colour_space = "srgb" if image.declared_srgb and holds == "color" else "linear"
    return texture_artifact(image, holds, colour_space, "generated", keep_length=keep_length)


def colour_note(image: DecodedImage, colour_space: str) -> str | None:
    """A note where the file declares another colour space than the packing's (the packing's is used)."""
    if image.declared_srgb is None or image.texels.dtype != np.uint8:
        return None
    if image.declared_srgb != (colour_space == "srgb"):
        said = "sRGB" if image.declared_srgb else "linear"
        return (f"image '{image.source}' declares {said} ({image.declaration}); the packing reads it as "
                f"{colour_space}, as its texture declaration says")
    return None
