"""Hand-painted BRDF tables: NDF maps, Fresnel ramps and NDF + Fresnel maps.

Hoffman & Baker 2006 ("Physically-Based Reflectance for Games", "Other Types of BRDFs"):

- **NDF maps.** f_r(ω_i, ω_e) = ρ_d/π + K_N R_F(0) p(ω_h): "a generalization of Blinn-Phong to a
  general NDF (K_N is a normalization factor)"; the NDF is painted into a texture (1D p(θ_h) for an
  isotropic BRDF), and "the value of K_N is automatically calculated from the NDF texture in tools to
  ensure that the BRDF is both reciprocal and energy-conserving". "NDFs are high dynamic range by
  nature — the normalization helps increase range"; "a colored NDF map can simulate colored facets".
- **Fresnel ramps.** "R_F(α_h) can be stored in a 1D texture or ramp — computed from material
  properties, or painted by an artist."
- **NDF + Fresnel texture.** "A 2D texture mapped by θ_h on one axis and α_h on the other allows
  hand-painting both arbitrary 1D NDFs and Fresnel functions, as well as interactions between the two.
  Texture still needs to be processed for normalization."

Angles, as the notes define them ("Translating BRDF Math to Shaders"): θ_h the angle between h and n
(cos θ_h = n·h), α_h the angle between h and l, or equally v (cos α_h = l·h = v·h).

**Normalization (K_N).** The painted p is scaled to a microfacet distribution D = p / ∫ p(ω_h) cos θ_h
dω_h, so that ∫ D cos θ_h dω_h = 1 (the projected-area normalization of every NDF brick, Walter et al.
2007 eq. 4; library/kinds.py's "ndf" contract), per RGB channel (a coloured map is one NDF per channel).
The BRDF term is the microfacet BRDF D G R_F / (4 n·l n·v) with the implicit visibility
G = (n·l)(n·v) (Hoffman & Baker's reading of Blinn-Phong as a microfacet BRDF: "the cosine raised to a
power is simply a normal distribution function"), so

    K_N p(ω_h) = D(ω_h) / 4 = p(ω_h) / (4 ∫ p cos θ_h dω_h),

and that product is what the table stores (fp16: HDR, no extra constant in the shader). For p = cos^n θ_h
this is (n + 2)/(8π) cos^n θ_h, the course's (n + 4)/(8π) up to its large-n approximation of the same
normalization. Why it is *reciprocal*: the term depends on h (and α_h) only, and h, l·h = v·h are
symmetric in l and v. Why it is *energy-conserving*: the directional albedo is
R(v) = R_F(0) ∫ D(h) (h·v) (n·l)⁺ dω_h (dω_l = 4 (h·v) dω_h), which at normal incidence is
R_F(0) ∫ D cos θ_h (2cos²θ_h − 1)⁺ dω_h ≤ R_F(0); measured ≤ 1 for every view on the shipped maps, the
cos^n family and rings of facets up to θ_h = 88° (tests/library/test_painted.py) — so ρ_d + R_F(0) ≤ 1 keeps
the whole BRDF within 1, the notes' rule for the normalized Blinn-Phong.
The integral is computed from the continuous painted function (the image linearly interpolated on
its own axes, below), not from the table, by composite quadrature that resolves every painted
segment (relative error < 1e-6: tests).

**Axes.** A painted image is painted on the axes its table uses, so that a painting of the table's size
*is* the table (times K_N), and the shader's bilinear filter interpolates the same piecewise-linear
function the artist's pixels define; a painting of another size is resampled (bilinearly) onto the
table. Pixel i of w samples its axis at i/(w − 1), ends exact (the tables' convention, tables.py).
(A first version painted p over θ_h and resampled to the shader's axis: the two interpolations
differ most where the painting falls to 0, and the brick was 90× off in the tails.)
- `ndf_map` (isotropic): a w × 1 image over u = √(1 − cos θ_h) = √2 sin(θ_h/2) (pixel 0: the highlight's
  centre, the last: θ_h = 90°); nearly linear in θ_h (u ≈ θ_h/√2 at the peak, θ_h = 41° at u = ½) and one
  sqrt of ALU in the shader (θ_h itself would cost an acos), which computes it as √(sin²θ_h /
  (1 + cos θ_h)) from NxH2, free of cancellation at the peak.
- `ndf_map_anisotropic`: a w × h image over the tangent-plane projection of h, x = h·t, y = h·b in
  [−1, 1] (the orthographic "disk" view of the hemisphere of normals from above; no trigonometry in
  the shader). Its area element makes the normalization a plain area integral:
  ∫ D cos θ_h dω_h = ∫∫_{x²+y²≤1} D dx dy. Texels outside the disk keep the painted values (so the
  filter sees a continuous function at the rim) and do not count.
- `ndf_fresnel_map`: a w × h image, x = u = √(1 − cos θ_h), y = 1 − cos α_h (row 0: α_h = 0, normal
  incidence; the last row: grazing, where Fresnel changes, gets the finest steps in angle).
  Normalized so that the row α_h = 0 is a unit NDF as above: K = 1 / (4 ∫ T(θ_h, 0) cos θ_h dω_h),
  f = R_F(0) K T(θ_h, α_h); the other rows paint R_F(α_h)/R_F(0) and its interaction with the NDF
  (their brightness relative to row 0).
- `fresnel_ramp`: R_F per f0: a table W × H over x = 1 − cos α_h (left: normal incidence) and y = √f0
  (one ramp per normal-incidence reflectance; √f0 spends the rows on the dielectrics' small f0).
  Computed from material properties when no image is given: the exact unpolarized dielectric Fresnel
  at η = (1 + √f0)/(1 − √f0) (Cook & Torrance 1982; exact.fresnel_dielectric_f0), so the ramp honours
  the brick's f0 per channel. A painted ramp (same axes, any height; a 1-row ramp is the same for
  every f0) replaces it, its RGB being R_F directly.

The example painted images are generated by scripts/paint_examples.py into bricks/brdf/painted/
(deterministic PNGs; the brick loader reads only *.py). A baker given image=None uses them (fresnel_ramp:
the computed ramp). `bake_painted(name, image_path)` bakes an engine's own image at the declaring
brick's size and format, validating it with errors that name the file.
"""
from __future__ import annotations

