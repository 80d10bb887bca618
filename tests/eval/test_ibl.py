"""Image-based lighting's tables and environments (generator/eval/ibl_*.py) against independent integrals."""
from __future__ import annotations

import math
import struct
import time

import numpy as np
import pytest

from generator.eval import ibl_accuracy, ibl_env, ibl_tables, plausibility
from generator.io import ktx2
from generator.lang.errors import SourceError

GGX = "microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"
BECKMANN = "microfacet(ndf=beckmann,fresnel=schlick,vis=smith_beckmann)"


@pytest.mark.parametrize("spec", [GGX, BECKMANN])
@pytest.mark.parametrize("mu,alpha", [(1.0, 0.3), (0.5, 0.05), (0.2, 0.6), (0.05, 0.9)])
def test_scale_and_bias_match_an_independent_quadrature(spec, mu, alpha):
    # the sampler-driven integral against plausibility's graded (θ, φ) quadrature, no sampler involved
    e = ibl_tables._integrals(spec, np.array([mu]), alpha, ibl_tables._golden_lattice(ibl_tables.SAMPLES),
                              (0.0, 1.0), None)[:, 0]
    theta = math.degrees(math.acos(mu))
    for k, f0 in enumerate((0.0, 1.0)):
        want = plausibility.furnace(spec, None, {"alpha": alpha, "f0": f0}, theta)[0]
        assert abs(e[k] - want) <= 1e-3 * max(want, 0.05), (f0, e[k], want)


def test_diffuse_channel_closed_form_at_zero_roughness():
    # α → 0: the facet is the surface and ∫ F_diff cos/π = (1 − f0)(1 − (1 − μ)^5) (21/20 normalizes eq. 6)
    mu = np.array([0.1, 0.3, 0.7, 1.0])
    got = ibl_tables.diffuse_albedo(mu, 1e-3)
    assert np.allclose(got, 1.0 - (1.0 - mu) ** 5, rtol=2e-3)


def test_diffuse_channel_against_the_reference_model_by_brute_force():
    # eq. 4 from reference/diffuse.py (its own quadrature), integrated over l on a plain grid
    from generator.reference.diffuse import microfacet_diffuse
    mu, alpha = 0.6, 0.5
    c, wc = plausibility.gauss_legendre(0.0, 1.0, 24)
    p, wp = plausibility.gauss_legendre(0.0, math.pi, 24)
    C, P = (a.ravel() for a in np.meshgrid(c, p, indexing="ij"))
    f = microfacet_diffuse(C, np.full_like(C, mu), np.cos(P), alpha, f0=0.0, n_t=48, n_phi=96)
    want = float(np.sum(f * C * 2.0 * np.outer(wc, wp).ravel()))
    assert abs(ibl_tables.diffuse_albedo([mu], alpha)[0] - want) < 2e-4 * want


def test_classification_and_located_refusals():
    how = {t.brick: t.how for t in ibl_tables.classify("gotanda_fitted+" + GGX)}
    assert how == {"gotanda_fitted": "gotanda_eq4", "microfacet": "ambient_brdf"}
    with pytest.raises(ibl_tables.IblRefusal, match=r"^scene.toml:3:9: .*not a microfacet term"):
        ibl_tables.ambient_brdf("lambert+phong_normalized", where="scene.toml:3:9", store=False)
    with pytest.raises(ibl_tables.IblRefusal, match=r"^scene.toml:4:2: brdf term 'oren_nayar': .*no ambient table"):
        ibl_tables.ambient_brdf("oren_nayar+" + GGX, where="scene.toml:4:2", store=False)
    lam = ibl_tables.ambient_brdf("lambert+" + GGX, size=(4, 4), samples=64, store=False)
    bare = ibl_tables.ambient_brdf(GGX, size=(4, 4), samples=64, store=False)
    assert (lam.texels[..., 2] == 1.0).all() and (bare.texels[..., 2] == 0.0).all()  # B: Lambert's 1, none's 0
    assert lam.key != bare.key and np.array_equal(lam.texels[..., :2], bare.texels[..., :2])
    with pytest.raises(ibl_tables.IblRefusal, match="reads eta, k"):
        ibl_tables.ambient_brdf("microfacet(ndf=ggx,fresnel=conductor_exact,vis=smith_ggx_height_correlated)",
                                store=False)
    with pytest.raises(ibl_tables.IblRefusal, match="anisotropic"):
        ibl_tables.ambient_brdf("microfacet(ndf=ggx_anisotropic,fresnel=schlick,vis=smith_ggx_height_correlated_anisotropic)",
                                store=False)


