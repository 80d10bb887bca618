"""The twist map (Hoffman & Baker 2006, "Anisotropic BRDF with Normal and Twist Maps").

The normal fillers `normal_twist_map` (one RGBA texture: RG normal xy, BA twist direction) and
`twist_map` (vertex normal, RG twist texture) define the normal kind's optional `tangent` entry; the
glue then hands an anisotropic BRDF the frame (N', T', B' = N' × T') with T' the twist direction
Gram-Schmidt-orthogonalized against the perturbed normal N' (link/glue.py shading_tangent).

- shade() in NumPy (float64, textures sampled at texel centres) equals π f_r c cos θ of the float64
  reference BRDF evaluated in the reference frame of generator/reference/frames.py, for Ward,
  Ashikhmin-Shirley, Banks and anisotropic GGX;
- a twist of 90° swaps the roles of the two roughnesses (Ward: m_u ↔ m_v), a twist of 0 is the
  vertex tangent Gram-Schmidt-orthogonalized against N';
- guards: an unpainted (mid-grey) twist texel keeps the vertex tangent, d ∥ N' stays finite (in float16 too);
- isotropic BRDFs ignore the twist (channels not read, texture and tangent interpolant not declared);
- a scene of twist materials builds in GLSL, HLSL and WGSL (and its ubershader), and on lavapipe the
  specialized and ubershader renders agree while the twist changes the image.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

LANGS = ("glsl", "hlsl", "wgsl")
GGX_ANISO = "microfacet(ndf=ggx_anisotropic,fresnel=schlick,vis=smith_ggx_height_correlated)"
ANISOTROPIC = {
    "ward_anisotropic": {"m_u": 0.08, "m_v": 0.35, "f0": [0.9, 0.8, 0.6]},
    "ashikhmin_shirley": {"n_u": 400.0, "n_v": 12.0, "f0": [0.9, 0.8, 0.6]},
    "banks": {"n": 40.0, "k_s": [0.6, 0.5, 0.4]},
    GGX_ANISO: {"alpha_u": 0.08, "alpha_v": 0.4, "alpha": 0.2, "f0": [0.9, 0.8, 0.6]},
}
LIGHT_DIR, LIGHT_COLOR = np.array([0.3, 0.2, 1.0]) / np.linalg.norm([0.3, 0.2, 1.0]), [1.5, 1.2, 1.0]
SIZE = 4


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _unit(a):
    a = np.asarray(a, np.float64)
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def _perm(brdf, normal, packing="constants"):
    from generator.spec.permutation import LightKey, Permutation
    return Permutation(brdf, (LightKey("directional", "none"),), f"{packing}(normal={normal})", "linear")


def _shade_fn(lib, perm):
    """shade() of a permutation emitted to NumPy (float64), its parameter names and the linked permutation."""
    from generator.link import link_permutation
    from generator.backends.numpy.emit import NumpyTarget

    lp = link_permutation(perm, lib)
    t = NumpyTarget()
    fn = t.load(t.emit(lp.program.structs, lp.program.functions, lp.program.globals), np.float64)["shade"]
    return fn, [n for n, _ in lp.glue.signature], lp


def _samples(rng, n):
    """An interpolated frame (T not quite ⟂ Ng, as after interpolation), V and uv at texel centres."""
    from generator.eval.shade import _surface

    Ng = _unit(np.array([0.0, 0.0, 1.0]) + rng.uniform(-0.2, 0.2, (n, 3)))
    V = _unit(Ng + rng.uniform(-0.9, 0.9, (n, 3)))
    T = _unit(np.cross(Ng, rng.normal(size=(n, 3))) + 0.05 * Ng)
    i, j = rng.integers(0, SIZE, n), rng.integers(0, SIZE, n)
    uv = np.stack([(i + 0.5) / SIZE, (j + 0.5) / SIZE], 1)
    local = _surface(np.zeros((n, 3)), Ng, V, np.concatenate([T, np.ones((n, 1))], 1), uv)
    return local, j, i


def _textures(rng):
    """RGBA: RG a unit tangent-space normal's xy (|xy| ≤ 0.6), BA a unit twist direction in one half-plane."""
    t = _unit(rng.uniform(-0.45, 0.45, (SIZE, SIZE, 3)) + [0.0, 0.0, 1.0])
    phi = rng.uniform(-0.5 * np.pi, 0.5 * np.pi, (SIZE, SIZE))
    w = np.stack([np.cos(phi), np.sin(phi)], -1)
    return np.concatenate([(t[..., :2] + 1.0) / 2.0, (w + 1.0) / 2.0], -1)