import math

import numpy as np

from ..lang.errors import SourceError
from ..library.bricks import BUILTIN_BRICKS, display
from . import exact
from .tables import axis, quantize, table

EXAMPLES = BUILTIN_BRICKS / "brdf" / "painted"  # the painted bricks' own example images, package data with them
EXAMPLE_FILES = {"ndf_map": "ndf_map.png", "ndf_map_anisotropic": "ndf_map_anisotropic.png",
                 "ndf_fresnel_map": "ndf_fresnel_map.png", "fresnel_ramp": "fresnel_ramp.png"}
MAX_SIDE = 4096  # as the brick schema's table sizes: a larger painted image is a mistake, not a table


# ------------------------------------------------------------------ images

def load_image(path) -> np.ndarray:
    """A PNG (or any image Pillow reads) as float64 (h, w, 4) in [0, 1]: 8-bit and 16-bit grey, grey +
    alpha, RGB, RGBA, palette. SourceError naming the file for anything else."""
    from PIL import Image, UnidentifiedImageError

    shown = str(path)
    try:
        with Image.open(path) as im:
            im.load()
            a = _rgba(im, im.format, shown)
    except FileNotFoundError:
        raise SourceError(shown, 1, 1, "no such image file", "check the path") from None
    except UnidentifiedImageError:
        raise SourceError(shown, 1, 1, "not an image Pillow can read", "give a PNG file") from None
    except OSError as e:
        raise SourceError(shown, 1, 1, f"cannot read the image: {e}", "give a valid PNG file") from None
    if a.ndim != 3 or a.shape[2] != 4:
        raise SourceError(shown, 1, 1, f"unexpected image shape {a.shape}", "give a 2D grey, RGB or RGBA image")
    return a


GREY16 = ("I;16", "I;16B", "I;16L")  # Pillow's 16-bit grey modes (native, big- and little-endian words)