def test_a_fresnel_not_affine_in_f0_is_refused():
    spec = "microfacet(ndf=ggx,fresnel=dielectric_exact,vis=smith_ggx_height_correlated)"
    with pytest.raises(ibl_tables.IblRefusal, match="not affine in f0"):
        ibl_tables._specular_texels(spec, (3, 3), 256, None, "scene.toml:1:1")
    # a Schlick term passes the same check
    ibl_tables._specular_texels(GGX, (3, 3), 256, None, "")


def test_white_furnace_split_sum_equals_directional_albedo():
    # a constant environment of 1: every prefiltered level is 1, so split sum × (f0 = 1) = R + G = E(v)
    env = ibl_env.Environment(np.ones((32, 64, 3)))
    cube = ibl_env.prefilter(env, 8)
    assert all(np.allclose(level, 1.0, atol=1e-12) for level in cube)
    for mu, alpha in ((0.9, 0.2), (0.3, 0.5)):
        e = ibl_tables._integrals(GGX, np.array([mu]), alpha, ibl_tables._golden_lattice(4096), (0.0, 1.0), None)
        r = np.array([0.0, 1.0, 0.0])
        pre = ibl_env.cube_lookup(cube, r[None], math.sqrt(alpha) * (len(cube) - 1))[0]
        want = plausibility.furnace(GGX, None, {"alpha": alpha, "f0": 1.0}, math.degrees(math.acos(mu)))[0]
        assert abs(pre[0] * e[1, 0] - want) < 1e-3 * want


# ------------------------------------------------------------------ the RGBE reader

def _rgbe(rgb):
    """One float triple as Radiance's float2rgbe does it (frexp of the largest, mantissa × 256)."""
    v = max(rgb)
    if v < 1e-32:
        return bytes(4)
    m, e = math.frexp(v)
    s = m * 256.0 / v
    return bytes([int(c * s) for c in rgb] + [e + 128])


def _rle_channel(values: bytes) -> bytes:
    """Radiance's new run-length channel encoding, written from the format's description (runs of >= 4)."""
    out, i = bytearray(), 0
    while i < len(values):
        j = i
        while j < len(values) and values[j] == values[i] and j - i < 127:
            j += 1
        if j - i >= 4:
            out += bytes([128 + j - i, values[i]])
            i = j
        else:
            k = i
            while k < len(values) and k - i < 128 and not (k + 3 < len(values) and values[k] == values[k + 1] ==
                                                            values[k + 2] == values[k + 3]):
                k += 1
            k = max(k, i + 1)
            out += bytes([k - i]) + values[i:k]
            i = k
    return bytes(out)


def _hdr(pixels, rle: bool) -> bytes:
    h, w = len(pixels), len(pixels[0])
    out = bytearray(b"#?RADIANCE\n# hand-written\nFORMAT=32-bit_rle_rgbe\n\n" + f"-Y {h} +X {w}\n".encode())
    for row in pixels:
        enc = [_rgbe(p) for p in row]
        if rle:
            out += bytes([2, 2, w >> 8, w & 255])
            for c in range(4):
                out += _rle_channel(bytes(e[c] for e in enc))
        else:
            out += b"".join(enc)
    return bytes(out)


@pytest.mark.parametrize("rle", [False, True])
def test_rgbe_reader_reads_a_hand_written_file(tmp_path, rle):
    w, h = 12, 3
    pixels = [[(0.0, 0.0, 0.0) if x < 5 else (1.0, 0.5, 0.25 * y) if x < 9 else (3.0 + x, 100.0, 1e-3)
               for x in range(w)] for y in range(h)]
    path = tmp_path / "sky.hdr"
    path.write_bytes(_hdr(pixels, rle))
    got = ibl_env.read_hdr(path)
    assert got.shape == (h, w, 3)
    want = np.array(pixels)
    # RGBE keeps 8 bits of mantissa relative to the largest channel of the texel
    tol = np.maximum(want.max(axis=-1, keepdims=True), 1e-30) / 128.0
    assert np.all(np.abs(got - want) <= tol)
    assert np.all(got[:, :5] == 0.0)