def _run(fn, names, local, values):
    missing = [k for k in names if k not in local and k not in values]
    assert not missing, missing
    return np.asarray(fn(*[local[k] if k in local else values[k] for k in names]), np.float64)


def _values(params, **textures):
    return {**{f"m_{k}": v for k, v in params.items()}, "l0_direction": LIGHT_DIR, "l0_color": LIGHT_COLOR,
            **textures}


def _expect(lib, spec, L, V, N, T, params):
    """π f_r c cos θ_l of the float64 reference in the frame (N, T, N × T) (0 where n·l ≤ 0)."""
    from generator.reference import reference_brdf

    f = reference_brdf(spec, L, V, N, T=T, params=params, lib=lib)
    return np.pi * f * np.asarray(LIGHT_COLOR) * np.maximum(np.einsum("ij,ij->i", N, L), 0.0)[:, None]


# ------------------------------------------------------------------ the reference frame


def test_the_reference_frame_is_orthonormal_and_follows_the_notes():
    """T' ⟂ N', unit, B' = N' × T'; a flat normal and w = (1, 0) give T; w = (cos φ, sin φ) turns T by φ."""
    from generator.reference.frames import twisted_frame

    rng = np.random.default_rng(1)
    n = 200
    N = np.tile([0.0, 0.0, 1.0], (n, 1))
    T, B = np.tile([1.0, 0.0, 0.0], (n, 1)), np.tile([0.0, 1.0, 0.0], (n, 1))
    xy, w = rng.uniform(0.25, 0.75, (n, 2)), rng.uniform(0.0, 1.0, (n, 2))
    Np, Tp, Bp = twisted_frame(xy, w, N, T, B)
    np.testing.assert_allclose(np.einsum("ij,ij->i", Np, Tp), 0.0, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(Tp, axis=1), 1.0, rtol=1e-15)
    np.testing.assert_allclose(np.linalg.det(np.stack([Tp, Bp, Np], 1)), 1.0, rtol=1e-14)  # right-handed
    flat = np.full((n, 2), 0.5)
    phi = rng.uniform(-np.pi, np.pi, n)
    _, Tp, Bp = twisted_frame(flat, (np.stack([np.cos(phi), np.sin(phi)], 1) + 1.0) / 2.0, N, T, B)
    np.testing.assert_allclose(Tp, np.stack([np.cos(phi), np.sin(phi), 0.0 * phi], 1), atol=1e-15)
    np.testing.assert_allclose(Bp, np.stack([-np.sin(phi), np.cos(phi), 0.0 * phi], 1), atol=1e-15)


# ------------------------------------------------------------------ shade() against the reference


@pytest.mark.parametrize("brdf", list(ANISOTROPIC), ids=["ward", "ashikhmin_shirley", "banks", "ggx_anisotropic"])
@pytest.mark.parametrize("normal", ["normal_twist_map", "twist_map"])
def test_shade_in_numpy_equals_the_reference_brdf_in_the_twisted_frame(lib, brdf, normal):
    from generator.reference.frames import normal_from_xy, twist_tangent

    fn, names, lp = _shade_fn(lib, _perm(brdf, normal))
    rng = np.random.default_rng(2)
    n = 500
    local, j, i = _samples(rng, n)
    tex = _textures(rng)
    if normal == "normal_twist_map":
        assert [(t.param, t.srgb) for t in lp.glue.textures] == [("normal_map", False)]
        got = _run(fn, names, local, _values(ANISOTROPIC[brdf], t_normal_map=tex))
        Np = normal_from_xy(tex[j, i, :2], local["Ng"], local["T"], local["B"])
    else:
        assert [(t.param, t.srgb) for t in lp.glue.textures] == [("twist_map", False)]
        got = _run(fn, names, local, _values(ANISOTROPIC[brdf], t_twist_map=tex[..., 2:]))
        Np = local["Ng"]
    Tp = twist_tangent(tex[j, i, 2:], Np, local["T"], local["B"])
    want = _expect(lib, brdf, np.tile(LIGHT_DIR, (n, 1)), local["V"], Np, Tp, ANISOTROPIC[brdf])
    assert np.abs(want).max() > 0.05 and (want[:, 0] > 0).mean() > 0.5
    np.testing.assert_allclose(got[:, :3], want, rtol=1e-9, atol=1e-12)
    # the interpolated frame (T not ⟂ N') gives a different image: the Gram-Schmidt step matters
    untwisted = _expect(lib, brdf, np.tile(LIGHT_DIR, (n, 1)), local["V"], Np, local["T"], ANISOTROPIC[brdf])
    assert np.abs(untwisted - want).max() > 1e-3 * np.abs(want).max()


