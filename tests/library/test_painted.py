"""Hand-painted BRDFs: NDF maps, Fresnel ramp, NDF + Fresnel map
(generator/reference/tables_painted.py; bricks ndf_map, ndf_map_anisotropic, ndf_fresnel_map, fresnel_ramp)."""
from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from generator.lang import SourceError
from generator.reference import tables, tables_painted as tp
from generator.reference.models import reference_brdf
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

REPO = Path(__file__).resolve().parents[2]
PAINTED_SPECS = ["ndf_map", "ndf_map_anisotropic", "ndf_fresnel_map", "microfacet(fresnel=fresnel_ramp)"]


def _sphere(n_theta: int, n_phi: int):
    """Midpoint nodes of the upper hemisphere in (θ, φ): unit vectors (n_θ, n_φ, 3) and dω weights."""
    t = (np.arange(n_theta) + 0.5) * (0.5 * math.pi / n_theta)
    p = (np.arange(n_phi) + 0.5) * (2.0 * math.pi / n_phi)
    T, P = np.meshgrid(t, p, indexing="ij")
    h = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    return h, np.sin(T) * (0.5 * math.pi / n_theta) * (2.0 * math.pi / n_phi)


def test_k_n_normalizes_the_painted_ndfs():
    """∫ D cos θ_h dω_h = 1, D = 4 K_N p, by an independent quadrature over the hemisphere of h (midpoint
    in θ_h and φ_h, not the Gauss-Legendre / polar rules the generator uses): within 1e-4 (the midpoint
    rule on the piecewise-linear painting; measured 4e-8 isotropic, 1.2e-5 anisotropic at 512²)."""
    t = (np.arange(20000) + 0.5) * (0.5 * math.pi / 20000)
    dth = 0.5 * math.pi / 20000
    for name, f in (("ndf_map", lambda c: tp.painted("ndf_map").iso(c)),
                    ("ndf_fresnel_map", lambda c: tp.painted("ndf_fresnel_map").ndf_fresnel(c, np.ones_like(c)))):
        D = 4.0 * f(np.cos(t))
        total = 2.0 * math.pi * np.einsum("n,nc->c", np.cos(t) * np.sin(t) * dth, D)
        assert np.abs(total - 1.0).max() < 1e-4, (name, total)
    h, dw = _sphere(512, 512)
    D = 4.0 * tp.painted("ndf_map_anisotropic").aniso(h[..., 0], h[..., 1])
    total = np.einsum("ij,ijc->c", dw * h[..., 2], D)
    assert np.abs(total - 1.0).max() < 1e-4, total


def _albedo(D_of_h, views, n=512):
    """R(v) = ∫ D(h) (h·v) (n·l)⁺ dω_h for f = D/4 (dω_l = 4 (h·v) dω_h), per view."""
    h, dw = _sphere(n, n)
    D = D_of_h(h)
    out = []
    for v in views:
        hv = h @ v
        nl = 2.0 * hv * h[..., 2] - v[2]
        m = (hv > 0.0) & (nl > 0.0)
        out.append(np.einsum("ij,ij...->...", dw * hv * nl * m, D))
    return np.array(out)


def _views(k=7):
    th = np.linspace(0.0, 0.49 * math.pi, k)
    return [np.array([math.sin(a) * math.cos(p), math.sin(a) * math.sin(p), math.cos(a)])
            for a in th for p in (0.0, 0.25 * math.pi, 0.5 * math.pi)]


