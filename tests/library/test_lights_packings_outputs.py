"""Range-limited, spot and uber lights, texture packings and output encodings: what each adds and its checks.

- Lights (`point_range`, `spot`, `uberlight`): shade() with a Lambert BRDF of albedo 1 and the normal
  toward the light returns c_light exactly (π · (1/π) · c_light · 1); that equals the float64
  reference of generator/reference/lights.py in NumPy (float64) and, on lavapipe, in GLSL, HLSL and
  WGSL shade kernels (float32).
- Packings (`normal_map_xy`, `normal_power_gloss`, `specular_map`, `gltf_metallic_roughness`,
  `f0_roughness_texture`): shade() in NumPy with textures sampled at texel centres equals
  π f_r c cosθ of the float64 reference BRDF with the parameters the packing's source formula gives
  (glTF 2.0 Appendix B, the course's packings); only the textures and parameters a permutation
  reads are declared; a packing providing what the BRDF does not read is one clear error.
- Outputs (`sqrt_gamma`, `srgb`): the course's sqrt against the exact sRGB encoding (the figure in
  sqrt_gamma's docstring), and the float32 error of `srgb` in NumPy and on lavapipe.
- A scene using every new brick builds for GLSL, HLSL and WGSL with the real compilers (and its
  ubershader), and `shadermatrix bricks` lists each brick.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

REPO = Path(__file__).resolve().parents[2]
LANGS = ("glsl", "hlsl", "wgsl")
NEW_BRICKS = {"light": ("point_range", "spot", "uberlight"),
              "normal": ("normal_map_xy",),
              "packing": ("normal_power_gloss", "specular_map", "gltf_metallic_roughness", "f0_roughness_texture"),
              "output": ("sqrt_gamma", "srgb")}
GGX = "microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _unit(a):
    a = np.asarray(a, np.float64)
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


# ------------------------------------------------------------------ bricks load

def test_every_new_brick_is_listed_by_shadermatrix_bricks():
    r = subprocess.run([sys.executable, "-m", "generator.cli", "bricks"], cwd=REPO, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    rows = {tuple(line.split()[:2]) for line in r.stdout.splitlines() if line and not line.startswith(" ")}
    for kind, ids in NEW_BRICKS.items():
        for i in ids:
            assert (kind, i) in rows, (kind, i)


# ------------------------------------------------------------------ lights

LIGHTS = {
    "directional": {"direction": [0.3, 0.9, 0.3], "color": [3.0, 2.9, 2.7]},
    "point": {"position": [0.3, 2.0, 0.1], "color": [2.0, 1.5, 1.0]},
    "point_range": {"position": [0.3, 2.0, 0.1], "color": [2.0, 1.5, 1.0], "radius": 4.0},
    "spot": {"position": [0.3, 2.0, 0.1], "direction": [0.2, -1.0, 0.1], "color": [2.0, 1.5, 1.0], "radius": 6.0,
             "inner_angle": 0.3, "outer_angle": 0.7},
    "uberlight": {"position": [0.3, 2.0, 0.1], "direction": [0.2, -1.0, 0.1], "up": [0.0, 0.0, 1.0],
                  "color": [2.0, 1.5, 1.0], "radius": 6.0, "width": 0.6, "height": 0.3, "width_edge": 0.2,
                  "height_edge": 0.1, "roundness": 0.5},
}
VARIANTS = [("directional", {}), ("point", {}), ("point_range", {}), ("spot", {}), ("uberlight", {}),
            ("uberlight", {"roundness": 1.0}),
            ("uberlight", {"roundness": 0.02, "up": [1.0, 0.0, 0.0]}),
            ("spot", {"inner_angle": 0.0, "outer_angle": 1.2, "radius": 2.5})]


def _light_samples(n=3000, seed=1):
    """Surface points around the lights (some beyond the range, behind the spot), none within 5 cm of them."""
    rng = np.random.default_rng(seed)
    P = rng.uniform(-3.0, 3.0, (n, 3))
    P[:, 1] = rng.uniform(-3.0, 1.9, n)
    return P[np.linalg.norm(P - np.array(LIGHTS["spot"]["position"]), axis=1) > 0.05]


def _light_perm(light):
    from generator.spec.permutation import LightKey, Permutation
    return Permutation("lambert", (LightKey(light, "none"),), "constants(normal=vertex)", "linear")


def _light_shade(lib, light, values, P, target):
    """shade() with Lambert ρ_d = 1 and N = V = l: c_light, as the brick computes it."""
    from generator.eval.shade import shade_samples
    from generator.reference.lights import LIGHTS as REF

    l, c = REF[light](P, **values)
    got = shade_samples(_light_perm(light), P, l, l, values={"m_rho_d": [1.0, 1.0, 1.0],
                                                             **{f"l0_{k}": v for k, v in values.items()}},
                        target=target, lib=lib)
    return got, c


@pytest.mark.parametrize("light,change", VARIANTS)
def test_light_brick_equals_its_float64_reference_in_numpy(lib, light, change):
    values = {**LIGHTS[light], **change}
    P = _light_samples()
    got, want = _light_shade(lib, light, values, P, "numpy")
    lit = want[:, 0] > 0.0
    if light not in ("directional", "point"):
        assert 0.1 < lit.mean() < 0.95, lit.mean()  # both sides of the window / the cone's edge are sampled
    np.testing.assert_allclose(got[:, :3], want, rtol=1e-12, atol=1e-13)
    assert np.all(got[:, 3] == 1.0)


@pytest.mark.parametrize("light", ["point_range", "spot", "uberlight"])
def test_a_storage_buffer_of_the_new_lights_equals_them_unrolled(lib, light):
    """`*light/none` (a loop over LightData, its parameters packed in vec4s) sums what two static lights give."""
    from generator.eval.shade import shade_samples
    from generator.spec.permutation import LightKey, Permutation

    P = _light_samples(400, seed=9)
    N = np.tile([0.0, 1.0, 0.0], (len(P), 1))
    second = {**LIGHTS[light], "position": [-0.5, 1.5, 0.4]}
    two = {k: np.array([LIGHTS[light][k], second[k]], np.float64) for k in LIGHTS[light]}
    dyn = Permutation("lambert", (LightKey(light, "none", dynamic=True),), "constants(normal=vertex)", "linear")
    static = Permutation("lambert", (LightKey(light, "none"),) * 2, "constants(normal=vertex)", "linear")
    got = shade_samples(dyn, P, N, N, values={"m_rho_d": [1.0] * 3}, buffers={0: two}, lib=lib)
    lv = {f"l{i}_{k}": v for i, vals in enumerate((LIGHTS[light], second)) for k, v in vals.items()}
    want = shade_samples(static, P, N, N, values={"m_rho_d": [1.0] * 3, **lv}, lib=lib)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-14)
    assert got[:, :3].max() > 0.1


def test_light_guards_keep_degenerate_inputs_finite(lib):
    """A point on the light, an überlight whose `up` is its axis, a spot with inner ≥ outer: finite values
    (the guards of the bricks' docstrings), and the unshaped überlight equals the point_range light in front."""
    from generator.eval.shade import shade_samples

    P = np.array([[0.3, 2.0, 0.1], [0.3, 1.0, 0.1], [1.3, 1.0, 0.1], [0.3, 3.0, 0.1]])
    N = np.tile([0.0, 1.0, 0.0], (len(P), 1))
    cases = [("point_range", {}), ("spot", {"inner_angle": 0.9, "outer_angle": 0.5}),
             ("uberlight", {"up": [0.2, -1.0, 0.1]}), ("uberlight", {})]
    for light, change in cases:
        vals = {f"l0_{k}": v for k, v in {**LIGHTS[light], **change}.items()}
        got = shade_samples(_light_perm(light), P, N, N, values={"m_rho_d": [1.0, 1.0, 1.0], **vals}, lib=lib)
        assert np.all(np.isfinite(got)), (light, change, got)
    vals = {f"l0_{k}": v for k, v in {**LIGHTS["uberlight"], "up": [0.2, -1.0, 0.1]}.items()}
    unshaped = shade_samples(_light_perm("uberlight"), P, N, N, values={"m_rho_d": [1.0] * 3, **vals}, lib=lib)
    vals = {f"l0_{k}": LIGHTS["uberlight"][k] for k in ("position", "color", "radius")}
    point = shade_samples(_light_perm("point_range"), P, N, N, values={"m_rho_d": [1.0] * 3, **vals}, lib=lib)
    np.testing.assert_allclose(unshaped[1], point[1], rtol=1e-12)  # 1 below the light, in front of it (z > 0)
    assert unshaped[1, 0] > 1.0


def test_light_references_follow_their_sources_at_known_points():
    """Spot checks of the references themselves: the window is 1 near the light and 0 from the radius
    on, the cone is full inside inner and 0 outside outer, the überlight's superellipse bounds."""
    from generator.reference import lights as R

    P = np.array([[0.0, -0.5, 0.0], [0.0, -1.0, 0.0], [0.0, -3.999, 0.0], [0.0, -4.0, 0.0], [0.0, -5.0, 0.0]])
    _, c = R.point_range(P + [0.0, 2.0, 0.0], [0.0, 2.0, 0.0], [1.0, 1.0, 1.0], 4.0)
    assert c[0, 0] == pytest.approx((1.0 - (0.5 / 4.0) ** 4) ** 2 / 0.25)
    assert c[1, 0] == pytest.approx((1.0 - (1.0 / 4.0) ** 4) ** 2) and c[3, 0] == 0.0 and c[4, 0] == 0.0
    assert 0.0 < c[2, 0] < 1e-5
    # spot: axis straight down, a point 1 below at angle θ from the axis
    for theta, want in ((0.2, 1.0), (0.5, ((np.cos(0.5) - np.cos(0.6)) / (np.cos(0.3) - np.cos(0.6))) ** 2),
                        (0.7, 0.0)):
        p = np.array([[np.tan(theta), -1.0, 0.0]])
        _, c = R.spot(p, [0.0, 0.0, 0.0], [0.0, -1.0, 0.0], [1.0, 1.0, 1.0], 1e6, 0.3, 0.6)
        assert c[0, 0] * (1.0 + np.tan(theta) ** 2) == pytest.approx(want, abs=1e-12), theta
    # überlight: width 0.5, edge 0.1; on the x axis of the light at unit distance
    for x, want in ((0.0, 1.0), (0.49, 1.0), (0.55, 0.5), (0.61, 0.0)):
        p = np.array([[x, -1.0, 0.0]])
        _, c = R.uberlight(p, [0.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0], 1e6,
                           0.5, 0.3, 0.1, 0.1, 1.0)
        assert c[0, 0] * (1.0 + x * x) == pytest.approx(want, abs=1e-9), x
    _, c = R.uberlight(np.array([[0.0, 1.0, 0.0]]), [0.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0],
                       [1.0, 1.0, 1.0], 1e6, 0.5, 0.3, 0.1, 0.1, 1.0)
    assert c[0, 0] == 0.0  # behind the light


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_light_bricks_agree_with_the_reference_on_lavapipe(lib, device, language):
    """float32 shade kernels: within 1e-6 of max c_light plus 1e-5 relative per sample (measured, the same in
    the three languages: ≤ 2.1e-7 of the max everywhere, the window's and the cones' edges included; where
    c_light > 1e-3 of the max, ≤ 1.4e-5 relative, the überlight's soft edge)."""
    P = _light_samples(1024, seed=7)
    for light, change in VARIANTS:
        values = {**LIGHTS[light], **change}
        got, want = _light_shade(lib, light, values, P, language)
        scale = np.abs(want).max()
        err = np.abs(got[:, :3] - want)
        assert np.all(err <= 1e-6 * scale + 1e-5 * np.abs(want)), (light, change, err.max() / scale)
        assert np.all(got[:, 3] == 1.0)


# ------------------------------------------------------------------ packings

def _numpy_shade(lib, perm):
    """The fragment glue's shade() of a permutation, emitted to NumPy (float64); its signature names."""
    from generator.link import link_permutation
    from generator.backends.numpy.emit import NumpyTarget

    lp = link_permutation(perm, lib)
    t = NumpyTarget()
    fn = t.load(t.emit(lp.program.structs, lp.program.functions, lp.program.globals), np.float64)["shade"]
    return fn, [n for n, _ in lp.glue.signature], lp


def _texture(rng, size=4, channels=4, lo=0.0, hi=1.0):
    return rng.uniform(lo, hi, (size, size, channels))


def _texel_uv(rng, n, size=4):
    """uv at texel centres (bilinear = the texel) and the texel indices (row j, column i)."""
    i, j = rng.integers(0, size, n), rng.integers(0, size, n)
    return np.stack([(i + 0.5) / size, (j + 0.5) / size], 1), j, i


def _frame(rng, n):
    """Ng = +z tilted a little, V and L in its upper hemisphere, T ⟂ Ng."""
    Ng = _unit(np.array([0.0, 0.0, 1.0]) + rng.uniform(-0.2, 0.2, (n, 3)))
    V = _unit(Ng + rng.uniform(-0.9, 0.9, (n, 3)))
    T = _unit(np.cross(Ng, rng.normal(size=(n, 3))))
    return Ng, V, T


def _call(fn, names, local, values):
    missing = [k for k in names if k not in local and k not in values]
    assert not missing, missing
    return np.asarray(fn(*[local[k] if k in local else values[k] for k in names]), np.float64)


def _expect(lib, spec, L, V, N, params, color, T=None):
    """π f_r c cos θ_l of the float64 reference (0 where n·l ≤ 0)."""
    from generator.reference import reference_brdf

    f = reference_brdf(spec, L, V, N, T=T, params=params, lib=lib)
    cos = np.maximum(np.einsum("ij,ij->i", N, L), 0.0)
    return np.pi * f * np.asarray(color) * cos[:, None]


LIGHT_DIR, LIGHT_COLOR = _unit([0.3, 0.2, 1.0]), [1.5, 1.2, 1.0]


def _dir_light_values():
    return {"l0_direction": LIGHT_DIR, "l0_color": LIGHT_COLOR}


def test_gltf_metallic_roughness_gives_rho_d_f0_alpha_of_gltf_appendix_b(lib):
    """glTF 2.0 Appendix B: c_diff = base (1 − metallic), f0 = mix(0.04, base, metallic), α = roughness²,
    base = baseColorFactor · texture (sRGB decoded by the view), metallic/roughness = factor · ORM.b / .g."""
    from generator.spec.permutation import LightKey, Permutation

    spec = f"lambert+{GGX}"
    perm = Permutation(spec, (LightKey("directional", "none"),), "gltf_metallic_roughness(normal=vertex)", "linear")
    fn, names, lp = _numpy_shade(lib, perm)
    assert [t.param for t in lp.glue.textures] == ["base_color_map", "orm_map"]
    # the BRDF's constants rho_d, f0 and alpha are not declared: the packing provides them
    assert {n for n in names if n.startswith("m_")} == {"m_base_color", "m_metallic", "m_roughness"}
    rng = np.random.default_rng(3)
    n = 600
    Ng, V, _ = _frame(rng, n)
    uv, j, i = _texel_uv(rng, n)
    base_tex, orm = _texture(rng), _texture(rng, lo=0.05)
    orm[0, 0, 2], orm[0, 1, 2] = 0.0, 1.0  # a pure dielectric and a pure metal texel
    factors = {"m_base_color": [0.9, 0.8, 0.7], "m_metallic": 0.9, "m_roughness": 0.8}
    got = _call(fn, names, {"P": np.zeros((n, 3)), "Ng": Ng, "V": V, "uv": uv},
                {**factors, **_dir_light_values(), "t_base_color_map": base_tex, "t_orm_map": orm})
    base = np.asarray(factors["m_base_color"]) * base_tex[j, i, :3]
    metallic = factors["m_metallic"] * orm[j, i, 2]
    rough = factors["m_roughness"] * orm[j, i, 1]
    params = {"rho_d": base * (1.0 - metallic)[:, None],
              "f0": 0.04 * (1.0 - metallic)[:, None] + base * metallic[:, None], "alpha": rough ** 2}
    want = _expect(lib, spec, np.tile(LIGHT_DIR, (n, 1)), V, Ng, params, LIGHT_COLOR)
    assert np.abs(want).max() > 0.1
    np.testing.assert_allclose(got[:, :3], want, rtol=1e-10, atol=1e-12)
    # occlusion (ORM.r) is not read: direct light only
    orm2 = orm.copy()
    orm2[..., 0] = 0.0
    again = _call(fn, names, {"P": np.zeros((n, 3)), "Ng": Ng, "V": V, "uv": uv},
                  {**factors, **_dir_light_values(), "t_base_color_map": base_tex, "t_orm_map": orm2})
    np.testing.assert_array_equal(again, got)


def test_a_textured_ggx_metal_with_f0_roughness_texture(lib):
    """A specular-only GGX metal: f0 = f0 · texture.rgb, α = (roughness · texture.a)²."""
    from generator.spec.permutation import LightKey, Permutation

    perm = Permutation(GGX, (LightKey("directional", "none"),), "f0_roughness_texture(normal=vertex)", "linear")
    fn, names, lp = _numpy_shade(lib, perm)
    assert [(t.param, t.srgb) for t in lp.glue.textures] == [("f0_map", True)]
    rng = np.random.default_rng(4)
    n = 500
    Ng, V, _ = _frame(rng, n)
    uv, j, i = _texel_uv(rng, n)
    tex = _texture(rng, lo=0.02)
    vals = {"m_f0": [1.0, 0.71, 0.29], "m_roughness": 0.7, "t_f0_map": tex, **_dir_light_values()}
    got = _call(fn, names, {"P": np.zeros((n, 3)), "Ng": Ng, "V": V, "uv": uv}, vals)
    params = {"f0": np.asarray(vals["m_f0"]) * tex[j, i, :3], "alpha": (0.7 * tex[j, i, 3]) ** 2}
    want = _expect(lib, GGX, np.tile(LIGHT_DIR, (n, 1)), V, Ng, params, LIGHT_COLOR)
    np.testing.assert_allclose(got[:, :3], want, rtol=1e-10, atol=1e-12)


def _tangent_args(Ng, T):
    return np.concatenate([T, np.ones((len(T), 1))], 1)  # w = +1: B = Ng × T


def test_normal_map_xy_reconstructs_z_and_equals_the_rgb_normal_map(lib):
    """A unit tangent-space normal stored as RGB (normal_map) and as RG only (normal_map_xy) shades the same;
    an xy beyond the unit disc (filtering) gives z = 0, not NaN."""
    from generator.spec.permutation import LightKey, Permutation
    from generator.eval.shade import _surface

    rng = np.random.default_rng(5)
    size, n = 4, 400
    t = _unit(rng.uniform(-0.6, 0.6, (size, size, 3)) + [0.0, 0.0, 1.0])
    rgb = (t + 1.0) / 2.0
    rgb_xy = rgb.copy()
    rgb_xy[..., 2] = rng.uniform(0.0, 1.0, (size, size))  # B is not read by normal_map_xy
    rgb_xy[0, 0, :2] = [1.0, 1.0]  # |t.xy| = √2 > 1
    Ng, V, T = _frame(rng, n)
    uv, j, i = _texel_uv(rng, n, size)
    out = {}
    for normal, tex in (("normal_map", rgb), ("normal_map_xy", rgb_xy)):
        perm = Permutation("lambert+blinn_phong_normalized", (LightKey("directional", "none"),),
                           f"constants(normal={normal})", "linear")
        fn, names, _ = _numpy_shade(lib, perm)
        local = _surface(np.zeros((n, 3)), Ng, V, _tangent_args(Ng, T), uv)
        out[normal] = _call(fn, names, local, {"m_rho_d": [0.5, 0.4, 0.3], "m_n": 40.0, "m_f0": [0.04] * 3,
                                               "t_normal_map": tex, **_dir_light_values()})
    assert np.all(np.isfinite(out["normal_map_xy"]))
    ok = ~((j == 0) & (i == 0))
    np.testing.assert_allclose(out["normal_map_xy"][ok], out["normal_map"][ok], rtol=1e-10, atol=1e-12)
    # the clipped texel: N' = normalize(T + B), z = 0
    k = np.flatnonzero(~ok)
    if len(k):
        local = _surface(np.zeros((n, 3)), Ng, V, _tangent_args(Ng, T), uv)
        Np = _unit(local["T"][k] + local["B"][k])
        want = _expect(lib, "lambert+blinn_phong_normalized", np.tile(LIGHT_DIR, (len(k), 1)), local["V"][k], Np,
                       {"rho_d": [0.5, 0.4, 0.3], "n": 40.0, "f0": [0.04] * 3}, LIGHT_COLOR)
        np.testing.assert_allclose(out["normal_map_xy"][k, :3], want, rtol=1e-10, atol=1e-12)


def test_normal_power_gloss_packs_normal_power_and_gloss_in_one_texture(lib):
    """The course's packed texture: one binding `normal_map` read by the packing (B, A) and its
    normal_map_xy filler (R, G); n = n_max^B, f0 = A · f0."""
    from generator.spec.permutation import LightKey, Permutation
    from generator.eval.shade import _surface

    spec = "lambert+blinn_phong_normalized"
    perm = Permutation(spec, (LightKey("directional", "none"),), "normal_power_gloss(normal=normal_map_xy)", "linear")
    fn, names, lp = _numpy_shade(lib, perm)
    assert [(t.param, t.srgb) for t in lp.glue.textures] == [("normal_map", False)]
    assert "m_n" not in names and "m_f0" in names and "m_n_max" in names
    rng = np.random.default_rng(6)
    size, n = 4, 500
    t = _unit(rng.uniform(-0.5, 0.5, (size, size, 3)) + [0.0, 0.0, 1.0])
    tex = np.concatenate([(t[..., :2] + 1.0) / 2.0, rng.uniform(0.0, 1.0, (size, size, 2))], -1)
    Ng, V, T = _frame(rng, n)
    uv, j, i = _texel_uv(rng, n, size)
    local = _surface(np.zeros((n, 3)), Ng, V, _tangent_args(Ng, T), uv)
    vals = {"m_rho_d": [0.5, 0.4, 0.3], "m_f0": [0.9, 0.8, 0.6], "m_n_max": 8192.0, "t_normal_map": tex,
            **_dir_light_values()}
    got = _call(fn, names, local, vals)
    tt = t[j, i]
    Np = _unit(tt[:, :1] * local["T"] + tt[:, 1:2] * local["B"] + tt[:, 2:3] * local["Ng"])
    params = {"rho_d": [0.5, 0.4, 0.3], "n": 8192.0 ** tex[j, i, 2], "f0": np.outer(tex[j, i, 3], [0.9, 0.8, 0.6])}
    want = _expect(lib, spec, np.tile(LIGHT_DIR, (n, 1)), local["V"], Np, params, LIGHT_COLOR)
    assert np.abs(want).max() > 0.1
    np.testing.assert_allclose(got[:, :3], want, rtol=1e-9, atol=1e-12)


def test_specular_map_is_the_course_shift_variant_shader(lib):
    """Kd from albedo_map, Ks = specular_map.rgb, n = n_max^(specular_map.a)."""
    from generator.spec.permutation import LightKey, Permutation

    spec = "lambert+blinn_phong_normalized"
    perm = Permutation(spec, (LightKey("directional", "none"),), "specular_map(normal=vertex)", "linear")
    fn, names, lp = _numpy_shade(lib, perm)
    assert [(t.param, t.srgb) for t in lp.glue.textures] == [("albedo_map", True), ("specular_map", True)]
    rng = np.random.default_rng(8)
    n = 500
    Ng, V, _ = _frame(rng, n)
    uv, j, i = _texel_uv(rng, n)
    kd, ks = _texture(rng), _texture(rng)
    vals = {"m_rho_d": [1.0, 1.0, 1.0], "m_f0": [1.0, 1.0, 1.0], "m_n_max": 1000.0, "t_albedo_map": kd,
            "t_specular_map": ks, **_dir_light_values()}
    got = _call(fn, names, {"P": np.zeros((n, 3)), "Ng": Ng, "V": V, "uv": uv}, vals)
    params = {"rho_d": kd[j, i, :3], "f0": ks[j, i, :3], "n": 1000.0 ** ks[j, i, 3]}
    want = _expect(lib, spec, np.tile(LIGHT_DIR, (n, 1)), V, Ng, params, LIGHT_COLOR)
    np.testing.assert_allclose(got[:, :3], want, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("brdf,packing,names", [
    (GGX, "albedo_texture", "rho_d"),
    (GGX, "gltf_metallic_roughness", "rho_d"),
    ("lambert", "f0_roughness_texture", "f0"),
    (f"lambert+{GGX}", "specular_map", "n"),
    ("lambert+blinn_phong_normalized", "gltf_metallic_roughness", "alpha"),
])
def test_a_packing_providing_what_the_brdf_does_not_read_is_one_clear_error(lib, brdf, packing, names):
    from generator.spec.permutation import LightKey, Permutation
    from generator.spec.resolve import check_packing, resolve

    r = resolve(Permutation(brdf, (LightKey("directional", "none"),), packing, "linear"), lib)
    problem, todo = check_packing(r)
    assert f"packing '{packing}' provides {names}, which BRDF" in problem and "does not read" in problem, problem
    assert todo


# ------------------------------------------------------------------ outputs

SQRT_MAX_ERROR, SQRT_AT = 0.0374, 0.213  # the figures of bricks/output/sqrt_gamma.py's docstring


def test_sqrt_gamma_error_against_exact_srgb_is_the_documented_figure():
    from generator.reference.outputs import max_error_against_srgb, sqrt_gamma, srgb_encode

    err, at = max_error_against_srgb(sqrt_gamma)
    assert err == pytest.approx(SQRT_MAX_ERROR, abs=5e-5) and at == pytest.approx(SQRT_AT, abs=5e-4)
    x = np.linspace(0.0, 1.0, 1_000_001)
    codes = np.abs(np.round(255 * sqrt_gamma(x)) - np.round(255 * srgb_encode(x))).max()
    assert codes == 10
    assert err * 255 == pytest.approx(9.5, abs=0.05)
    doc = (REPO / "bricks" / "output" / "sqrt_gamma.py").read_text()
    assert "0.0374 at x = 0.213" in doc and "10 after rounding" in doc
    # sRGB's own pieces meet at the threshold (continuity of IEC 61966-2-1's constants, to 1e-7)
    assert 12.92 * 0.0031308 == pytest.approx(1.055 * 0.0031308 ** (1 / 2.4) - 0.055, abs=1e-7)


def _output_inputs(n=4097):
    """Lambert ρ_d = 1 under a directional light of color 1 along +z, normal at angle arccos(x):
    the output brick's input is x (here from 0 to 1, denser near sRGB's threshold)."""
    x = np.unique(np.concatenate([np.linspace(0.0, 1.0, n), np.linspace(0.0, 0.01, 513)]))
    x[0] = 1e-6  # n·l > 0
    s = np.sqrt(1.0 - x * x)
    N = np.stack([s, np.zeros_like(x), x], 1)
    return x, N


def _output_run(lib, output, target):
    from generator.eval.shade import shade_samples
    from generator.spec.permutation import LightKey, Permutation

    x, N = _output_inputs()
    perm = Permutation("lambert", (LightKey("directional", "none"),), "constants(normal=vertex)", output)
    vals = {"m_rho_d": [1.0, 1.0, 1.0], "l0_direction": [0.0, 0.0, 1.0], "l0_color": [1.0, 1.0, 1.0]}
    return shade_samples(perm, np.zeros_like(N), N, N, values=vals, target=target, lib=lib)


def test_output_bricks_equal_their_references_in_numpy(lib):
    from generator.reference.outputs import sqrt_gamma, srgb_encode

    lin = _output_run(lib, "linear", "numpy")[:, :3]
    np.testing.assert_allclose(lin[:, 0], _output_inputs()[0], rtol=1e-13)
    for output, ref in (("sqrt_gamma", sqrt_gamma), ("srgb", srgb_encode)):
        got = _output_run(lib, output, "numpy")
        np.testing.assert_allclose(got[:, :3], ref(lin), rtol=1e-13, atol=1e-15)
        assert np.all(got[:, 3] == 1.0)
    # saturate: out-of-range inputs are clipped as a UNORM target would, never NaN
    from generator.backends.numpy.emit import NumpyTarget
    from generator.link import link_permutation
    from generator.spec.permutation import LightKey, Permutation

    perm = Permutation("lambert", (LightKey("directional", "none"),), "constants(normal=vertex)", "srgb")
    lp = link_permutation(perm, lib)
    t = NumpyTarget()
    f = t.load(t.emit(lp.program.structs, lp.program.functions, lp.program.globals), np.float32)
    out = f[next(k for k in f if k.endswith("_output") and k.startswith("srgb"))]
    v = np.asarray(out(np.array([[-1.0, 0.5, 7.0]], np.float32)), np.float64)
    np.testing.assert_allclose(v[0], [0.0, srgb_encode(0.5), 1.0, 1.0], rtol=1e-6)


def test_srgb_in_float32_numpy_is_within_a_few_ulp_of_float64():
    """The srgb brick's encode in float32 (NumPy target) against float64 IEC 61966-2-1, for every float32
    input of a dense sweep: the figure in bricks/output/srgb.py's docstring."""
    from generator.reference.outputs import srgb_encode
    from generator.library.bricks import load_library
    from generator.link import link_permutation
    from generator.spec.permutation import LightKey, Permutation
    from generator.backends.numpy.emit import NumpyTarget

    lib = load_library()
    perm = Permutation("lambert", (LightKey("directional", "none"),), "constants(normal=vertex)", "srgb")
    lp = link_permutation(perm, lib)
    t = NumpyTarget()
    f = t.load(t.emit(lp.program.structs, lp.program.functions, lp.program.globals), np.float32)
    out = f[next(k for k in f if k.endswith("_output") and k.startswith("srgb"))]
    x = np.linspace(0.0, 1.0, 1_000_001).astype(np.float32)
    got = np.asarray(out(np.stack([x, x, x], 1)), np.float64)[:, 0]
    err = np.abs(got - srgb_encode(x.astype(np.float64))).max()
    assert err <= SRGB_F32_BOUND, err


SRGB_F32_BOUND = 3e-7  # measured 1.5e-7 (NumPy float32), 2.1e-7 (lavapipe): srgb.py's docstring


def test_the_comparison_figures_of_srgb_docstring():
    from generator.reference.outputs import max_error_against_srgb

    doc = (REPO / "bricks" / "output" / "srgb.py").read_text()
    for encode, err, at in ((lambda x: x ** (1 / 2.2), 0.0335, 0.0022), (lambda x: x, 0.287, 0.244)):
        e, x = max_error_against_srgb(encode)
        assert e == pytest.approx(err, abs=5e-4) and x == pytest.approx(at, abs=5e-4)
        assert f"{err} (x = {at})" in doc


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_output_bricks_on_lavapipe(lib, device, language):
    """The GPU's encoding of its own linear value (the `linear` permutation's output, same glue) against
    float64: srgb within SRGB_F32_BOUND, sqrt_gamma within 2 ulp at 1 (measured: 2.1e-7 and 3.0e-8)."""
    from generator.reference.outputs import sqrt_gamma, srgb_encode

    lin = _output_run(lib, "linear", language)[:, :3]
    np.testing.assert_allclose(lin[:, 0], _output_inputs()[0], rtol=2e-6, atol=1e-7)
    for output, ref, bound in (("srgb", srgb_encode, SRGB_F32_BOUND), ("sqrt_gamma", sqrt_gamma, 2.4e-7)):
        got = _output_run(lib, output, language)
        err = np.abs(got[:, :3] - ref(lin)).max()
        assert err <= bound, (output, err)
        assert np.all(got[:, 3] == 1.0)


# ------------------------------------------------------------------ a scene builds in every language

SCENE = """
[scene]
name = "lights_packings_outputs"
output = "{output}"

[materials.gltf_metal]
brdf = "lambert+{ggx}"
packing = "gltf_metallic_roughness(normal=normal_map)"
params = {{ base_color = [1.0, 0.8, 0.5], metallic = 1.0, roughness = 0.6 }}

[materials.textured_gold]
brdf = "{ggx}"
packing = "f0_roughness_texture"
params = {{ f0 = [1.0, 0.71, 0.29], roughness = 0.5 }}

[materials.packed]
brdf = "lambert+blinn_phong_normalized"
packing = "normal_power_gloss"
params = {{ rho_d = [0.5, 0.5, 0.5], f0 = [0.04, 0.04, 0.04] }}

[materials.course]
brdf = "lambert+blinn_phong_normalized"
packing = "specular_map(normal=normal_map_xy)"

[lights.lamp]
type = "point_range"
params = {{ position = [1.0, 2.5, 0.0], color = [4.0, 3.2, 2.0], radius = 8.0 }}

[lights.spot]
type = "spot"
params = {{ position = [0.0, 3.0, 0.0], direction = [0.0, -1.0, 0.2], color = [9.0, 9.0, 9.0], radius = 12.0, inner_angle = 0.3, outer_angle = 0.6 }}

[lights.shaped]
type = "uberlight"
params = {{ position = [0.0, 3.0, 1.0], direction = [0.0, -1.0, 0.0], up = [0.0, 0.0, 1.0], color = [9.0, 9.0, 9.0], roundness = 0.3 }}

[light_sets]
all = ["lamp", "spot", "shaped"]
{objects}
"""


def _scene_text(output, materials):
    objs = "".join(f'\n[[objects]]\nname = "{m}"\nmaterial = "{m}"\nlights = "all"\n' for m in materials)
    return SCENE.format(output=output, ggx=GGX, objects=objs)


@pytest.mark.toolchain
@pytest.mark.parametrize("output,materials", [
    ("srgb", ("gltf_metal", "textured_gold", "packed", "course")),
    ("sqrt_gamma", ("packed",)),
])
def test_a_scene_of_the_new_bricks_builds_in_every_language(lib, tmp_path, output, materials):
    """Every permutation (and the ubershader) compiles and validates in GLSL, HLSL and WGSL; the
    fragment shader declares exactly the textures its packing and normal read, with their color spaces."""
    from generator.assemble import BuildContext, build
    from generator.scene.load import load_scene

    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        from tests.conftest import require_tool
        require_tool(t)
    path = tmp_path / "scene.toml"
    path.write_text(_scene_text(output, materials))
    res = build(load_scene(path, lib), tmp_path / "out", BuildContext(lib))
    assert res.ok, res.failures
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    want = {"gltf_metallic_roughness(normal=normal_map)": [("base_color_map", "srgb"), ("orm_map", "linear"),
                                                          ("normal_map", "linear")],
            "f0_roughness_texture(normal=vertex)": [("f0_map", "srgb")],
            "normal_power_gloss(normal=normal_map_xy)": [("normal_map", "linear")],
            "specular_map(normal=normal_map_xy)": [("albedo_map", "srgb"), ("specular_map", "srgb"),
                                                   ("normal_map", "linear")]}
    assert len(manifest["permutations"]) == len(materials)
    for p in manifest["permutations"]:
        assert set(p["languages"]) == set(LANGS)
        packing = p["id"].split(";packing=")[1].split(";")[0]
        assert f"output={output}" in p["id"]
        got = [(t["name"], t["color_space"]) for t in p["interface"]["frag"]["textures"]]
        assert got == want[packing], (packing, got)


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_the_scene_renders_the_same_specialized_and_through_the_ubershader(lib, device, tmp_path):
    """Fragment shaders on lavapipe: the new lights, packings (generated or grey test textures) and the
    srgb output draw a lit image, and the ubershader's switch over them draws the same pixels
    (measured: identical)."""
    from PIL import Image

    from generator.scene.load import load_scene
    from generator.runtime.renderer import render_scene
    from generator.assemble.render_inputs import scene_textures

    path = tmp_path / "scene.toml"
    path.write_text(_scene_text("srgb", ("gltf_metal", "textured_gold", "packed", "course")))
    scene = load_scene(path, lib)
    images = {}
    for mode in ("specialized", "ubershader"):
        render_scene(scene, lib, mode, 1, tmp_path / mode, (96, 64), device=device,
                     build=scene_textures(scene, tmp_path / "build"))
        images[mode] = np.asarray(Image.open(tmp_path / mode / "frame_0000.png").convert("RGB")).astype(int)
    assert np.abs(images["specialized"] - images["ubershader"]).max() <= 1
    assert (images["specialized"].max(-1) > 20).mean() > 0.05  # lit, not black
