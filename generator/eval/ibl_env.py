"""Environments for image-based lighting: an equirectangular HDR image (Radiance .hdr) or a procedural sky,
its SH9 irradiance and its GGX-prefiltered radiance cube with a roughness mip chain, in float64 NumPy.

Conventions (world +Y up, as glTF): an equirectangular image of W × H texels maps texel centre (i, j) to
u = (i + ½)/W, v = (j + ½)/H, θ = v π from +Y, φ = (u − ½) 2π, direction (sin θ sin φ, cos θ, −sin θ cos φ):
row 0 is the zenith, the image centre looks down −Z. `Environment.rotation` turns the image about +Y
(radians), `intensity` scales it. Radiance is looked up bilinearly (u wraps, v clamps).

- `read_hdr(path)`: Radiance RGBE (Ward 1991, "Real Pixels"; the format as Radiance's color.c writes it):
  header `#?RADIANCE` or `#?RGBE`, `FORMAT=32-bit_rle_rgbe`, an empty line, `-Y H +X W`; scanlines flat or
  in the new run-length form (2, 2, W >> 8, W & 255, then per channel runs: a count > 128 repeats the next
  byte count − 128 times, otherwise count literal bytes). RGBE → float as Radiance's colr_color:
  (m + ½) 2^(e − 136), 0 for e = 0. Old-style runs (1, 1, 1, n), XYZE and rotated images are refused,
  located.
- `sky(...)`: a deterministic analytic sky (zenith-to-horizon gradient, a darker ground, and a sun disc of
  angular radius 2° with a smoothstep limb), rasterized at 2 × 2 supersamples per texel.
- `sh9(env)`: the real spherical harmonics to l = 2 of the radiance, by the exact solid angle of each texel;
  `sh9_irradiance(coeffs, n)` = Σ Â_l L_lm Y_lm(n), Â = (π, 2π/3, π/4) (Ramamoorthi & Hanrahan 2001 eqs. 8,
  12). Their bound is on the clamped cosine, not on a given environment's irradiance: its energy past
  l = 2 is under 1 %, and the average error is under 3 % for smooth lighting. A small bright source is
  far from that: on the default sky (2° sun) `irradiance_error` measures 15.6 % mean and 83 % largest
  relative error over normals (the sun), which is why the sun is better a light than part of the SH9.
- `prefilter(env, term)`: the split sum's first factor (Karis 2013), Σ L(l) (n·l) / Σ (n·l) over l drawn
  by the term's own sampler (generator.eval.sampling: GGX by visible normals) with **n = v = r** (the
  lobe is not stretched at grazing views: the split sum's known error there); at v = n the visible-normal
  density is D(h)(n·h), the NDF's. Level k of L holds α = (k/(L − 1))² (level 0 the mirror: the radiance
  itself, 4 × 4 supersamples per texel). Each sample reads a box-filtered mip of the equirectangular image
  at lod ½ log2(Ω_s/Ω_p), Ω_s = 1/(K pdf), Ω_p the texel's solid angle (Křivánek & Colbert 2008,
  filtered importance sampling): a sun smaller than the sample spacing is not missed. `cube_error` measures
  a baked chain against a quadrature over every source texel. `write_cube` writes the chain as KTX2
  (io/ktx2.py: six faces +X −X +Y −Y +Z −Z, Vulkan's face orientation, level 0 first).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..lang.errors import SourceError

CUBE_SIZE = 64
GGX_TERM = "microfacet(ndf=ggx,fresnel=none,vis=smith_ggx_height_correlated)"
SUN_RADIUS_DEG = 2.0


# ------------------------------------------------------------------ the Radiance .hdr reader

def read_hdr(path, shown: str | None = None) -> np.ndarray:
    """(H, W, 3) float64 radiance of a Radiance RGBE file; SourceError (path:line:col) for what it cannot read."""
    shown = shown or str(path)
    data = Path(path).read_bytes()
    pos, line = 0, 1

    def fail(msg, hint, ln=None, col=1):
        return SourceError(shown, ln or line, col, msg, hint)

    def next_line():
        nonlocal pos
        end = data.find(b"\n", pos)
        if end < 0:
            raise fail("the header ends before its resolution line", "write the header, an empty line, then '-Y H +X W'")
        text = data[pos:end].rstrip(b"\r")  # a header written with CRLF line ends
        pos = end + 1
        return text

    first = next_line()
    if not (first.startswith(b"#?RADIANCE") or first.startswith(b"#?RGBE")):
        raise fail("not a Radiance HDR file (the first line is not '#?RADIANCE' or '#?RGBE')",
                   "give an RGBE .hdr file")
    exposure = 1.0  # Radiance: pixels were multiplied by every EXPOSURE= value; radiance is pixel / their product
    while True:
        line += 1
        text = next_line()
        if text == b"":
            break
        if text.startswith(b"EXPOSURE="):
            try:
                value = float(text[len(b"EXPOSURE="):].strip())
            except ValueError:
                value = 0.0
            if not (value > 0.0 and math.isfinite(value)):
                raise fail(f"{text.decode('latin-1')!r}: an exposure must be a positive number", "write EXPOSURE=1.0 "
                           "or remove the line", col=len("EXPOSURE=") + 1)
            exposure *= value
        if text.startswith(b"FORMAT=") and text.strip() != b"FORMAT=32-bit_rle_rgbe":
            raise fail(f"{text.decode('latin-1')!r}: only 32-bit_rle_rgbe is read", "convert the image to RGB (not XYZE)")
    line += 1
    res = next_line().split()
    if len(res) != 4 or res[0] != b"-Y" or res[2] != b"+X" or not (res[1].isdigit() and res[3].isdigit()):
        raise fail(f"resolution line {b' '.join(res).decode('latin-1')!r}: only '-Y H +X W' (rows top to bottom) is read",
                   "re-save the image unrotated")
    h, w = int(res[1]), int(res[3])
    if not (0 < w <= 1 << 15 and 0 < h <= 1 << 15):
        raise fail(f"an image of {w} × {h}", "give 1 to 32768 texels per side")
    out = np.empty((h, w, 4), np.uint8)
    for y in range(h):
        where = f"scanline {y} (byte {pos})"
        if pos + 4 > len(data):
            raise fail(f"{where}: the file ends", "the file is truncated: write it again")
        b = data[pos:pos + 4]
        if 8 <= w < 32768 and b[0] == 2 and b[1] == 2 and not b[2] & 0x80:
            if (b[2] << 8 | b[3]) != w:
                raise fail(f"{where}: a run-length scanline of width {b[2] << 8 | b[3]}, not {w}",
                           "the file is damaged: write it again")
            pos += 4
            for c in range(4):
                x = 0
                while x < w:
                    if pos >= len(data):
                        raise fail(f"{where}: the file ends inside channel {c}", "the file is truncated: write it again")
                    n = data[pos]
                    pos += 1
                    if n > 128:
                        n -= 128
                        if x + n > w or pos >= len(data):
                            raise fail(f"{where}: a run of {n} passes the scanline's end", "the file is damaged")
                        out[y, x:x + n, c] = data[pos]
                        pos += 1
                    else:
                        if n == 0 or x + n > w or pos + n > len(data):
                            raise fail(f"{where}: a literal of {n} bytes passes the scanline's end", "the file is damaged")
                        out[y, x:x + n, c] = np.frombuffer(data, np.uint8, n, pos)
                        pos += n
                    x += n
        else:
            if pos + 4 * w > len(data):
                raise fail(f"{where}: the file ends", "the file is truncated: write it again")
            flat = np.frombuffer(data, np.uint8, 4 * w, pos).reshape(w, 4)
            if np.any((flat[:, 0] == 1) & (flat[:, 1] == 1) & (flat[:, 2] == 1)):
                raise fail(f"{where}: an old-style run (1, 1, 1, n)", "re-save the image with a current writer")
            out[y] = flat
            pos += 4 * w
    e = out[..., 3].astype(np.int64)
    scale = np.where(e == 0, 0.0, np.ldexp(1.0, e - 136))
    return (out[..., :3].astype(np.float64) + 0.5) * (scale / exposure)[..., None]


# ------------------------------------------------------------------ directions and lookups

def equirect_dirs(w: int, h: int, sub: int = 1) -> np.ndarray:
    """(h·sub, w·sub, 3) directions of the (sub-)texel centres of a w × h equirectangular image."""
    u = (np.arange(w * sub) + 0.5) / (w * sub)
    v = (np.arange(h * sub) + 0.5) / (h * sub)
    phi, th = (u - 0.5) * 2.0 * np.pi, v * np.pi
    T, P = np.meshgrid(th, phi, indexing="ij")
    return np.stack([np.sin(T) * np.sin(P), np.cos(T), -np.sin(T) * np.cos(P)], -1)


def texel_solid_angles(w: int, h: int) -> np.ndarray:
    """(h,) the exact solid angle of one texel of each row: (2π/w)(cos θ_j − cos θ_{j+1})."""
    edges = np.cos(np.arange(h + 1) * np.pi / h)
    return 2.0 * np.pi / w * (edges[:-1] - edges[1:])


def _bilinear_wrap(img: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    h, w = img.shape[:2]
    x, y = u * w - 0.5, np.clip(v * h - 0.5, 0.0, h - 1.0)
    x0, y0 = np.floor(x), np.floor(y)
    ax, ay = (x - x0)[..., None], (y - y0)[..., None]
    i0, i1 = np.mod(x0, w).astype(np.intp), np.mod(x0 + 1, w).astype(np.intp)
    j0 = y0.astype(np.intp)
    j1 = np.minimum(j0 + 1, h - 1)
    return (img[j0, i0] * (1 - ax) + img[j0, i1] * ax) * (1 - ay) + (img[j1, i0] * (1 - ax) + img[j1, i1] * ax) * ay


@dataclass
class Environment:
    """An equirectangular radiance image (H, W, 3) float64, turned about +Y by `rotation` and scaled."""

    image: np.ndarray
    rotation: float = 0.0
    intensity: float = 1.0
    name: str = "environment"

    def __post_init__(self):
        self.image = np.asarray(self.image, np.float64)
        self._mips = None

    def uv(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = np.asarray(d, np.float64)
        phi = np.arctan2(d[..., 0], -d[..., 2]) - self.rotation
        u = np.mod(phi / (2.0 * np.pi) + 0.5, 1.0)
        v = np.arccos(np.clip(d[..., 1] / np.linalg.norm(d, axis=-1), -1.0, 1.0)) / np.pi
        return u, v

    def radiance(self, d: np.ndarray) -> np.ndarray:
        """(..., 3) radiance towards unit directions d (bilinear)."""
        u, v = self.uv(d)
        return self.intensity * _bilinear_wrap(self.image, u, v)

    def mips(self) -> list[np.ndarray]:
        """The image and its 2 × 2 box-filtered levels down to one row."""
        if self._mips is None:
            levels = [self.image]
            while levels[-1].shape[0] > 1 and levels[-1].shape[1] > 1:
                a = levels[-1]
                h, w = a.shape[0] // 2 * 2, a.shape[1] // 2 * 2
                a = a[:h, :w]
                levels.append(0.25 * (a[0::2, 0::2] + a[1::2, 0::2] + a[0::2, 1::2] + a[1::2, 1::2]))
            self._mips = levels
        return self._mips

    def radiance_lod(self, d: np.ndarray, lod: np.ndarray) -> np.ndarray:
        """Radiance read trilinearly from the box-filtered mips at level `lod` (≥ 0)."""
        u, v = self.uv(d)
        levels = self.mips()
        lod = np.clip(np.asarray(lod, np.float64), 0.0, len(levels) - 1.0)
        k0 = np.floor(lod).astype(np.intp)
        out = np.zeros(u.shape + (3,))
        for k in np.unique(k0):
            sel = k0 == k
            a = (lod[sel] - k)[:, None]
            lo = _bilinear_wrap(levels[k], u[sel], v[sel])
            hi = _bilinear_wrap(levels[min(k + 1, len(levels) - 1)], u[sel], v[sel])
            out[sel] = lo * (1.0 - a) + hi * a
        return self.intensity * out


def sky_radiance(d: np.ndarray, sun_elevation_deg: float = 35.0, sun_azimuth_deg: float = 30.0,
                 sun_radius_deg: float = SUN_RADIUS_DEG, sun: float = 2000.0) -> np.ndarray:
    """(..., 3) the analytic default sky: a zenith-to-horizon gradient (a bluish zenith 0.3, 0.5, 1.0 brightening
    to 1.0, 0.95, 0.9 at the horizon), a ground of 0.12, 0.1, 0.08 below it, and a sun disc of radiance `sun`
    (warm white) with a smoothstep limb over its outer fifth."""
    d = np.asarray(d, np.float64)
    y = d[..., 1]
    t = np.clip(y, 0.0, 1.0) ** 0.5
    zen, hor, gnd = np.array([0.3, 0.5, 1.0]), np.array([1.0, 0.95, 0.9]), np.array([0.12, 0.1, 0.08])
    sky = hor * (1.0 - t[..., None]) + zen * t[..., None]
    ground = gnd * np.ones_like(y)[..., None]
    out = np.where((y >= 0.0)[..., None], sky, ground)
    el, az = np.radians(sun_elevation_deg), np.radians(sun_azimuth_deg)
    s = np.array([np.cos(el) * np.sin(az), np.sin(el), -np.cos(el) * np.cos(az)])
    ang = np.degrees(np.arccos(np.clip(d @ s, -1.0, 1.0)))
    x = np.clip((sun_radius_deg - ang) / (0.2 * sun_radius_deg), 0.0, 1.0)
    disc = x * x * (3.0 - 2.0 * x)
    return out + sun * disc[..., None] * np.array([1.0, 0.95, 0.85])


def sky(width: int = 512, **kwargs) -> Environment:
    """The default sky as an equirectangular Environment of width × width/2 texels (2 × 2 supersamples each)."""
    h = width // 2
    d = equirect_dirs(width, h, 2)
    img = sky_radiance(d, **kwargs).reshape(h, 2, width, 2, 3).mean(axis=(1, 3))
    return Environment(img, name="default sky")


def load(path, rotation: float = 0.0, intensity: float = 1.0) -> Environment:
    """An Environment from a Radiance .hdr file."""
    return Environment(read_hdr(path), rotation, intensity, name=Path(path).name)


# ------------------------------------------------------------------ SH9

def sh_basis(d: np.ndarray) -> np.ndarray:
    """(..., 9) real spherical harmonics Y_00, Y_1-1, Y_10, Y_11, Y_2-2, Y_2-1, Y_20, Y_21, Y_22 of unit d
    (Ramamoorthi & Hanrahan 2001 eq. 3, with their x, y, z = our x, z, y so that z is a direction's +Y here)."""
    x, y, z = d[..., 0], d[..., 2], d[..., 1]
    c0, c1, c2 = 0.5 / np.sqrt(np.pi), np.sqrt(3 / (4 * np.pi)), 0.5 * np.sqrt(15 / np.pi)
    c20, c22 = 0.25 * np.sqrt(5 / np.pi), 0.25 * np.sqrt(15 / np.pi)  # the printed 0.282095, 0.488603, ... exactly
    return np.stack([c0 * np.ones_like(x), c1 * y, c1 * z, c1 * x, c2 * x * y, c2 * y * z, c20 * (3 * z * z - 1),
                     c2 * x * z, c22 * (x * x - y * y)], -1)


SH_A = np.array([np.pi] + [2 * np.pi / 3] * 3 + [np.pi / 4] * 5)


def sh9(env: Environment) -> np.ndarray:
    """(9, 3) L_lm = ∫ L(ω) Y_lm(ω) dω over the image's texels (exact texel solid angles)."""
    h, w = env.image.shape[:2]
    d = equirect_dirs(w, h)
    L = env.radiance(d)
    wgt = np.broadcast_to(texel_solid_angles(w, h)[:, None], (h, w))
    return np.einsum("hwk,hwc,hw->kc", sh_basis(d), L, wgt)


def sh9_irradiance(coeffs: np.ndarray, n: np.ndarray) -> np.ndarray:
    """(..., 3) irradiance E(n) = Σ Â_l L_lm Y_lm(n) (R&H 2001 eq. 12)."""
    return np.einsum("...k,kc->...c", sh_basis(np.asarray(n, np.float64)) * SH_A, coeffs)


def irradiance(env: Environment, n: np.ndarray, chunk: int = 64) -> np.ndarray:
    """(m, 3) brute-force irradiance ∫ L max(0, n·ω) dω over every texel of the image."""
    h, w = env.image.shape[:2]
    d = equirect_dirs(w, h).reshape(-1, 3)
    L = env.radiance(d) * np.repeat(texel_solid_angles(w, h), w)[:, None]
    n = np.atleast_2d(n)
    return np.concatenate([np.maximum(n[i:i + chunk] @ d.T, 0.0) @ L for i in range(0, len(n), chunk)])


def fibonacci_sphere(m: int) -> np.ndarray:
    """m near-uniform unit directions (the spherical Fibonacci lattice)."""
    i = np.arange(m) + 0.5
    y = 1.0 - 2.0 * i / m
    r, phi = np.sqrt(1.0 - y * y), i * np.pi * (3.0 - np.sqrt(5.0))
    return np.stack([r * np.cos(phi), y, r * np.sin(phi)], -1)


def irradiance_error(env: Environment, normals: int = 256) -> dict:
    """SH9 irradiance against the brute-force one over `normals` directions: relative error (per luminance)."""
    n = fibonacci_sphere(normals)
    lum = np.array([0.2126, 0.7152, 0.0722])
    ref, got = irradiance(env, n) @ lum, sh9_irradiance(sh9(env), n) @ lum
    rel = np.abs(got - ref) / np.maximum(ref, 1e-12)
    return {"mean_rel": float(rel.mean()), "max_rel": float(rel.max()), "normals": normals,
            "worst": n[int(np.argmax(rel))].round(4).tolist()}


# ------------------------------------------------------------------ the prefiltered cube

def cube_dirs(size: int, sub: int = 1) -> np.ndarray:
    """(6, S·sub, S·sub, 3) unit directions of the (sub-)texel centres of a cube's faces +X −X +Y −Y +Z −Z
    (Vulkan's cube face selection: s = (sc/|ma| + 1)/2 along a row, t = (tc/|ma| + 1)/2 down the rows)."""
    n = size * sub
    s = 2.0 * (np.arange(n) + 0.5) / n - 1.0
    tc, sc = np.meshgrid(s, s, indexing="ij")
    one = np.ones_like(sc)
    faces = [(one, -tc, -sc), (-one, -tc, sc), (sc, one, tc), (sc, -one, -tc), (sc, -tc, one), (-sc, -tc, -one)]
    d = np.stack([np.stack(f, -1) for f in faces])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def level_alpha(level: int, levels: int) -> float:
    """α of mip `level` of `levels`: (level/(levels − 1))²; a shader reads lod = √α (levels − 1)."""
    return (level / (levels - 1)) ** 2 if levels > 1 else 0.0


def _lattice(n: int) -> np.ndarray:
    i = np.arange(n, dtype=np.float64)
    return np.stack([(i + 0.5) / n, np.mod(i * 0.6180339887498949, 1.0)], -1)


def _frames(r: np.ndarray) -> np.ndarray:
    from .sampling import frame
    return frame(r)[0]


def prefilter_dirs(env: Environment, r: np.ndarray, alpha: float, samples: int, term: str = GGX_TERM,
                   lib=None, chunk: int = 1 << 17) -> np.ndarray:
    """(m, 3) Σ L(l)(n·l) / Σ (n·l) at directions r with n = v = r, l from the term's sampler (lattice points),
    each read at the filtered-importance-sampling lod."""
    from . import sampling
    u = _lattice(samples)
    h, w = env.image.shape[:2]
    out = np.zeros((len(r), 3))
    per = max(1, chunk // samples)
    for i in range(0, len(r), per):
        R = np.repeat(r[i:i + per], samples, axis=0)
        T = _frames(R)
        U = np.tile(u, (len(R) // samples, 1))
        L = sampling.sample(term, U, R, R, T, {"alpha": alpha}, lib=lib)
        p = sampling.pdf(term, L, R, R, T, {"alpha": alpha}, lib=lib)
        nl = np.einsum("ij,ij->i", L, R)
        ok = (p > 0.0) & (nl > 0.0)
        sin_t = np.sqrt(np.maximum(1.0 - L[:, 1] ** 2, 1e-8))
        omega_p = (2.0 * np.pi / w) * (np.pi / h) * sin_t
        lod = 0.5 * np.log2(np.maximum(1.0 / (samples * np.where(ok, p, 1.0) * omega_p), 1.0))
        rad = env.radiance_lod(L, lod)
        wgt = np.where(ok, nl, 0.0)
        num = (rad * wgt[:, None]).reshape(-1, samples, 3).sum(axis=1)
        out[i:i + per] = num / np.maximum(wgt.reshape(-1, samples).sum(axis=1), 1e-30)[:, None]
    return out


def level_samples(texels: int, budget: int = 1 << 20) -> int:
    """Samples per texel at a level of `texels` texels: the budget shared, a power of two in [256, 65536]."""
    k = 1 << max(0, int(np.ceil(np.log2(max(budget // texels, 1)))))
    return int(min(max(k, 256), 65536))


def prefilter(env: Environment, size: int = CUBE_SIZE, term: str = GGX_TERM, lib=None,
              budget: int = 1 << 20) -> list[np.ndarray]:
    """The prefiltered radiance cube, level 0 (S × S, the mirror) to 1 × 1, each (6, s, s, 3) float64; each
    level ≥ 1 draws about `budget` samples in all (level_samples: at least 256 per texel)."""
    from ..io.ktx2 import full_level_count
    levels = full_level_count(size, size)
    out = [env.radiance(cube_dirs(size, 4)).reshape(6, size, 4, size, 4, 3).mean(axis=(2, 4))]
    for k in range(1, levels):
        s = max(1, size >> k)
        r = cube_dirs(s).reshape(-1, 3)
        n = level_samples(len(r), budget)
        out.append(prefilter_dirs(env, r, level_alpha(k, levels), n, term, lib).reshape(6, s, s, 3))
    return out


def prefilter_reference(env: Environment, r: np.ndarray, alpha: float, term: str = GGX_TERM,
                        lib=None) -> np.ndarray:
    """(m, 3) the prefiltered integral at directions r by quadrature over every source texel (no sampler):
    Σ L p(l) (n·l) dω / Σ p(l) (n·l) dω, p the term's sampling density with n = v = r."""
    from . import sampling
    h, w = env.image.shape[:2]
    d = equirect_dirs(w, h).reshape(-1, 3)
    L = env.radiance(d)
    dw = np.repeat(texel_solid_angles(w, h), w)
    out = np.zeros((len(r), 3))
    for i, ri in enumerate(r):
        R = np.broadcast_to(ri, d.shape)
        p = sampling.pdf(term, d, R, R, _frames(np.ascontiguousarray(R)), {"alpha": alpha}, lib=lib)
        wgt = p * np.maximum(d @ ri, 0.0) * dw
        out[i] = wgt @ L / wgt.sum()
    return out


def cube_lookup(levels: list[np.ndarray], d: np.ndarray, lod) -> np.ndarray:
    """(m, 3) the cube read at unit directions d (m, 3): bilinear within a face (clamped at its edges, no
    seamless filtering across faces), linear between the two levels around `lod`."""
    d = np.atleast_2d(d)
    lod = np.broadcast_to(np.clip(np.asarray(lod, np.float64), 0.0, len(levels) - 1.0), (len(d),))
    ax = np.abs(d)
    major = np.argmax(ax, axis=1)
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    face = np.where(major == 0, np.where(x > 0, 0, 1), np.where(major == 1, np.where(y > 0, 2, 3),
                                                                 np.where(z > 0, 4, 5)))
    ma = ax[np.arange(len(d)), major]
    sc = np.choose(face, [-z, z, x, x, x, -x])
    tc = np.choose(face, [-y, -y, z, -z, -y, -y])
    s, t = (sc / ma + 1) / 2, (tc / ma + 1) / 2

    def at(level, k):
        n = level.shape[1]
        fx, fy = np.clip(s * n - 0.5, 0, n - 1), np.clip(t * n - 0.5, 0, n - 1)
        x0, y0 = np.floor(fx).astype(np.intp), np.floor(fy).astype(np.intp)
        x1, y1 = np.minimum(x0 + 1, n - 1), np.minimum(y0 + 1, n - 1)
        a, b = (fx - x0)[:, None], (fy - y0)[:, None]
        return ((level[face, y0, x0] * (1 - a) + level[face, y0, x1] * a) * (1 - b)
                + (level[face, y1, x0] * (1 - a) + level[face, y1, x1] * a) * b)

    k0 = np.floor(lod).astype(np.intp)
    k1 = np.minimum(k0 + 1, len(levels) - 1)
    f = (lod - k0)[:, None]
    out = np.zeros((len(d), 3))
    for k in np.unique(k0):
        sel = k0 == k
        lo = at(levels[k], k)[sel]
        hi = at(levels[int(k1[sel][0])], k)[sel]
        out[sel] = lo * (1 - f[sel]) + hi * f[sel]
    return out


def cube_error(env: Environment, levels: list[np.ndarray], directions: int = 24, term: str = GGX_TERM,
               lib=None) -> list[dict]:
    """Per level ≥ 1: the baked texels at `directions` texel centres against prefilter_reference (relative
    error of the luminance): mean and max."""
    lum = np.array([0.2126, 0.7152, 0.0722])
    rows = []
    for k in range(1, len(levels)):
        s = levels[k].shape[1]
        flat = levels[k].reshape(-1, 3)
        r = cube_dirs(s).reshape(-1, 3)
        pick = np.linspace(0, len(r) - 1, min(directions, len(r))).round().astype(np.intp)
        ref = prefilter_reference(env, r[pick], level_alpha(k, len(levels)), term, lib) @ lum
        rel = np.abs(flat[pick] @ lum - ref) / np.maximum(ref, 1e-12)
        rows.append({"level": k, "alpha": level_alpha(k, len(levels)), "size": s,
                     "samples": level_samples(len(r)), "mean_rel": float(rel.mean()), "max_rel": float(rel.max())})
    return rows


def rgba(level: np.ndarray) -> np.ndarray:
    out = np.ones(level.shape[:-1] + (4,))
    out[..., :3] = level
    return out


def encode_cube(levels: list[np.ndarray], fmt: str = "fp16") -> bytes:
    """The KTX2 bytes of a prefiltered chain (RGBA, alpha 1): fp16 (radiance up to 65504) or fp32."""
    from ..io.ktx2 import encode_levels
    from ..reference.tables import quantize
    return encode_levels([quantize(rgba(x), fmt) for x in levels], fmt, cube=True, writer="shadermatrix")


def write_cube(path, levels: list[np.ndarray], fmt: str = "fp16") -> bool:
    """Write the chain as a KTX2 cube atomically; False when the file already holds these bytes."""
    from ..io import atomic_write
    return atomic_write(Path(path), encode_cube(levels, fmt))