def test_a_quarter_turn_of_the_twist_swaps_the_two_roughnesses(lib):
    """Ward with twist 90° (w = (0, 1): T' along B) and (m_u, m_v) equals twist 0 (w = (1, 0)) with (m_v, m_u):
    B' = N' × T' turns with T', and Ward reads (h·t/m_u)² + (h·b/m_v)². With the flat normal texel (N' = N):
    under a tilted N', Gram-Schmidt of B is not N' × (Gram-Schmidt of T), the order of the steps matters."""
    fn, names, _ = _shade_fn(lib, _perm("ward_anisotropic", "normal_twist_map"))
    rng = np.random.default_rng(3)
    local, _, _ = _samples(rng, 400)
    tex = _textures(rng)
    quarter, zero = tex.copy(), tex.copy()
    quarter[...] = [0.5, 0.5, 0.5, 1.0]
    zero[...] = [0.5, 0.5, 1.0, 0.5]
    a = _run(fn, names, local, _values({"m_u": 0.08, "m_v": 0.35, "f0": [0.9] * 3}, t_normal_map=quarter))
    b = _run(fn, names, local, _values({"m_u": 0.35, "m_v": 0.08, "f0": [0.9] * 3}, t_normal_map=zero))
    assert np.abs(a).max() > 0.05
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-13)


def test_guards_an_unpainted_texel_keeps_the_vertex_tangent_and_a_twist_along_the_normal_stays_finite(lib):
    from generator.reference.frames import normal_from_xy

    fn, names, _ = _shade_fn(lib, _perm("ward_anisotropic", "normal_twist_map"))
    rng = np.random.default_rng(4)
    n = 300
    local, j, i = _samples(rng, n)
    tex = _textures(rng)
    grey, zero = tex.copy(), tex.copy()
    grey[..., 2:] = 128.0 / 255.0  # the 8-bit mid-grey of an unpainted map: |w| = 0.0039
    zero[..., 2:] = [1.0, 0.5]
    params = {"m_u": 0.08, "m_v": 0.35, "f0": [0.9] * 3}
    np.testing.assert_array_equal(_run(fn, names, local, _values(params, t_normal_map=grey)),
                                  _run(fn, names, local, _values(params, t_normal_map=zero)))
    # N' tilted 90° toward the twist: normal xy = (1, 0) (z = 0) and twist (1, 0): d ∥ N', T' = 0
    edge = tex.copy()
    edge[...] = [1.0, 0.5, 1.0, 0.5]
    got = _run(fn, names, local, _values(params, t_normal_map=edge))
    assert np.all(np.isfinite(got))
    Np = normal_from_xy(edge[j, i, :2], local["Ng"], local["T"], local["B"])
    np.testing.assert_allclose(Np, _unit(local["T"]), atol=1e-15)