def _rgba(im, fmt: str | None, shown: str) -> np.ndarray:
    """An opened image's pixels as float64 RGBA in [0, 1]; `fmt` the file's format (Pillow's im.format).

    16-bit grey is scaled by 1/65535: modes "I;16", "I;16B", "I;16L" and mode "I" read from a PNG, the mode in
    which older Pillow versions open 16-bit grey PNGs (PNG stores at most 16 bits a channel, so "I" from a PNG
    holds 0 … 65535). Mode "I" from any other file is 32-bit signed: no scale to [0, 1] is known, so it is refused
    (dividing by 2^32 − 1 made a 16-bit painting almost black)."""
    mode = im.mode
    if mode in GREY16 or (mode == "I" and fmt == "PNG"):
        a = np.asarray(im, dtype=np.float64) / 65535.0
        a = np.repeat(a[..., None], 3, axis=-1)
        return np.concatenate([a, np.ones(a.shape[:2] + (1,))], axis=-1)
    if mode in ("1", "L", "LA", "P", "PA", "RGB", "RGBA"):
        return np.asarray(im.convert("RGBA"), dtype=np.float64) / 255.0
    if mode in ("I", "F"):
        raise SourceError(shown, 1, 1, f"the image is {'32-bit integer' if mode == 'I' else '32-bit float'} "
                          f"grey (Pillow mode {mode!r}), which has no fixed [0, 1] scale",
                          "save it as an 8-bit or 16-bit grey PNG (or 8-bit RGB/RGBA)")
    raise SourceError(shown, 1, 1, f"the image's pixel mode {mode!r} is not read",
                      "save it as 8-bit (or 16-bit grey) PNG: grey, RGB or RGBA")


def example_image(name: str) -> np.ndarray:
    """The shipped example painting of table `name` (bricks/brdf/painted/)."""
    return load_image(EXAMPLES / EXAMPLE_FILES[name])


def check_image(name: str, image: np.ndarray, shown: str = "<image>") -> np.ndarray:
    """The image's RGB (h, w, 3) after the checks table `name` needs; SourceError naming `shown`."""
    a = np.asarray(image, np.float64)
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise SourceError(shown, 1, 1, f"a painted table is an (h, w, 3 or 4) image, got shape {a.shape}",
                          "give a grey, RGB or RGBA image")
    h, w = a.shape[:2]
    if max(h, w) > MAX_SIDE:
        raise SourceError(shown, 1, 1, f"the image is {w} × {h}, larger than {MAX_SIDE} on a side",
                          "paint it smaller: the table is resampled to the brick's size anyway")
    if not np.isfinite(a).all() or a.min() < 0.0 or a.max() > 1.0:
        raise SourceError(shown, 1, 1, "image values outside [0, 1]", "give an 8- or 16-bit image")
    rgb = a[..., :3]
    need = {"ndf_map": (2, 1, "a 1D profile: w × 1 pixels, p over u = √(1 − cos θ_h) from 0 (left) to 1 (right)"),
            "ndf_map_anisotropic": (2, 2, "w × h pixels over (h·t, h·b) in [−1, 1]²"),
            "ndf_fresnel_map": (2, 2, "w × h pixels over u = √(1 − cos θ_h) (x) and 1 − cos α_h (y)"),
            "fresnel_ramp": (2, 1, "w × h pixels, R_F over 1 − cos α_h (x), rows over √f0")}[name]
    min_w, min_h, what = need
    if name == "ndf_map" and h != 1:
        raise SourceError(shown, 1, 1, f"the isotropic NDF map is {w} × {h}; it must be one row", f"paint {what}")
    if w < min_w or h < min_h:
        raise SourceError(shown, 1, 1, f"the image is {w} × {h}, too small for table '{name}'", f"paint {what}")
    if name != "fresnel_ramp":
        for c in range(3):
            if not rgb[..., c].any():
                raise SourceError(shown, 1, 1, f"channel {'RGB'[c]} is 0 everywhere: an NDF cannot be normalized",
                                  "paint some facets in every channel (a grey image paints all three)")
        if name == "ndf_fresnel_map" and not rgb[0].any(axis=0).all():
            raise SourceError(shown, 1, 1, "row 0 (α_h = 0) is 0 in some channel: it is the NDF that is normalized",
                              "paint the normal-incidence NDF in the top row")
        if name == "ndf_map_anisotropic":
            x = np.linspace(-1.0, 1.0, w)[None, :]
            y = np.linspace(-1.0, 1.0, h)[:, None]
            if not (rgb * ((x * x + y * y) <= 1.0)[..., None]).any(axis=(0, 1)).all():
                raise SourceError(shown, 1, 1, "nothing is painted inside the unit disk in some channel",
                                  "paint the highlight within the disk x² + y² ≤ 1 (the hemisphere seen from above)")
    return rgb


