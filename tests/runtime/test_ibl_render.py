"""`render` draws an environment (image-based lighting): a metal sphere lit by nothing but a sky reflects it.

The scene: one GGX/Schlick metal sphere (f0 high, α = 0.2), no lights, its light set lit by an environment
(scenes guide, "Environments"): a Radiance .hdr of the default sky without its sun (written here, turned 40°
about +Y) and, in a second test, the procedural default sky with its sun. Each pixel of the sphere is checked
against the NumPy evaluation of the same split sum (generator/reference/environment.py) at that pixel — its
normal and view from the camera's ray onto the unit sphere, the baked SH9 values, cube and AmbientBRDF table the
renderer uploads — in GLSL, HLSL and WGSL, with the Khronos validation layer on.

What separates the two: the mesh's interpolated normals (a 24 × 48 UV sphere), Vulkan's seamless cube filtering
(the reference clamps within a face), lavapipe's filtering precision and the 8-bit sRGB attachment. Measured
(lavapipe, Mesa 25, 64 × 48, cube 16², the 468 sphere pixels with n·v ≥ 0.3): relative difference of the
luminance median 0.41 %, 95th percentile 3.4 %, largest 8.8 % (at the silhouette's side of the n·v cut, where a
pixel's interpolated normal differs most from the sphere's), the same in GLSL, HLSL and WGSL. Asserted: median
≤ 1.5 %, 95th percentile ≤ 5 %. Bake (SH9, the 16² cube, the table): ~8 s with an empty cache, 2.7 s with the
table cached; each render ~0.5 s.
"""
from __future__ import annotations

import numpy as np
import pytest

from generator.lang import SourceError
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

W, H = 64, 48
METAL = "microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"
LUMA = np.array([0.2126, 0.7152, 0.0722])


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


def _scene(env: str, brdf: str = METAL, extra: str = "", params: str = "alpha = 0.2, f0 = [0.9, 0.85, 0.8]") -> str:
    return (f'[scene]\nname = "ibl"\nenvironment = "sky"\nubershader = false\n\n[environments.sky]\n{env}\n{extra}\n'
            f'[materials.metal]\nbrdf = "{brdf}"\nparams = {{ {params} }}\n\n'
            '[light_sets]\nnone = []\n\n[[objects]]\nname = "ball"\nmaterial = "metal"\nlights = "none"\n')


def _sunless_hdr(path):
    from generator.eval import ibl_env
    from tests.eval.test_ibl import _hdr
    w, h = 128, 64
    rad = ibl_env.sky_radiance(ibl_env.equirect_dirs(w, h), sun=0.0).reshape(h, w, 3)
    path.write_bytes(_hdr([[tuple(float(c) for c in px) for px in row] for row in rad], rle=False))


def _load(lib, d, text):
    from generator.scene.load import load_scene
    d.mkdir(parents=True, exist_ok=True)
    (d / "s.toml").write_text(text)
    return load_scene(d / "s.toml", lib)


def _render(lib, device, scene, d, language, inputs):
    from PIL import Image

    from generator.runtime.renderer import render_scene
    render_scene(scene, lib, "specialized", 1, d / language, (W, H), language, device=device, environments=inputs)
    return np.asarray(Image.open(d / language / "frame_0000.png").convert("RGB")).astype(np.float64) / 255.0


def _linear(srgb):
    return np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)


def _expected(scene, inputs):
    """(mask, N·V, expected linear RGB) per pixel: the camera's ray onto the unit sphere, the split sum there."""
    from generator.link.values import environment_values
    from generator.reference.environment import split_sum
    from generator.runtime.placement import load_placement

    eye, vp = load_placement(scene).camera(W, H)
    inv = np.linalg.inv(vp)
    x, y = np.meshgrid((np.arange(W) + 0.5) / W * 2 - 1, (np.arange(H) + 0.5) / H * 2 - 1)
    far = np.stack([x, y, np.ones_like(x), np.ones_like(x)], -1) @ inv.T
    d = far[..., :3] / far[..., 3:] - eye
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ eye
    disc = b * b - (eye @ eye - 1.0)
    hit = disc > 0
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    P = eye + t[..., None] * d
    N, V = P, -d
    env = inputs.environments["sky"]
    specs = {f"sh{k}": None for k in range(9)}
    sh = np.array([env.sh[k] for k in specs])
    table = inputs.tables[METAL]
    f0 = np.array(scene.materials["metal"].params["f0"])
    vals = environment_values(scene, "none", {"intensity": _Spec(1.0), "radiance_levels": _Spec(7.0)})
    want = split_sum(N.reshape(-1, 3), V.reshape(-1, 3), np.zeros(3), f0, 0.2, sh, vals["intensity"],
                     env.levels, table).reshape(H, W, 3)
    return hit, np.einsum("...i,...i->...", N, V), want


class _Spec:
    def __init__(self, default):
        self.default = default