@pytest.mark.parametrize("normal", ["normal_twist_map", "twist_map"])
def test_the_parallel_twist_guard_holds_in_float16(lib, normal):
    """d exactly ∥ N' (t = d − (d·N') N' = 0 exactly, in half as in double): the floor 1e-6 is a half, so
    shade() in NumPy float16 gives T' = 0 and the colour float64 gives (1e-30 was 0 in half: 0 · rsqrt(0) is
    NaN, and the pixel came out black). An
    axis-aligned frame makes the cancellation exact: normal_twist_map tilts N' 90° onto T (normal xy (1, 0))
    with the twist along T; twist_map keeps N' = N and takes a degenerate interpolated T = N."""
    from generator.backends.numpy.emit import NumpyTarget

    _, names, lp = _shade_fn(lib, _perm("ward_anisotropic", normal))
    t = NumpyTarget()
    emitted = t.emit(lp.program.structs, lp.program.functions, lp.program.globals)
    n = 16
    rng = np.random.default_rng(6)
    X, Z = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    Np = X if normal == "normal_twist_map" else Z
    V = _unit(Np + 0.5 * LIGHT_DIR + rng.uniform(-0.3, 0.3, (n, 3)))  # n·v ≥ 0.3: no half overflow in Ward
    local = {"P": np.zeros((n, 3)), "Ng": np.tile(Z, (n, 1)), "V": V, "uv": np.full((n, 2), 0.5 / SIZE),
             "T": np.tile(X if normal == "normal_twist_map" else Z, (n, 1)), "B": np.tile([0.0, 1.0, 0.0], (n, 1))}
    params = {"m_u": 0.08, "m_v": 0.35, "f0": [0.9] * 3}
    texel = np.full((SIZE, SIZE, 4), [1.0, 0.5, 1.0, 0.5])  # normal xy (1, 0), twist w = (1, 0)
    tex = {"t_normal_map": texel} if normal == "normal_twist_map" else {"t_twist_map": texel[..., 2:]}
    got = {dt: _run(t.load(emitted, dt)["shade"], names, local, _values(params, **tex))
           for dt in (np.float64, np.float16)}
    assert np.all(np.isfinite(got[np.float16])) and got[np.float64][:, :3].max() > 0.1
    np.testing.assert_allclose(got[np.float16], got[np.float64], rtol=2e-2, atol=1e-2)


# ------------------------------------------------------------------ isotropic BRDFs: the twist is ignored


def test_an_isotropic_brdf_ignores_the_twist(lib):
    """normal_twist_map with Blinn-Phong shades as normal_map_xy for any twist channels; twist_map with an
    isotropic BRDF declares neither its texture nor the tangent interpolant."""
    from generator.lang import ir

    spec = "lambert+blinn_phong_normalized"
    rng = np.random.default_rng(5)
    local, _, _ = _samples(rng, 300)
    tex = _textures(rng)
    params = {"rho_d": [0.5, 0.4, 0.3], "n": 40.0, "f0": [0.04] * 3}
    fn, names, lp = _shade_fn(lib, _perm(spec, "normal_twist_map"))
    shade = lp.program.by_name["shade"]
    assert not any(isinstance(x, ir.Call) and x.func.endswith("_tangent") for x in ir.walk_body(shade.body))
    other = tex.copy()
    other[..., 2:] = rng.uniform(0.0, 1.0, (SIZE, SIZE, 2))
    a = _run(fn, names, local, _values(params, t_normal_map=tex))
    fn2, names2, _ = _shade_fn(lib, _perm(spec, "normal_map_xy"))
    np.testing.assert_array_equal(a, _run(fn, names, local, _values(params, t_normal_map=other)))
    np.testing.assert_array_equal(a, _run(fn2, names2, local, _values(params, t_normal_map=tex)))
    _, _, lp = _shade_fn(lib, _perm(spec, "twist_map"))
    assert lp.glue.textures == [] and lp.glue.surface == ["P", "N"]


def test_twist_fillers_satisfy_the_tangent_frame_constraint(lib):
    from generator.spec.resolve import check_packing, resolve

    for normal in ("twist_map", "normal_twist_map"):
        for brdf in ANISOTROPIC:
            assert check_packing(resolve(_perm(brdf, normal), lib)) == ("", "")
    problem, _ = check_packing(resolve(_perm("ward_anisotropic", "vertex"), lib))
    assert "supplies no tangent" in problem


# ------------------------------------------------------------------ every language, and lavapipe

SCENE = """
[scene]
name = "twist"
output = "linear"

[materials.brushed]
brdf = "ward_anisotropic"
packing = "constants(normal=normal_twist_map)"
params = {{ m_u = 0.08, m_v = 0.35, f0 = [0.9, 0.8, 0.6] }}

[materials.radial]
brdf = "{ggx}"
packing = "constants(normal=twist_map)"
params = {{ alpha_u = 0.1, alpha_v = 0.4, f0 = [0.9, 0.8, 0.6] }}

[materials.plastic]
brdf = "lambert+blinn_phong_normalized"
packing = "constants(normal=normal_twist_map)"

[lights.lamp]
type = "point"
params = {{ position = [3.0, 1.0, 2.0], color = [8.0, 8.0, 8.0] }}

[light_sets]
all = ["lamp"]
{objects}
"""