def interp(img: np.ndarray, x, y=None) -> np.ndarray:
    """Linear (y None: along row 0) or bilinear sample of an (h, w, C) image whose pixel i sits at
    i/(w − 1) (ends exact); x, y in [0, 1] (clamped). Returns (..., C) float64."""
    img = np.asarray(img, np.float64)
    h, w = img.shape[:2]

    def split(t, n):
        t = np.clip(np.asarray(t, np.float64), 0.0, 1.0) * (n - 1)
        i0 = np.minimum(np.floor(t).astype(np.intp), max(n - 2, 0))
        return i0, np.minimum(i0 + 1, n - 1), (t - i0)[..., None]

    i0, i1, ax = split(x, w)
    if y is None or h == 1:
        row = img[0]
        return row[i0] * (1.0 - ax) + row[i1] * ax
    j0, j1, ay = split(y, h)
    return ((img[j0, i0] * (1.0 - ax) + img[j0, i1] * ax) * (1.0 - ay)
            + (img[j1, i0] * (1.0 - ax) + img[j1, i1] * ax) * ay)


# ------------------------------------------------------------------ normalization

def profile_norm(rgb_row: np.ndarray) -> np.ndarray:
    """(3,) ∫ p cos θ_h dω_h of an isotropic profile painted along u = √(1 − cos θ_h) (a (1, w, 3) row,
    pixel i at u = i/(w − 1), linear in between), per channel. With cos θ_h = 1 − u², dω = 2π sin θ dθ:
    ∫ p cos θ_h dω_h = 2π ∫_0^1 p(u) (1 − u²) 2u du — a degree-4 polynomial on each painted segment,
    which 3-point Gauss-Legendre integrates exactly (rounding only)."""
    w = rgb_row.shape[1]
    g, gw = np.polynomial.legendre.leggauss(3)
    edges = axis(w)
    a, b = edges[:-1, None], edges[1:, None]
    u = 0.5 * (a + b) + 0.5 * (b - a) * g  # (w - 1, 3) nodes
    wts = 0.5 * (b - a) * gw
    vals = interp(rgb_row, u.ravel()).reshape(u.shape + (3,))
    return 2.0 * math.pi * np.einsum("sn,snc->c", wts * (1.0 - u * u) * 2.0 * u, vals)


def disk_norm(rgb: np.ndarray, nr: int = 384, nphi: int = 1536) -> np.ndarray:
    """(3,) ∫∫_{x²+y²≤1} p dx dy of the painted anisotropic map (= ∫ p cos θ_h dω_h), in polar
    coordinates: Gauss-Legendre in r (nr nodes), the periodic trapezoid in φ (nphi)."""
    r, wr = np.polynomial.legendre.leggauss(nr)
    r, wr = 0.5 * (r + 1.0), 0.5 * wr
    phi = (np.arange(nphi) + 0.5) * (2.0 * math.pi / nphi)
    R, P = np.meshgrid(r, phi, indexing="ij")
    x, y = R * np.cos(P), R * np.sin(P)
    vals = interp(rgb, (x + 1.0) * 0.5, (y + 1.0) * 0.5)
    w = (wr * r)[:, None] * (2.0 * math.pi / nphi)
    return np.einsum("rp,rpc->c", w, vals)


def u_of_cos(cos_h):
    """The isotropic tables' axis u = √(1 − cos θ_h)."""
    return np.sqrt(np.clip(1.0 - np.asarray(cos_h, np.float64), 0.0, 1.0))


