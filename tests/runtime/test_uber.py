"""The fallback ubershader: linked from the same bricks as the matrix, every permutation reachable, same results.

Hoffman & Baker 2006: "Hybrid — use Ubershader as fallback, shader matrix as a cache".
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from generator.library.bricks import load_library
from generator.spec.permutation import LightKey, Permutation

REPO = Path(__file__).resolve().parents[2]
LANGS = ("glsl", "hlsl", "wgsl")
C = "constants(normal=vertex)"
PERMS = [Permutation("lambert+blinn_phong_normalized", (LightKey("point", "none"), LightKey("directional", "none")),
                     C, "exposure"),
         Permutation("microfacet(ndf=ggx)", (LightKey("directional", "none"),), C, "exposure"),
         Permutation("lobes(lobes=2)", (LightKey("point", "none"), LightKey("point", "none")), C, "exposure")]
LIGHTS = {"point": [{"position": [0.5, 2.0, 1.0], "color": [2.0, 1.5, 1.0]},
                    {"position": [-2.0, 1.0, 0.5], "color": [0.4, 0.5, 0.9]}],
          "directional": [{"direction": [0.3, 0.9, 0.3], "color": [1.0, 1.0, 0.8]}]}


@pytest.fixture(scope="module")
def lib():
    return load_library([REPO / "tests" / "bricks" / "link"])


@pytest.fixture(scope="module")
def example_build(tmp_path_factory):
    from generator.assemble import BuildContext, build
    from generator.scene.load import load_scene

    base = load_library()
    out = tmp_path_factory.mktemp("uber")
    res = build(load_scene(REPO / "scenes" / "example.toml", base), out, BuildContext(base))
    assert res.ok, res.failures
    return out, json.loads((out / "manifest.json").read_text())


@pytest.mark.toolchain
def test_example_ubershader_builds_in_every_language_and_its_spirv_matches_its_interface(example_build):
    from generator.analysis.reflect import flatten_layout, reflect

    out, manifest = example_build
    uber = manifest["ubershader"]
    assert uber["status"] == "ok"
    t = uber["tables"]
    assert len(t["variants"]) == 5 and set(t["light_types"]) == {"point", "directional"}
    assert set(t["shadows"]) == {"none", "shadow_map"} and t["shadow_maps"] == 1
    frag = uber["interface"]["frag"]
    want = {(b["set"], b["binding"]): b for b in frag["storage_blocks"] + frag["uniform_blocks"]}
    for lang in LANGS:
        entry = reflect((out / uber["languages"][lang]["frag"]["spirv"]).read_bytes()).entry("frag")
        got = {(r.set, r.binding): r for r in entry.resources}
        for key, b in want.items():
            assert key in got, (lang, b["name"])
        mb = got[(1, 1)]
        assert mb.kind == "storage_buffer" and mb.readonly
        m = t["material_entry"]["data_vec4s"]
        assert flatten_layout(mb.members) == [f"0:{{0:ivec4,16:vec4[{m}] s16}}[] s{16 * (1 + m)}"], lang
        textures = {(x["set"], x["binding"]) for x in frag["textures"]}
        assert textures <= set(got) and all(got[k].kind == "sampled_image" for k in textures), lang


def test_every_permutation_is_reachable_and_a_missing_value_is_named(lib):
    from generator.link.uber import coverage, link_ubershader

    full = link_ubershader(PERMS, lib, kernel=True)
    assert coverage(full, PERMS, lib) == []
    part = link_ubershader(PERMS[1:], lib, kernel=True)
    problems = coverage(part, PERMS, lib)
    assert any("brdf=lambert+blinn_phong_normalized" in p and "is no variant" in p for p in problems), problems
    shadowed = Permutation("lambert", (LightKey("directional", "shadow_map"),), C)
    problems = coverage(full, PERMS + [shadowed], lib)
    assert any("shadow filter 'shadow_map'" in p for p in problems), problems


def _case(perm):
    """The uber kernel's light entries and the specialized shade kernel's values for one permutation."""
    lights, static, seen = [], {"o_ev": 0.5}, {"point": 0, "directional": 0}
    for i, lk in enumerate(perm.lights):
        v = LIGHTS[lk.light][seen[lk.light]]
        seen[lk.light] += 1
        lights.append((lk.light, lk.shadow, v))
        static.update({f"l{i}_{k}": x for k, x in v.items()})
    return lights, static


@pytest.fixture(scope="module")
def surface():
    rng = np.random.default_rng(4)
    n = 256
    v = rng.normal(size=(2, n, 3))
    Ng, V = (x / np.linalg.norm(x, axis=1)[:, None] for x in v)
    return rng.uniform(-1.0, 1.0, (n, 3)), Ng, V


@pytest.mark.parametrize("target", ["numpy"] + [pytest.param(x, marks=[pytest.mark.lavapipe, pytest.mark.toolchain])
                                                for x in LANGS])
def test_ubershader_shades_every_permutation_like_its_specialized_shader(lib, surface, target, eval_session):
    """Per sample, the ubershader's shade() (material and lights from buffers, switches) equals the
    specialized permutation's: on lavapipe within 2 float32 ulp (the optimizer may contract a
    multiply-add differently inside a switch), in NumPy within the float32 rounding of the
    material data (the entry stores the Material block's float32 bytes)."""
    from generator.eval.shade import shade_samples, uber_samples
    from generator.link.uber import link_ubershader

    if target != "numpy":
        from generator.runtime.probe import lavapipe_present
        from tests.conftest import require
        require(lavapipe_present(), "no lavapipe Vulkan device")
    P, Ng, V = surface
    u = link_ubershader(PERMS, lib, kernel=True)
    for k, perm in enumerate(PERMS):
        assert u.variants[k].key == (perm.brdf, perm.packing, perm.output)
        lights, static = _case(perm)
        got = uber_samples(PERMS, P, Ng, V, np.zeros(len(P), int), [(k, {"o_ev": 0.5})], lights, target=target, lib=lib,
                           session=eval_session)
        want = shade_samples(perm, P, Ng, V, values=static, target=target, lib=lib, session=eval_session)
        rtol = 2 * 2.0 ** -23 if target != "numpy" else 1e-6
        np.testing.assert_allclose(got, want, rtol=rtol, atol=rtol * np.abs(want).max(), err_msg=f"{target} {k}")
        assert np.abs(want[:, :3]).max() > 0.0


def test_one_dispatch_shades_samples_of_different_materials(lib, surface):
    """The material index is read per sample (P.w in the kernel): three materials in one call."""
    from generator.eval.shade import uber_samples

    P, Ng, V = surface
    ids = np.arange(len(P)) % 3
    lights = [("point", "none", LIGHTS["point"][0])]
    mats = [(k, {"o_ev": 0.0}) for k in range(3)]
    mixed = uber_samples(PERMS, P, Ng, V, ids, mats, lights, lib=lib)
    for k in range(3):
        alone = uber_samples(PERMS, P, Ng, V, np.full(len(P), k), mats, lights, lib=lib)
        np.testing.assert_array_equal(mixed[ids == k], alone[ids == k])


@pytest.mark.parametrize("target", ["numpy"] + [pytest.param(x, marks=[pytest.mark.lavapipe, pytest.mark.toolchain])
                                                for x in LANGS])
def test_specialization_constant_ubershader_matches_the_buffer_id_one(lib, surface, target, eval_session):
    """The variant as a specialization constant (one pipeline per variant from one module) shades like the
    ubershader that reads it from the material entry."""
    from generator.eval.shade import uber_samples

    if target != "numpy":
        from generator.runtime.probe import lavapipe_present
        from tests.conftest import require
        require(lavapipe_present(), "no lavapipe Vulkan device")
    P, Ng, V = surface
    lights = [("point", "none", LIGHTS["point"][0]), ("directional", "none", LIGHTS["directional"][0])]
    for k in range(len(PERMS)):
        by_id = uber_samples(PERMS, P, Ng, V, np.zeros(len(P), int), [(k, {})], lights, target=target, lib=lib,
                             session=eval_session)
        spec = uber_samples(PERMS, P, Ng, V, np.zeros(len(P), int), [(k, {})], lights, target=target, lib=lib,
                            variant=k, session=eval_session)
        np.testing.assert_allclose(spec, by_id, rtol=2 * 2.0 ** -23, atol=1e-7, err_msg=f"{target} {k}")


@pytest.mark.toolchain
def test_specialization_constant_ubershader_keeps_one_module_in_glsl_and_hlsl(lib):
    from generator.compose.uber import compose_uber_kernel
    from generator.toolchain import CompileJob, compile_many

    c, _ = compose_uber_kernel(PERMS, lib, specialized=True)
    jobs = [CompileJob(f"s.comp.{s.language}", s.language, "comp", s.text, line_map=tuple(s.line_map),
                       overrides=(("0", 1),) if s.language == "wgsl" else ())
            for s in c.sources]
    res = compile_many(jobs, optimize=False)
    import struct as st
    for key, r in res.items():
        assert r.ok, r.errors()
        words = st.unpack(f"<{len(r.spirv) // 4}I", r.spirv)
        spec_id = any(words[i] & 0xFFFF == 71 and words[i + 2] == 1 for i in range(5, len(words) - 3))  # OpDecorate SpecId
        assert spec_id == (".glsl" in key or ".hlsl" in key), key  # WGSL: naga resolves the override


@pytest.mark.parametrize("target", ["numpy"] + [pytest.param(x, marks=[pytest.mark.lavapipe, pytest.mark.toolchain])
                                                for x in LANGS])
def test_ubershader_with_a_tangent_frame_and_a_scalar_splat_matches_the_specialized_shader(lib, surface, target,
                                                                                           eval_session):
    from generator.eval.shade import shade_samples, uber_samples

    if target != "numpy":
        from generator.runtime.probe import lavapipe_present
        from tests.conftest import require
        require(lavapipe_present(), "no lavapipe Vulkan device")
    P, Ng, V = surface
    rng = np.random.default_rng(9)
    t = rng.normal(size=(len(P), 3))
    t -= np.sum(t * Ng, 1)[:, None] * Ng  # perpendicular to the normal
    T = np.c_[t / np.linalg.norm(t, axis=1)[:, None], np.where(rng.random(len(P)) < 0.5, -1.0, 1.0)]
    perm = Permutation("microfacet(ndf=aniso_ggx)", (LightKey("point", "none"),), "constants(normal=vertex_tangent)")
    light = {"position": [0.5, 2.0, 1.0], "color": 3.0}  # a scalar for a vec3 splats on both paths
    got = uber_samples([perm], P, Ng, V, np.zeros(len(P), int), [(0, {})], [("point", "none", light)],
                       target=target, lib=lib, T=T, session=eval_session)
    want = shade_samples(perm, P, Ng, V, T=T, values={"l0_position": light["position"], "l0_color": [3.0] * 3},
                         target=target, lib=lib, session=eval_session)
    rtol = 2 * 2.0 ** -23 if target != "numpy" else 1e-6
    np.testing.assert_allclose(got, want, rtol=rtol, atol=rtol * np.abs(want).max())
    assert np.abs(want[:, :3]).max() > 0.0


def test_a_scene_without_lights_gets_an_ubershader_without_a_light_loop(lib):
    from generator.lang import ir
    from generator.link.uber import link_ubershader

    u = link_ubershader([Permutation("lambert", (), C)], lib)
    assert u.light_types == [] and u.interface().block("LightBuffer") is None
    assert not any(isinstance(n, ir.For) for f in u.program.functions for n in ir.walk_body(f.body))


@pytest.mark.toolchain
def test_the_build_fails_naming_a_value_the_ubershader_cannot_reach(tmp_path, monkeypatch):
    """An ubershader that lost a variant (simulated by linking it from all but one permutation) fails the build."""
    import generator.compose.uber as uber
    from generator.assemble import BuildContext, build
    from generator.scene.load import load_scene

    base = load_library()
    scene = load_scene(REPO / "scenes" / "example.toml", base)
    real = uber.compose_ubershader
    monkeypatch.setattr(uber, "compose_ubershader", lambda perms, lib, langs: real(perms[1:], lib, langs))
    res = build(scene, tmp_path / "out", BuildContext(base, languages=("glsl",)))
    assert not res.ok
    msg = "\n".join(res.failures)
    assert "ubershader" in msg and "coverage:" in msg and "is no variant of the ubershader" in msg
    first = sorted(scene.permutations.items())[0][1]
    assert f"brdf={first.brdf}" in msg