def test_directional_albedo_stays_within_1():
    """White furnace at R_F(0) = 1: the normalized NDF terms reflect at most what arrives, on the shipped
    maps, a Blinn-Phong-like painted lobe and rings of facets up to θ_h ≈ 88° (the worst shapes for the
    microfacet normalization with the implicit visibility). Quadrature error of the 512² grid: < 1e-3."""
    views = _views()
    albedo = {"ndf_map": _albedo(lambda h: 4.0 * tp.painted("ndf_map").iso(h[..., 2]), views),
              "ndf_map_anisotropic": _albedo(lambda h: 4.0 * tp.painted("ndf_map_anisotropic").aniso(h[..., 0], h[..., 1]),
                                             views)}
    u = np.linspace(0.0, 1.0, 256)
    for label, prof in (("cos^64", np.cos(np.arccos(1.0 - u * u)) ** 64), ("ring 60°", np.exp(-((u - 0.707) / 0.03) ** 2)),
                        ("ring 88°", np.exp(-((u - 0.99) / 0.01) ** 2))):
        img = np.ones((1, 256, 4))
        img[0, :, :3] = prof[:, None]
        p = tp.Painted("ndf_map", img)
        albedo[label] = _albedo(lambda h, p=p: 4.0 * p.iso(h[..., 2]), views)
    for label, a in albedo.items():
        assert a.max() <= 1.0 + 1e-3, (label, a.max())
    assert albedo["ndf_map"].max() > 0.5  # not trivially small: the sharp core reflects most at normal incidence


def test_painted_brdfs_are_reciprocal():
    """f(l, v) = f(v, l) in the reference and in the NumPy emission of the bricks (float32 inputs)."""
    from generator.eval.evaluate import evaluate

    rng = np.random.default_rng(13)

    def dirs(n):
        d = rng.normal(size=(n, 3))
        d[:, 2] = np.abs(d[:, 2]) + 0.05
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    L, V = dirs(400), dirs(400)
    N = np.tile([0.0, 0.0, 1.0], (400, 1))
    T = np.tile([1.0, 0.0, 0.0], (400, 1))
    for spec in PAINTED_SPECS:
        a, b = reference_brdf(spec, L, V, N, T), reference_brdf(spec, V, L, N, T)
        assert np.allclose(a, b, rtol=1e-12, atol=0.0), spec
        ga = evaluate(spec, L, V, N, T, target="numpy", dtype="float32")
        gb = evaluate(spec, V, L, N, T, target="numpy", dtype="float32")
        assert np.allclose(ga, gb, rtol=1e-5, atol=1e-7 * np.abs(ga).max()), spec


def test_the_baked_tables_are_the_paintings_times_k_n():
    """At the shipped size the table is the painting's pixels × K_N (no resampling), fp16-rounded; an
    engine's file baked through bake_painted gives the same bytes as the shipped default."""
    for name, brick_size in (("ndf_map", (64, 1)), ("ndf_map_anisotropic", (64, 64)), ("ndf_fresnel_map", (64, 32))):
        p = tp.painted(name)
        stored = tables.baked(name, brick_size, "fp16")
        want = p.rgb * p.k_n
        assert np.abs(tables.decoded(stored)[..., :3] - want).max() <= 2.0 ** -11 * want.max(), name
        path = tp.EXAMPLES / tp.EXAMPLE_FILES[name]
        assert tables.sha256(tp.bake_painted(name, path)) == tables.sha256(stored), name
    ramp = tables.decoded(tables.baked("fresnel_ramp", (64, 32), "fp16"))
    assert ramp[0, :, 0].max() == 0.0 and abs(ramp[-1, 0, 0] - 1.0) < 1e-3  # f0 = 0: no interface; f0 = 1: mirror
    gold = tp.bake_painted("fresnel_ramp", tp.EXAMPLES / "fresnel_ramp.png")
    assert np.allclose(tables.decoded(gold)[0], tables.decoded(gold)[-1])  # a one-row ramp: every f0 alike