class Painted:
    """One painted table's continuous function (the image on its own axes, normalized): what the
    baker samples at the texel centres and what the float64 reference evaluates at the samples."""

    def __init__(self, name: str, image: np.ndarray | None = None, shown: str = "<image>"):
        self.name = name
        if image is None and name == "fresnel_ramp":
            self.rgb = None  # computed from material properties
            return
        if image is None:
            shown = display(EXAMPLES / EXAMPLE_FILES[name])
            image = example_image(name)
        self.rgb = check_image(name, image, shown)
        h, w = self.rgb.shape[:2]
        if name in ("ndf_map", "ndf_fresnel_map"):
            self.norm = profile_norm(self.rgb[:1])
        elif name == "ndf_map_anisotropic":
            self.norm = disk_norm(self.rgb)
        if name != "fresnel_ramp":
            self.k_n = 1.0 / (4.0 * self.norm)  # K_N: the table holds K_N p = D / 4

    # the normalized functions, (N, 3)
    def iso(self, cos_h) -> np.ndarray:
        """K_N p(θ_h) at cos θ_h (ndf_map)."""
        return interp(self.rgb, u_of_cos(cos_h)) * self.k_n

    def aniso(self, ht, hb) -> np.ndarray:
        """K_N p at the tangent-plane projection (h·t, h·b) (ndf_map_anisotropic)."""
        return interp(self.rgb, (np.asarray(ht) + 1.0) * 0.5, (np.asarray(hb) + 1.0) * 0.5) * self.k_n

    def ndf_fresnel(self, cos_h, cos_a) -> np.ndarray:
        """K T(θ_h, α_h) at cos θ_h, cos α_h (ndf_fresnel_map)."""
        return interp(self.rgb, u_of_cos(cos_h), 1.0 - np.clip(cos_a, 0.0, 1.0)) * self.k_n

    def ramp(self, cos_a, f0) -> np.ndarray:
        """R_F at cos α_h for normal-incidence reflectance f0 (per channel: f0 (..., 3) or scalar)."""
        c = np.clip(np.asarray(cos_a, np.float64), 0.0, 1.0)
        f0 = np.clip(np.asarray(f0, np.float64), 0.0, 1.0)
        if self.rgb is None:
            cc = c[..., None] if f0.ndim > c.ndim else c
            f = exact.fresnel_dielectric_f0(f0, np.broadcast_to(cc, np.broadcast_shapes(np.shape(cc), f0.shape)))
            return np.where(f0 <= 0.0, 0.0, f)
        x = 1.0 - c
        f0 = np.broadcast_to(f0, c.shape + (3,)) if f0.ndim <= c.ndim else f0
        return np.stack([interp(self.rgb, x, np.sqrt(f0[..., k]))[..., k] for k in range(3)], axis=-1)


_PAINTED: dict[str, Painted] = {}


def painted(name: str) -> Painted:
    """The shipped example of table `name` (cached): what the bricks' references evaluate."""
    if name not in _PAINTED:
        _PAINTED[name] = Painted(name)
    return _PAINTED[name]


def _source(name: str, image) -> Painted:
    """The example (image None), an already checked Painted (bake_painted), or a Painted of the array."""
    if isinstance(image, Painted):
        return image
    return painted(name) if image is None else Painted(name, image)


# ------------------------------------------------------------------ bakers

@table("ndf_map", "K_N p(θ_h) = D/4 of the painted isotropic NDF (Hoffman & Baker 2006, NDF maps), "
       "D = p / ∫ p cos θ_h dω_h, at u = √(1 − n·h)", painted=True,
       sources=(EXAMPLES / EXAMPLE_FILES["ndf_map"],))
def ndf_map(w: int, h: int, image=None) -> np.ndarray:
    """K_N p(θ_h) along u = √(1 − cos θ_h) (one row; rows repeat)."""
    src = _source("ndf_map", image)
    vals = interp(src.rgb, axis(w)) * src.k_n
    out = np.ones((h, w, 4))
    out[..., :3] = vals[None]
    return out


@table("ndf_map_anisotropic", "K_N p(h) = D/4 of the painted anisotropic NDF over (h·t, h·b) "
       "(Hoffman & Baker 2006, NDF maps), ∫∫_disk D dx dy = 1", painted=True,
       sources=(EXAMPLES / EXAMPLE_FILES["ndf_map_anisotropic"],))
def ndf_map_anisotropic(w: int, h: int, image=None) -> np.ndarray:
    """K_N p at x = h·t, y = h·b in [−1, 1] (texel i at −1 + 2i/(W − 1))."""
    src = _source("ndf_map_anisotropic", image)
    x, y = np.meshgrid(axis(w) * 2.0 - 1.0, axis(h) * 2.0 - 1.0)
    out = np.ones((h, w, 4))
    out[..., :3] = src.aniso(x, y)
    return out


@table("ndf_fresnel_map", "K T(θ_h, α_h) of the painted NDF + Fresnel texture (Hoffman & Baker 2006), "
       "row α_h = 0 a unit NDF / 4, at u = √(1 − n·h), v = 1 − l·h", painted=True,
       sources=(EXAMPLES / EXAMPLE_FILES["ndf_fresnel_map"],))
def ndf_fresnel_map(w: int, h: int, image=None) -> np.ndarray:
    """K T at u = √(1 − cos θ_h) (x) and v = 1 − cos α_h (y)."""
    src = _source("ndf_fresnel_map", image)
    u, v = np.meshgrid(axis(w), axis(h))
    out = np.ones((h, w, 4))
    out[..., :3] = interp(src.rgb, u, v) * src.k_n
    return out