def test_rgbe_reader_divides_by_exposure_and_reads_crlf_headers(tmp_path):
    pixels = [[(1.0, 0.5, 0.25)] * 8]
    plain = _hdr(pixels, True)
    head, _, body = plain.partition(b"FORMAT=32-bit_rle_rgbe\n")
    p = tmp_path / "e.hdr"
    p.write_bytes(head.replace(b"\n", b"\r\n") + b"EXPOSURE=2.0\r\nFORMAT=32-bit_rle_rgbe\r\nEXPOSURE=4\r\n"
                  + body.replace(b"\n", b"\r\n", 1))
    (tmp_path / "p.hdr").write_bytes(plain)
    assert np.array_equal(ibl_env.read_hdr(p) * 8.0, ibl_env.read_hdr(tmp_path / "p.hdr"))  # pixel / (2 x 4)
    p.write_bytes(head + b"EXPOSURE=-1\n" + b"FORMAT=32-bit_rle_rgbe\n" + body)
    with pytest.raises(SourceError, match=r"e.hdr:3:10: .*positive number"):
        ibl_env.read_hdr(p)


def test_rgbe_reader_refuses_with_a_location(tmp_path):
    p = tmp_path / "bad.hdr"
    p.write_bytes(b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\0\0\0\0")
    with pytest.raises(SourceError, match=r"bad.hdr:2:1: .*32-bit_rle_rgbe.* — "):
        ibl_env.read_hdr(p)
    p.write_bytes(b"#?RADIANCE\n\n+Y 1 +X 1\n\0\0\0\0")
    with pytest.raises(SourceError, match=r"bad.hdr:3:1: .*'-Y H \+X W'"):
        ibl_env.read_hdr(p)
    p.write_bytes(b"#?RADIANCE\n\n-Y 2 +X 1\n\0\0\0\0")
    with pytest.raises(SourceError, match="scanline 1 .*ends"):
        ibl_env.read_hdr(p)


# ------------------------------------------------------------------ SH9

def _analytic(fn, w=256):
    d = ibl_env.equirect_dirs(w, w // 2)
    return ibl_env.Environment(np.repeat(fn(d)[..., None], 3, axis=-1))


def test_sh9_of_a_constant_environment():
    env = _analytic(lambda d: np.full(d.shape[:-1], 2.0))
    c = ibl_env.sh9(env)[:, 0]
    # exact texel solid angles make L_00 exact; Y_20 read at texel centres is off by O(1/H²)
    assert abs(c[0] - 2.0 * math.sqrt(4 * math.pi)) < 1e-9 and np.abs(c[1:]).max() < 1e-3
    n = ibl_env.fibonacci_sphere(16)
    assert np.allclose(ibl_env.sh9_irradiance(ibl_env.sh9(env), n), 2.0 * math.pi, rtol=1e-4)


def test_sh9_of_a_clamped_cosine_lobe():
    # L = max(0, ω·y): zonal coefficients 2π sqrt((2l+1)/4π) ∫0^1 c P_l(c) dc = √π/2, √(π/3), √(5π)/8
    env = _analytic(lambda d: np.maximum(d[..., 1], 0.0), w=512)
    c = ibl_env.sh9(env)[:, 0]
    want = np.zeros(9)
    want[0], want[2], want[6] = math.sqrt(math.pi) / 2, math.sqrt(math.pi / 3), math.sqrt(5 * math.pi) / 8
    assert np.abs(c - want).max() < 2e-4
    # a linear lobe a + b ω·y is all l <= 1: its SH9 irradiance is exact, π a + (2π/3) b n·y
    env = _analytic(lambda d: 1.0 + 0.5 * d[..., 1], w=512)
    n = ibl_env.fibonacci_sphere(32)
    got = ibl_env.sh9_irradiance(ibl_env.sh9(env), n)[:, 0]
    assert np.allclose(got, math.pi + 2 * math.pi / 3 * 0.5 * n[:, 1], rtol=1e-4)


# ------------------------------------------------------------------ the cube

def test_prefiltered_cube_round_trips_through_ktx2(tmp_path):
    env = ibl_env.sky(64)
    levels = ibl_env.prefilter(env, 8)
    assert [lv.shape[1] for lv in levels] == [8, 4, 2, 1]
    path = tmp_path / "env.ktx2"
    assert ibl_env.write_cube(path, levels, "fp32")
    back, fmt, cube = ktx2.decode_levels(path.read_bytes())
    assert fmt == "fp32" and cube and len(back) == 4
    for a, b in zip(levels, back):
        assert np.array_equal(b[..., :3], a.astype(np.float32)) and np.all(b[..., 3] == 1.0)
    assert not ibl_env.write_cube(path, levels, "fp32")  # unchanged bytes: not rewritten


def test_cube_faces_follow_vulkan_selection():
    d = ibl_env.cube_dirs(4)
    major = [(0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1)]
    for f, (axis, sign) in enumerate(major):
        assert np.all(np.sign(d[f][..., axis]) == sign) and np.all(np.abs(d[f][..., axis]) >= np.abs(d[f]).max(-1) - 1e-12)
    # +Z face: s grows with +x, t (rows) with -y (Vulkan's table: sc = +rx, tc = -ry)
    assert d[4, 0, -1, 0] > 0 and d[4, 0, 0, 1] > 0 and d[4, -1, 0, 1] < 0
    assert np.allclose(ibl_env.cube_lookup([d], d.reshape(-1, 3), 0.0), d.reshape(-1, 3))


def test_prefiltered_level_against_texel_quadrature():
    env = ibl_env.sky(128, sun=0.0)
    r = ibl_env.fibonacci_sphere(6)
    got = ibl_env.prefilter_dirs(env, r, 0.25, 1024)
    want = ibl_env.prefilter_reference(env, r, 0.25)
    assert np.abs(got - want).max() < 0.01 * want.max()


def test_split_sum_and_sh9_on_a_sunless_sky_are_within_a_few_percent():
    env = ibl_env.sky(128, sun=0.0)
    res = ibl_accuracy.ibl_accuracy(env, roughness=(0.2,), views_deg=(0.0, 45.0), samples=1 << 12,
                                    cube=ibl_env.prefilter(env, 16))
    for row in res["rows"]:
        assert abs(row["spec_err"]) < 0.03 + 3 * row["spec_std"], row
        assert abs(row["diff_err"]) < 0.03 + 3 * row["diff_std"], row
        assert abs(row["lambert_err"]) > abs(row["diff_err"])  # the diffuse channel's gain


@pytest.mark.slow
def test_full_table_bake_time_and_convergence():
    start = time.perf_counter()
    t = ibl_tables.ambient_brdf("gotanda_fitted+" + GGX, store=False)
    assert time.perf_counter() - start < 60.0  # 30 s alone on this machine; shared cores leave slack
    assert t.texels.shape == (32, 32, 4) and np.isfinite(t.texels).all()
    conv = ibl_tables.convergence("gotanda_fitted+" + GGX)
    assert conv["scale"] < 1e-3 and conv["bias"] < 1e-3 and conv["diffuse"] < 1e-3


def test_rgbe_long_runs_of_a_wide_scanline(tmp_path):
    # the run-length scanline marker: 2, 2, then the width as a big-endian 16-bit number; runs of 127
    data = _hdr([[(1.0, 1.0, 1.0)] * 300], rle=True)
    start = data.index(b"+X 300\n") + len(b"+X 300\n")
    assert data[start:start + 2] == b"\x02\x02" and struct.unpack(">H", data[start + 2:start + 4])[0] == 300
    (tmp_path / "w.hdr").write_bytes(data)
    got = ibl_env.read_hdr(tmp_path / "w.hdr")
    assert got.shape == (1, 300, 3) and np.allclose(got, 1.0, rtol=1 / 128)