def _compare(got, scene, inputs, what):
    hit, nv, want = _expected(scene, inputs)
    use = hit & (nv >= 0.3) & (want.max(-1) < 0.95)
    assert use.sum() > 300, use.sum()
    g, w = _linear(got)[use] @ LUMA, want[use] @ LUMA
    rel = np.abs(g - w) / np.maximum(w, 1e-3)
    assert np.median(rel) <= 0.015 and np.percentile(rel, 95) <= 0.05, \
        f"{what}: median {np.median(rel):.4f}, 95th {np.percentile(rel, 95):.4f}, max {rel.max():.4f}"
    assert got[~hit].max() < 0.1  # the background stays the clear colour
    return rel


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_a_metal_sphere_reflects_its_environment_as_the_split_sum_says(lib, device, tmp_path):
    from generator.assemble.environments import bake

    _sunless_hdr(tmp_path / "sky.hdr")
    scene = _load(lib, tmp_path, _scene('image = "sky.hdr"\nrotation = 40.0\nsize = 16'))
    (perm,) = scene.permutations.values()
    assert perm.canonical().endswith(";environment=split_sum") and "lights=-" in perm.canonical()
    inputs = bake(scene, lib)
    for language in ("glsl", "hlsl", "wgsl"):
        got = _render(lib, device, scene, tmp_path, language, inputs)
        assert got.max() > 0.3  # not black: the sky, reflected
        _compare(got, scene, inputs, language)


@pytest.mark.lavapipe
@pytest.mark.toolchain
def test_the_default_sky_with_its_sun_lights_a_metal(lib, device, tmp_path):
    from generator.assemble.environments import bake

    scene = _load(lib, tmp_path, _scene('sky = "default"\nintensity = 0.5\nsize = 8'))
    inputs = bake(scene, lib)
    got = _render(lib, device, scene, tmp_path, "glsl", inputs)
    hit, _, _ = _expected(scene, inputs)
    assert got[hit].mean() > 0.2 and got[hit][:, 2].mean() > got[hit][:, 0].mean()  # a bluish sky in a metal


def test_a_brdf_the_environment_cannot_light_is_a_located_error_naming_the_material(lib, tmp_path):
    for brdf, what in (("lambert+phong", "not a microfacet term"),
                       ("microfacet(ndf=ggx,fresnel=conductor_exact,vis=smith_ggx_height_correlated)",
                        "Fresnel 'conductor_exact' reads"), ("lambert", "needs a microfacet specular term")):
        with pytest.raises(SourceError) as e:
            _load(lib, tmp_path, _scene('sky = "default"', brdf, params=""))
        msg = str(e.value)
        assert msg.startswith(f"{tmp_path / 's.toml'}:10:1: material 'metal', lit by environment 'sky' (light set "
                              "'none'): image-based lighting "), msg
        assert what in msg and " — " in msg, msg


@pytest.mark.parametrize("env,extra,at,what", [
    ('sky = "default"\nintesity = 2.0', "", "8:1", "unknown key 'intesity' in [environments.sky] — did you mean "
     "'intensity'?"),
    ('sky = "defualt"', "", "7:1", "unknown sky 'defualt' — did you mean 'default'?"),
    ('sky = "default"\nimage = "x.hdr"', "", "8:1", "needs one of image and sky, not both"),
    ('image = "missing.hdr"', "", "7:1", "image 'missing.hdr' not found"),
    ('sky = "default"\nsize = 24', "", "8:1", "size 24 is not a power of two"),
    ('sky = "default"\nlight_sets = ["nope"]', "", "8:1", "lights unknown light set 'nope'"),
    ('sky = "default"\nbrick = "split_summ"', "", "8:1", "unknown environment brick 'split_summ' — did you mean "
     "'split_sum'?"),
])
def test_bad_environment_keys_are_located_errors(lib, tmp_path, env, extra, at, what):
    with pytest.raises(SourceError) as e:
        _load(lib, tmp_path, _scene(env, extra=extra))
    msg = str(e.value)
    assert msg.startswith(f"{tmp_path / 's.toml'}:{at}: ") and what in msg, msg


def test_an_unknown_scene_environment_is_located_with_the_closest_name(lib, tmp_path):
    with pytest.raises(SourceError) as e:
        _load(lib, tmp_path, _scene('sky = "default"').replace('environment = "sky"', 'environment = "skye"'))
    assert str(e.value).startswith(f"{tmp_path / 's.toml'}:3:1: [scene] environment 'skye' is not declared — did "
                                   "you mean 'sky'?"), str(e.value)


def test_keys_without_an_environment_are_unchanged_and_the_ubershader_refuses_one(lib, tmp_path):
    from generator.compose.uber import compose_ubershader
    plain = _load(lib, tmp_path / "plain", _scene('sky = "default"').replace('environment = "sky"\n', ""))
    (perm,) = plain.permutations.values()
    assert "environment" not in perm.canonical() and not plain.environment_of
    lit = _load(lib, tmp_path / "lit", _scene('sky = "default"'))
    (p,) = lit.permutations.values()
    assert p.canonical() == perm.canonical() + ";environment=split_sum" and p.hash != perm.hash
    with pytest.raises(SourceError) as e:
        compose_ubershader([p], lib, ("glsl",))
    assert str(e.value).startswith(f"{tmp_path / 'lit' / 's.toml'}:6:1: the ubershader does not draw environments"), \
        str(e.value)