@table("fresnel_ramp", "R_F(α_h) per f0: exact dielectric Fresnel at η = (1 + √f0)/(1 − √f0) "
       "(Cook & Torrance 1982), or a painted ramp, at x = 1 − cos α_h, y = √f0", painted=True,
       sources=(EXAMPLES / EXAMPLE_FILES["fresnel_ramp"],))
def fresnel_ramp(w: int, h: int, image=None) -> np.ndarray:
    """R_F at x = 1 − cos α_h, y = √f0 (grey when computed: every channel the same ramp)."""
    src = _source("fresnel_ramp", image)
    x, s = np.meshgrid(axis(w), axis(h))
    c = 1.0 - x
    out = np.ones((h, w, 4))
    f0 = (s * s)[..., None] * np.ones(3)
    out[..., :3] = src.ramp(c, f0)
    return out


# ------------------------------------------------------------------ an engine's own image

def declared(name: str) -> tuple[list[int], str]:
    """(size, format) of table `name` as the built-in brick that samples it declares it."""
    from ..library.bricks import load_library
    for b in load_library().bricks.values():
        for t in b.textures.values():
            if t.get("table") == name:
                return list(t["size"]), t["format"]
    raise LookupError(f"no built-in brick samples table '{name}'")


def bake_painted(name: str, image_path, size=None, fmt: str | None = None) -> np.ndarray:
    """The stored texels of painted table `name` baked from an engine's image file (PNG), at the size
    and format its brick declares (or those given): normalized as the shipped example is. The file is
    validated (readable, channels, size for the table's axes, something painted); errors name it."""
    if name not in EXAMPLE_FILES:
        raise SourceError(str(image_path), 1, 1, f"table '{name}' is not a painted table",
                          f"painted tables: {', '.join(sorted(EXAMPLE_FILES))}")
    img = load_image(image_path)
    d_size, d_fmt = declared(name)
    w, h = (size or d_size)[0], (size or d_size)[1]
    src = Painted(name, img, str(image_path))
    bake = {"ndf_map": ndf_map, "ndf_map_anisotropic": ndf_map_anisotropic, "ndf_fresnel_map": ndf_fresnel_map,
            "fresnel_ramp": fresnel_ramp}[name]
    try:
        return quantize(bake(int(w), int(h), src), fmt or d_fmt)
    except ValueError as e:  # fp16's 65504 (a narrow painted lobe normalizes to large K_N p): name the file
        raise SourceError(str(image_path), 1, 1, f"the normalized table does not fit {fmt or d_fmt}: {e}",
                          "paint a wider lobe, or bake it as fp32 (--texel-format fp32)") from None


# ------------------------------------------------------------------ references of the painted bricks
# The continuous painted functions (normalized in float64), registered for the bricks that sample the
# tables: `accuracy` then measures what the table adds (resampling, filtering, fp16). Imported by
# specular.py (models.REFERENCES is filled when models is imported).

def register_references() -> None:
    from .models import reference  # (here, not at the top: models imports this module while it loads)

    @reference("specular", "ndf_map")
    def ndf_map_ref(g, p: dict, slots: dict) -> np.ndarray:
        """f = R_F(0) K_N p(θ_h) (Hoffman & Baker 2006, NDF maps), p the painted example, K_N p = D/4."""
        return np.asarray(p["f0"], np.float64) * painted("ndf_map").iso(g.NdotH)

    @reference("specular", "ndf_map_anisotropic")
    def ndf_map_anisotropic_ref(g, p: dict, slots: dict) -> np.ndarray:
        """f = R_F(0) K_N p(h·t, h·b) (Hoffman & Baker 2006, 2D NDF maps), the painted example, K_N p = D/4."""
        return np.asarray(p["f0"], np.float64) * painted("ndf_map_anisotropic").aniso(g["HdotT"], g["HdotB"])

    @reference("specular", "ndf_fresnel_map")
    def ndf_fresnel_map_ref(g, p: dict, slots: dict) -> np.ndarray:
        """f = R_F(0) K T(θ_h, α_h) (Hoffman & Baker 2006, NDF + Fresnel texture), the painted example."""
        return np.asarray(p["f0"], np.float64) * painted("ndf_fresnel_map").ndf_fresnel(g.NdotH, g.LdotH)

    @reference("fresnel", "fresnel_ramp")
    def fresnel_ramp_ref(f0, cos_d):
        """R_F(α_h) the ramp is computed from: exact dielectric Fresnel at η(f0) (Cook & Torrance 1982)."""
        f0 = np.asarray(f0, np.float64)
        return painted("fresnel_ramp").ramp(cos_d, f0)