def test_the_example_paintings_are_what_the_script_writes():
    spec = importlib.util.spec_from_file_location("paint_examples", REPO / "scripts" / "paint_examples.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for name in ("ndf_map", "ndf_map_anisotropic", "ndf_fresnel_map", "fresnel_ramp"):
        want = mod._u8(getattr(mod, name)())
        got = np.round(tp.example_image(name) * 255.0).astype(np.uint8)
        got = got[..., 0] if want.ndim == 2 else got[..., :3]
        assert np.array_equal(got, want), name


@pytest.mark.parametrize("content, words", [
    (b"not a png", "not an image"),
    ("two_rows", "must be one row"),
    ("black", "0 everywhere"),
])
def test_a_bad_image_is_an_error_naming_the_file(content, words, tmp_path):
    from PIL import Image

    path = tmp_path / "mine.png"
    if content == "two_rows":
        Image.fromarray(np.full((2, 8, 3), 200, np.uint8), "RGB").save(path)
    elif content == "black":
        Image.fromarray(np.zeros((1, 8, 3), np.uint8), "RGB").save(path)
    else:
        path.write_bytes(content)
    with pytest.raises(SourceError, match=words) as e:
        tp.bake_painted("ndf_map", path)
    assert str(e.value).startswith(f"{path}:1:1: ")
    with pytest.raises(SourceError, match="no such image"):
        tp.bake_painted("ndf_map", tmp_path / "missing.png")
    with pytest.raises(SourceError, match="not a painted table"):
        tp.bake_painted("oren_nayar_sin_sin", path)


def test_a_16_bit_grey_png_loads_to_0_1_and_a_32_bit_image_is_refused(tmp_path):
    """16-bit grey ("I;16" here; older Pillow opens such a PNG as "I", read as the same 0 … 65535) is scaled by
    1/65535, not 1/(2^32 − 1) (which loaded it almost black); 32-bit integer grey is an error naming the file."""
    from PIL import Image

    words = np.array([[0, 1, 257, 32768, 65535]], np.uint16)
    path = tmp_path / "grey16.png"
    Image.fromarray(words).save(path)  # mode "I;16": a 16-bit grey PNG
    want = np.repeat((words / 65535.0)[..., None], 3, -1)
    got = tp.load_image(path)
    np.testing.assert_array_equal(got[..., :3], want)
    np.testing.assert_array_equal(got[..., 3], 1.0)
    with Image.open(path) as im:
        assert im.mode in ("I;16", "I") and im.format == "PNG"
        np.testing.assert_array_equal(tp._rgba(im.convert("I"), "PNG", str(path)), got)  # older Pillow's mode
    tif = tmp_path / "grey32.tif"
    Image.fromarray(words.astype(np.int32) * 256).save(tif)  # mode "I": 32-bit signed (up to 2^24 here)
    with pytest.raises(SourceError, match="32-bit integer grey") as e:
        tp.load_image(tif)
    assert str(e.value).startswith(f"{tif}:1:1: ")


def test_the_painted_bricks_pass_accuracy_in_numpy():
    from generator.eval import accuracy
    from generator.library.bricks import load_library

    rep = accuracy.run(PAINTED_SPECS, ["numpy"], ["float32"], load_library(), hemisphere_k=6)
    for v in rep["verdicts"]:
        assert v["pass"] and v["float32_nan_inf"] == 0, v


@pytest.mark.lavapipe
@pytest.mark.toolchain  # compiles eval kernels
def test_the_painted_bricks_agree_with_numpy_on_lavapipe_in_three_languages(device):
    """GLSL, HLSL and WGSL sample the same fp16 texels: within each brick's declared tolerance of the
    reference, and within 2e-3 of NumPy's float32 emission (the filter's fixed-point weights on lavapipe)."""
    from generator.eval import accuracy
    from generator.library.bricks import load_library

    rep = accuracy.run(PAINTED_SPECS, ["numpy", *accuracy.GPU_TARGETS], ["float32"], load_library(), hemisphere_k=6)
    for v in rep["verdicts"]:
        assert v["pass"] and v["float32_nan_inf"] == 0, v
    hemi = {(r["spec"], r["target"]): r["max_rel"] for r in rep["results"] if r["set"] == "hemisphere"}
    for spec in PAINTED_SPECS:
        for t in accuracy.GPU_TARGETS:
            assert hemi[(spec, t)] <= hemi[(spec, "numpy")] + 2e-3, (spec, t, hemi[(spec, t)], hemi[(spec, "numpy")])