def _scene(tmp_path, materials, **brdf):
    objs = "".join(f'\n[[objects]]\nname = "{m}"\nmaterial = "{m}"\nlights = "all"\n' for m in materials)
    text = SCENE.format(ggx=GGX_ANISO, objects=objs)
    for old, new in brdf.items():
        text = text.replace(old, new)
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


@pytest.mark.toolchain
def test_a_scene_of_twist_materials_builds_in_every_language(lib, tmp_path):
    """GLSL, HLSL and WGSL compile and validate (and the ubershader); each fragment shader declares the
    textures and interpolants it reads: the tangent only where the BRDF is anisotropic."""
    from generator.assemble import BuildContext, build
    from generator.scene.load import load_scene
    from tests.conftest import require_tool

    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    res = build(load_scene(_scene(tmp_path, ("brushed", "radial", "plastic")), lib), tmp_path / "out", BuildContext(lib))
    assert res.ok, res.failures
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert len(manifest["permutations"]) == 3
    want = {"ward_anisotropic": [("normal_map", "linear")], GGX_ANISO: [("twist_map", "linear")],
            "lambert+blinn_phong_normalized": [("normal_map", "linear")]}
    for p in manifest["permutations"]:
        assert set(p["languages"]) == set(LANGS)
        brdf = p["id"].split("brdf=")[1].split(";")[0]
        assert [(t["name"], t["color_space"]) for t in p["interface"]["frag"]["textures"]] == want[brdf], brdf


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_twisted_spheres_render_the_same_specialized_and_through_the_ubershader(lib, device, tmp_path):
    """Fragment shaders on lavapipe (the renderer's 8-bit normal map: RG bumps, BA a twist of ~45°): the
    ubershader's switch computes the twisted frame as the specialized shader does, and the twist changes
    the image against normal_map_xy (same RG, no twist)."""
    from PIL import Image

    from generator.scene.load import load_scene
    from generator.runtime.renderer import render_scene
    from generator.assemble.render_inputs import scene_textures

    images = {}
    for name, normal in (("twist", "normal_twist_map"), ("plain", "normal_map_xy")):
        (tmp_path / name).mkdir()
        scene = load_scene(_scene(tmp_path / name, ("brushed",), **{"normal=normal_twist_map": f"normal={normal}"}),
                           lib)
        for mode in ("specialized", "ubershader") if name == "twist" else ("specialized",):
            render_scene(scene, lib, mode, 1, tmp_path / name / mode, (64, 64), device=device,
                         build=scene_textures(scene, tmp_path / name / "build"))
            img = Image.open(tmp_path / name / mode / "frame_0000.png").convert("RGB")
            images[(name, mode)] = np.asarray(img).astype(int)
    twist = images[("twist", "specialized")]
    assert np.abs(twist - images[("twist", "ubershader")]).max() <= 1
    assert (twist.max(-1) > 20).mean() > 0.05  # lit, not black
    assert np.abs(twist - images[("plain", "specialized")]).max() > 20


def test_the_optional_tangent_entry_is_checked_against_the_normal_contract():
    """`tangent` may be left out (vertex, normal_map …); when defined it must take Np and return vec3."""
    from generator.lang.errors import SourceError
    from generator.library.bricks import load_brick

    head = '"""A test normal brick (Hoffman & Baker 2006)."""\nBRICK = {"kind": "normal", "cite": "test"}\n\n\n' \
           'def normal(N: vec3) -> vec3:\n    return N\n\n\n'
    assert load_brick(Path("n.py"), text=head, shown="n.py").entries[0].name == "normal"
    with pytest.raises(SourceError, match="must take 'Np: vec3'"):
        load_brick(Path("n.py"), text=head + "def tangent(T: vec3) -> vec3:\n    return T\n",
                   shown="n.py")
    with pytest.raises(SourceError, match="must return vec3"):
        load_brick(Path("n.py"), text=head + "def tangent(Np: vec3) -> float:\n    return 1.0\n",
                   shown="n.py")
