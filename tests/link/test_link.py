"""The link stage: any set of nodes in one program, slot fillers bound by name, kind contracts, one parameter policy.

Proofs by construction (issue: the link-stage redesign): three fillers of one host behind a
switch; an anisotropic NDF filler reading HdotT/HdotB against a float64 formula; an output
brick with a parameter; the errors that name both bricks or the missing tangent frame.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from generator.lang import SourceError
from generator.library.bricks import load_brick, load_library

REPO = Path(__file__).resolve().parents[2]
LINK_BRICKS = REPO / "tests" / "bricks" / "link"
NDFS = ["microfacet(ndf=ggx)", "microfacet(ndf=beckmann)", "microfacet(ndf=blinn_phong)"]
LANGS = ("glsl", "hlsl", "wgsl")


@pytest.fixture(scope="module")
def lib():
    return load_library([LINK_BRICKS])


def _unit(rng, n, upper=True):
    v = rng.normal(size=(n, 3))
    if upper:
        v[:, 2] = np.abs(v[:, 2])
    return v / np.linalg.norm(v, axis=1)[:, None]


@pytest.fixture(scope="module")
def frame():
    rng = np.random.default_rng(7)
    n = 512
    L, V = _unit(rng, n), _unit(rng, n)
    N = np.tile([0.0, 0.0, 1.0], (n, 1))
    phi = rng.uniform(0, 2 * np.pi, n)
    T = np.stack([np.cos(phi), np.sin(phi), np.zeros(n)], 1)
    return L, V, N, T, rng.integers(0, 3, n)


# ------------------------------------------------------------------ one program, many fillers

def test_fillers_of_one_host_link_into_one_program_deterministically(lib):
    from generator.link import switch_program
    from generator.backends import get_target

    ep = switch_program(NDFS, lib)
    names = [f.name for f in ep.program.functions]
    hosts = [n for n in names if n.startswith("microfacet_") and n.endswith("_specular")]
    assert len(hosts) == 3 and len(set(names)) == len(names)
    assert {"ggx_ndf", "beckmann_ndf", "blinn_phong_ndf", "brdf_switch"} <= set(names)
    again = switch_program(NDFS, load_library([LINK_BRICKS]))
    glsl = get_target("glsl")
    text = glsl.emit(ep.program.structs, ep.program.functions).text
    assert text == glsl.emit(again.program.structs, again.program.functions).text
    import hashlib
    import os
    import subprocess
    import sys
    code = ("import hashlib; from pathlib import Path; from generator.library.bricks import load_library; "
            "from generator.link import switch_program; from generator.backends import get_target; "
            f"ep = switch_program({NDFS!r}, load_library([Path({str(LINK_BRICKS)!r})])); "
            "print(hashlib.sha256(get_target('glsl').emit(ep.program.structs, ep.program.functions).text.encode())"
            ".hexdigest())")
    for seed in ("1", "2"):  # another process, another hash seed: the same bytes
        env = {**os.environ, "PYTHONHASHSEED": seed}
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=REPO)
        assert out.stdout.strip() == hashlib.sha256(text.encode()).hexdigest(), out.stderr


def test_switch_program_equals_the_specialized_programs_in_numpy(lib, frame):
    from generator.eval.evaluate import evaluate
    from generator.eval.switch import evaluate_switch

    L, V, N, _, ids = frame
    got = evaluate_switch(NDFS, ids, L, V, N, params={"alpha": 0.3}, lib=lib)
    each = np.stack([evaluate(s, L, V, N, params={"alpha": 0.3}, target="numpy", lib=lib) for s in NDFS])
    assert np.array_equal(got, each[ids, np.arange(len(ids))])
    assert len(set(ids.tolist())) == 3


@pytest.mark.toolchain
def test_switch_kernel_compiles_and_validates_in_every_language(lib):
    from generator.compose import compose_eval
    from generator.link import switch_program
    from generator.toolchain import CompileJob, compile_many

    ep = switch_program(NDFS, lib)
    c = compose_eval(ep.spec, lib, ep=ep)
    jobs = [CompileJob(f"switch.comp.{s.language}", s.language, "comp", s.text, line_map=tuple(s.line_map))
            for s in c.sources]
    results = compile_many(jobs)
    assert all(r.ok for r in results.values()), {k: r.errors() for k, r in results.items()}
    heads = {"glsl": "switch (id) {", "hlsl": "switch (id) {", "wgsl": "switch id {"}
    assert all(heads[s.language] in s.text for s in c.sources)


# ------------------------------------------------------------------ a filler reading the tangent frame

def _aniso_expected(L, V, N, T, alpha, alpha_u, alpha_v, f0):
    """float64: microfacet(ndf=aniso_ggx) = reference microfacet(ndf=ggx) · D_aniso / D_ggx (same F, Vis)."""
    from generator.library.inputs import float64_geometry
    from generator.reference import d_ggx, reference_brdf

    g = float64_geometry(L, V, N, T)
    x, y = g["HdotT"] / alpha_u, g["HdotB"] / alpha_v
    d_aniso = 1.0 / (np.pi * alpha_u * alpha_v * (x * x + y * y + g["NdotH"] ** 2) ** 2)
    ref = reference_brdf("microfacet(ndf=ggx)", L, V, N, params={"alpha": alpha, "f0": f0})
    with np.errstate(all="ignore"):
        ratio = np.where(ref[:, 0] > 0, d_aniso / d_ggx(g["NdotH"], g["NxH2"], alpha), 0.0)
    return ref * ratio[:, None]


def test_anisotropic_filler_reads_HdotT_HdotB_threaded_through_its_host(lib, frame):
    from generator.eval.evaluate import evaluate, program

    L, V, N, T, _ = frame
    ep = program("microfacet(ndf=aniso_ggx)", lib)
    host = next(f for f in ep.program.functions if f.name.startswith("microfacet_"))
    assert {"HdotT", "HdotB", "alpha_u", "alpha_v"} <= {p.name for p in host.params}
    assert ep.tangent and list(ep.params) == ["alpha", "f0", "alpha_u", "alpha_v"]
    p = {"alpha": 0.3, "f0": [0.9, 0.6, 0.3], "alpha_u": 0.15, "alpha_v": 0.45}
    got = evaluate("microfacet(ndf=aniso_ggx)", L, V, N, T, params=p, target="numpy", lib=lib)
    want = _aniso_expected(L, V, N, T, 0.3, 0.15, 0.45, p["f0"])
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    iso = evaluate("microfacet(ndf=aniso_ggx)", L, V, N, T, params={**p, "alpha_u": 0.3, "alpha_v": 0.3},
                   target="numpy", lib=lib)
    ggx = evaluate("microfacet(ndf=ggx)", L, V, N, params={"alpha": 0.3, "f0": p["f0"]}, target="numpy", lib=lib)
    np.testing.assert_allclose(iso, ggx, rtol=1e-12)  # α_u = α_v: Walter's isotropic GGX


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_anisotropic_filler_on_lavapipe_against_float64(lib, frame, language):
    from generator.eval.evaluate import evaluate
    from generator.runtime.probe import lavapipe_present
    from tests.conftest import require

    require(lavapipe_present(), "no lavapipe Vulkan device")
    L, V, N, T, _ = frame
    p = {"alpha": 0.3, "f0": [0.9, 0.6, 0.3], "alpha_u": 0.15, "alpha_v": 0.45}
    got = evaluate("microfacet(ndf=aniso_ggx)", L, V, N, T, params=p, target=language, lib=lib)
    want = _aniso_expected(*(x.astype(np.float32).astype(np.float64) for x in (L, V, N, T)), 0.3, 0.15, 0.45,
                           p["f0"])
    # float32 arithmetic on f up to ~1/(π α_u α_v): relative 1e-4, absolute 2^-20 of the peak
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=2.0 ** -20 * np.abs(want).max())


def test_tangent_brdf_needs_a_packing_with_a_tangent_frame(lib, tmp_path):
    from generator.scene.load import load_scene

    scene = tmp_path / "s.toml"
    body = ('[scene]\nname = "t"\n[materials.brushed]\nbrdf = "microfacet(ndf=aniso_ggx)"\npacking = "{p}"\n'
            '[lights.sun]\ntype = "directional"\n[light_sets]\nall = ["sun"]\n'
            '[[objects]]\nname = "pan"\nmaterial = "brushed"\nlights = "all"\n')
    scene.write_text(body.format(p="constants"))
    with pytest.raises(SourceError) as e:
        load_scene(scene, lib)
    msg = str(e.value)
    assert f"{scene}:5:" in msg and "HdotB, HdotT (the tangent frame)" in msg and "normal=vertex_tangent" in msg
    scene.write_text(body.format(p="constants(normal=vertex_tangent)"))
    s = load_scene(scene, lib)
    assert len(s.permutations) == 1


# ------------------------------------------------------------------ parameterized output brick

def test_output_brick_parameter_reaches_the_material_block_and_scales_the_output(lib):
    from generator.link import link_permutation
    from generator.spec.permutation import LightKey, Permutation
    from generator.backends.numpy.emit import NumpyTarget

    perm = Permutation("lambert", (LightKey("directional", "none"),), "constants(normal=vertex)", "exposure")
    lp = link_permutation(perm, lib)
    ev = next(s for s in lp.material if s.param == "ev")
    assert ev.name == "o_ev" and lp.interface.block("Material").as_dict()["parameters"][-1]["name"] == "ev"
    t = NumpyTarget()
    shade = t.load(t.emit(lp.program.structs, lp.program.functions), np.dtype("float64"))["shade"]
    args = {"P": np.zeros((1, 3)), "Ng": np.array([[0.0, 0.0, 1.0]]), "V": np.array([[0.0, 0.0, 1.0]]),
            "m_rho_d": [0.5, 0.5, 0.5], "l0_direction": [0.0, 0.0, 1.0], "l0_color": [1.0, 1.0, 1.0]}
    names = [n for n, _ in lp.glue.signature]
    base = np.asarray(shade(*[args.get(n, 0.0) for n in names]))
    two = np.asarray(shade(*[args.get(n, 1.0 if n == "o_ev" else 0.0) for n in names]))
    np.testing.assert_allclose(base[..., :3], 0.5, rtol=1e-12)  # π · (ρ/π) · 1 · cos 0
    np.testing.assert_allclose(two[..., :3], 2.0 * base[..., :3], rtol=1e-12)


@pytest.mark.toolchain
def test_output_brick_with_a_parameter_compiles_in_every_language(lib):
    from generator.compose import compose_permutation
    from generator.spec.permutation import LightKey, Permutation
    from generator.toolchain import CompileJob, compile_many

    perm = Permutation("lambert", (LightKey("point", "none"),), "constants(normal=vertex)", "exposure")
    c = compose_permutation(perm, lib)
    jobs = [CompileJob(f"x.{s.stage}.{s.language}", s.language, s.stage, s.text, line_map=tuple(s.line_map))
            for s in c.sources]
    results = compile_many(jobs)
    assert all(r.ok for r in results.values()), {k: r.errors() for k, r in results.items()}


# ------------------------------------------------------------------ contracts and the parameter policy

def _brick(tmp_path, rel, text):
    path = tmp_path / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_filler_reading_an_unknown_input_is_located_with_the_closest_name(tmp_path):
    p = _brick(tmp_path, "ndf/bad.py", '"""Bad."""\nBRICK = {"kind": "ndf", "cite": "x"}\n\n\n'
               'def ndf(NdotH: float, HdotTT: float) -> float:\n    return NdotH\n')
    with pytest.raises(SourceError) as e:
        load_brick(p)
    assert ":5:" in str(e.value) and "HdotTT" in str(e.value) and "did you mean 'HdotT'" in str(e.value)


def test_output_brick_must_take_color(tmp_path):
    p = _brick(tmp_path, "output/bad.py", '"""Bad."""\nBRICK = {"kind": "output", "cite": "x"}\n\n\n'
               'def output(c: vec3) -> vec4:\n    return vec4(c, 1.0)\n')
    with pytest.raises(SourceError, match=r"must take 'color: vec3'"):
        load_brick(p)


def test_one_name_two_types_or_disjoint_ranges_is_an_error_naming_both_bricks(tmp_path):
    from generator.spec.resolve import resolve_brdf

    base = load_library()
    d = tmp_path / "b"
    _brick(d, "diffuse/odd.py", '"""Odd."""\nBRICK = {"kind": "diffuse", "cite": "x", "params": '
           '{"alpha": {"type": "vec3", "default": [0.1, 0.1, 0.1]}}}\n\n\ndef diffuse(alpha: vec3) -> vec3:\n'
           '    return alpha\n')
    _brick(d, "diffuse/far.py", '"""Far."""\nBRICK = {"kind": "diffuse", "cite": "x", "params": '
           '{"alpha": {"type": "float", "range": [2.0, 3.0], "default": 2.5}}}\n\n\ndef diffuse(alpha: float) -> vec3:\n'
           '    return vec3(alpha)\n')
    lib = load_library([d])
    for spec, what in [("odd+microfacet", "is float here but vec3 in"), ("far+microfacet", "disjoint from [2.0, 3.0]")]:
        with pytest.raises(SourceError) as e:
            resolve_brdf(spec, lib)
        msg = str(e.value)
        assert what in msg, msg
        assert "microfacet.py" in msg and ("odd.py" in msg or "far.py" in msg), msg
    assert resolve_brdf("lambert+microfacet", base).params["alpha"].range == (0.0, 1.0)


# ------------------------------------------------------------------ a light loop over a storage buffer

DYNAMIC = ("lambert+blinn_phong_normalized", "constants(normal=vertex)")


def test_fragment_loops_over_a_storage_buffer_of_lights_with_a_runtime_count(lib):
    """shade() with *point lights read from a buffer of 3 = shade() with 3 static point lights (NumPy)."""
    from generator.link import link_permutation
    from generator.spec.permutation import LightKey, Permutation
    from generator.backends.numpy.emit import NumpyTarget

    brdf, packing = DYNAMIC
    dyn = link_permutation(Permutation(brdf, (LightKey("point", "none", dynamic=True),), packing), lib)
    static = link_permutation(Permutation(brdf, (LightKey("point", "none"),) * 3, packing), lib)
    assert dyn.perm.canonical().startswith("brdf=lambert+blinn_phong_normalized;lights=*point/none;")
    blocks = {b.name: b for b in dyn.interface.blocks}
    assert blocks["LightBuffer0"].kind == "storage" and (blocks["LightBuffer0"].set, blocks["LightBuffer0"].binding) == (0, 2)
    assert "Lights" not in blocks  # no static light parameters left
    rng = np.random.default_rng(3)
    pos, col = rng.uniform(-3, 3, (3, 3)), rng.uniform(0, 2, (3, 3))
    P, Ng = np.array([[0.1, 0.0, -0.2]]), np.array([[0.0, 0.6, 0.8]])
    V = np.array([[0.0, 0.0, 1.0]])
    mat = {"m_rho_d": [0.6, 0.5, 0.4], "m_n": 32.0, "m_f0": [0.04, 0.04, 0.04]}
    t = NumpyTarget()
    slots = {s.param: s for s in blocks["LightBuffer0"].slots}  # each element: vec4 data[2], packed
    assert [(slots[k].index, slots[k].swizzle) for k in ("position", "color")] == [(0, ".xyz"), (1, ".xyz")]
    data = np.zeros((3, 2, 4))
    data[:, 0, :3], data[:, 1, :3] = pos, col
    res = {"light_buffer0": {"data": data}}
    f_dyn = t.load(t.emit(dyn.program.structs, dyn.program.functions, dyn.program.globals),
                   np.dtype("float64"), resources=res)["shade"]
    f_static = t.load(t.emit(static.program.structs, static.program.functions), np.dtype("float64"))["shade"]
    args = {"P": P, "Ng": Ng, "V": V, **mat}
    for i in range(3):
        args[f"l{i}_position"], args[f"l{i}_color"] = pos[i], col[i]
    got = np.asarray(f_dyn(*[args[n] for n, _ in dyn.glue.signature]))
    want = np.asarray(f_static(*[args[n] for n, _ in static.glue.signature]))
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert want[..., :3].max() > 0.0


@pytest.mark.toolchain
def test_buffer_light_loop_compiles_and_its_spirv_declares_the_storage_block(lib):
    from generator.analysis.reflect import flatten_layout, reflect
    from generator.compose import compose_permutation
    from generator.spec.permutation import LightKey, Permutation
    from generator.toolchain import CompileJob, compile_many

    brdf, packing = DYNAMIC
    perm = Permutation(brdf, (LightKey("directional", "shadow_map"), LightKey("point", "none", dynamic=True)), packing)
    c = compose_permutation(perm, lib)
    jobs = [CompileJob(f"d.{s.stage}.{s.language}", s.language, s.stage, s.text, line_map=tuple(s.line_map))
            for s in c.sources]
    results = compile_many(jobs)
    want = c.interface.block("LightBuffer1")
    assert (want.set, want.binding) == (0, 4)  # after the shadow map's image and sampler (2, 3)
    for key, r in results.items():
        assert r.ok, r.errors()
        if ".frag." in key:
            res = {(x.set, x.binding): x for x in reflect(r.spirv).entry("frag").resources}
            buf = res[(0, 4)]
            assert buf.kind == "storage_buffer" and buf.readonly, key
            assert flatten_layout(buf.members) == ["0:{0:vec4[2] s16}[] s32"], key


# ------------------------------------------------------------------ an array parameter whose count is in the key

LOBES = [[-1.0, 1.0, 8.0, 0.5], [-1.0, 1.0, 64.0, 0.3], [0.5, 0.5, 2.0, 0.1], [-0.9, 0.9, 200.0, 0.05]]


def _lobes_expected(L, V, N, lobes, count):
    nl, nv, lv = (np.sum(a * b, 1) for a, b in ((N, L), (N, V), (L, V)))
    f = np.zeros(len(L))
    for cxy, cz, n, rho in lobes[:count]:
        f += rho * np.maximum(cxy * (lv - np.minimum(nl, 1.0) * np.clip(nv, 1e-4, 1.0))
                              + cz * np.minimum(nl, 1.0) * np.clip(nv, 1e-4, 1.0), 0.0) ** n
    return np.where(nl[:, None] > 0.0, f[:, None], 0.0) * np.ones((1, 3))


def test_array_parameter_count_is_part_of_the_key(lib):
    from generator.spec.permutation import LightKey, Permutation, SpecError, parse_brdf, canonical
    from generator.link import link_permutation

    assert canonical(parse_brdf("lobes", lib)) == "lobes(lobes=4)"
    assert canonical(parse_brdf("lobes(lobes=2)", lib)) == "lobes(lobes=2)"
    with pytest.raises(SpecError, match="takes a count from 1 to 4"):
        parse_brdf("lobes(lobes=5)", lib)
    keys = {Permutation(f"lobes(lobes={n})", (LightKey("point", "none"),), "constants(normal=vertex)").hash
            for n in (1, 2, 3, 4)}
    assert len(keys) == 4
    lp = link_permutation(Permutation("lobes(lobes=2)", (LightKey("point", "none"),), "constants(normal=vertex)"), lib)
    params = lp.interface.block("Material").as_dict()["parameters"]
    assert [p["name"] for p in params] == ["lobes[0]", "lobes[1]", "lobes[2]", "lobes[3]"]
    assert [p["offset"] for p in params] == [0, 16, 32, 48]


@pytest.mark.parametrize("count", [1, 2, 4])
def test_array_parameter_lobes_in_numpy(lib, frame, count):
    from generator.eval.evaluate import evaluate

    L, V, N, _, _ = frame
    got = evaluate(f"lobes(lobes={count})", L, V, N, params={"lobes": LOBES}, target="numpy", lib=lib)
    np.testing.assert_allclose(got, _lobes_expected(L, V, N, LOBES, count), rtol=1e-12, atol=1e-300)


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_array_parameter_lobes_on_lavapipe(lib, frame, language):
    from generator.eval.evaluate import evaluate
    from generator.runtime.probe import lavapipe_present
    from tests.conftest import require

    require(lavapipe_present(), "no lavapipe Vulkan device")
    L, V, N, _, _ = frame
    for count in (1, 3):
        got = evaluate(f"lobes(lobes={count})", L, V, N, params={"lobes": LOBES}, target=language, lib=lib)
        want = evaluate(f"lobes(lobes={count})", L, V, N, params={"lobes": LOBES}, target="numpy",
                        dtype="float32", lib=lib)
        # pow with exponents up to 200 in float32: relative 1e-4 of each lobe's value
        np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6)


# ------------------------------------------------------------------ on lavapipe: the switch and a lookup texture

@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_switch_kernel_equals_the_three_specialized_kernels_per_sample(lib, frame, language):
    """One kernel, the BRDF chosen per sample by an id read from the samples buffer (L.w)."""
    from generator.eval.evaluate import evaluate
    from generator.eval.switch import evaluate_switch
    from generator.runtime.probe import lavapipe_present
    from tests.conftest import require

    require(lavapipe_present(), "no lavapipe Vulkan device")
    L, V, N, _, ids = frame
    p = {"alpha": 0.3, "f0": [0.9, 0.6, 0.3]}
    got = evaluate_switch(NDFS, ids, L, V, N, params=p, target=language, lib=lib)
    each = np.stack([evaluate(s, L, V, N, params=p, target=language, lib=lib) for s in NDFS])
    want = each[ids, np.arange(len(ids))]
    assert np.array_equal(got, want)  # bit for bit: the same float32 code runs for each sample
    assert np.any(got != evaluate_switch(NDFS, (ids + 1) % 3, L, V, N, params=p, target=language, lib=lib))


@pytest.fixture(scope="module")
def lut():
    rng = np.random.default_rng(11)
    return rng.uniform(0.0, 1.0, (16, 32, 4)).astype(np.float32)


def test_lut_brdf_in_numpy_samples_bilinearly(lib, frame, lut):
    from generator.eval.evaluate import EvalError, evaluate

    L, V, N, _, _ = frame
    got = evaluate("lut_diffuse", L, V, N, params={"rho_d": 0.8}, target="numpy", lib=lib, textures={"lut": lut})
    # float64 bilinear, clamp-to-edge, texel centres at (i + 0.5)/W (written here, not from the target)
    nl, nv = np.minimum(np.sum(N * L, 1), 1.0), np.clip(np.sum(N * V, 1), 1e-4, 1.0)
    h, w = lut.shape[:2]
    x, y = np.clip(nl * w - 0.5, 0, w - 1), np.clip(nv * h - 0.5, 0, h - 1)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    t = lut.astype(np.float64)[..., :3]
    s = (t[y0, x0] * (1 - fx) + t[y0, x1] * fx) * (1 - fy) + (t[y1, x0] * (1 - fx) + t[y1, x1] * fx) * fy
    want = np.where(np.sum(N * L, 1)[:, None] > 0, 0.8 * s / np.pi, 0.0)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    with pytest.raises(EvalError, match="samples texture lut"):
        evaluate("lut_diffuse", L, V, N, target="numpy", lib=lib)


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_lut_brdf_on_lavapipe_agrees_with_numpy(lib, frame, lut, language):
    """The eval kernel binds the table at set 0, bindings 3 (image) and 4 (sampler)."""
    from generator.eval.evaluate import evaluate, program
    from generator.runtime.probe import lavapipe_present
    from tests.conftest import require

    require(lavapipe_present(), "no lavapipe Vulkan device")
    tex = program("lut_diffuse", lib).interface.textures[0]
    assert (tex.set, tex.binding, tex.dim) == (0, 3, "2d")
    L, V, N, _, _ = frame
    got = evaluate("lut_diffuse", L, V, N, target=language, lib=lib, textures={"lut": lut})
    want = evaluate("lut_diffuse", L, V, N, target="numpy", dtype="float32", lib=lib, textures={"lut": lut})
    # lavapipe filters float textures in float32 (runtime tests: 4e-7 on a small table, values in [0, 1]):
    # stated tolerance 1e-6 of the largest value, relative
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-6 * np.abs(want).max())


@pytest.mark.toolchain
def test_texture_reading_brdfs_compile_as_fragment_shaders_with_their_bindings(lib):
    """2D and cube lookup textures of BRDF bricks become material textures of the permutation (set 1)."""
    from generator.analysis.reflect import reflect
    from generator.compose import compose_permutation
    from generator.spec.permutation import LightKey, Permutation
    from generator.toolchain import CompileJob, compile_many

    perm = Permutation("lut_diffuse+env_cube", (LightKey("point", "none"),), "constants(normal=vertex)")
    c = compose_permutation(perm, lib)
    texs = {t.param: t for t in c.interface.textures}
    assert (texs["lut"].set, texs["lut"].binding, texs["lut"].dim) == (1, 1, "2d")
    assert (texs["env"].set, texs["env"].binding, texs["env"].dim) == (1, 3, "cube")
    jobs = [CompileJob(f"t.{s.stage}.{s.language}", s.language, s.stage, s.text, line_map=tuple(s.line_map))
            for s in c.sources]
    for key, r in compile_many(jobs).items():
        assert r.ok, r.errors()
        if ".frag." in key:
            got = {(x.set, x.binding): (x.kind, x.dim) for x in reflect(r.spirv).entry("frag").resources}
            assert got[(1, 1)] == ("sampled_image", "2d") and got[(1, 3)] == ("sampled_image", "cube"), key
            assert got[(1, 2)][0] == got[(1, 4)][0] == "sampler", key


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_cube_texture_brdf_on_lavapipe_agrees_with_numpy(lib, frame, language):
    from generator.eval.evaluate import evaluate
    from generator.runtime.probe import lavapipe_present
    from tests.conftest import require

    require(lavapipe_present(), "no lavapipe Vulkan device")
    L, V, N, _, _ = frame
    size = 32
    cube = np.repeat(np.linspace(0.1, 0.9, 6)[:, None, None, None], size, 1).repeat(size, 2).repeat(4, 3)
    cube = cube.astype(np.float32)
    got = evaluate("env_cube", L, V, N, target=language, lib=lib, textures={"env": cube})
    want = evaluate("env_cube", L, V, N, target="numpy", dtype="float32", lib=lib, textures={"env": cube})
    # One value per face. Vulkan filters across face edges (seamless cube maps), NumPy within a face:
    # compare where the mirror direction is more than a texel away from every face edge.
    r = 2.0 * np.sum(N * V, 1)[:, None] * N - V
    a = np.sort(np.abs(r), 1)
    inner = a[:, 1] / a[:, 2] < 1.0 - 2.0 / size
    assert inner.sum() > len(r) // 2
    np.testing.assert_allclose(got[inner], want[inner], rtol=1e-6, atol=1e-9)
    assert len(np.unique(np.round(got[inner & (got[:, 0] > 0), 0], 6))) >= 5


def test_linked_programs_are_memoized_per_library_object(lib):
    from generator.eval.evaluate import program

    other = load_library([LINK_BRICKS])
    assert program("lobes", lib) is program("lobes", lib)
    assert program("lobes", other) is not program("lobes", lib)
    assert lib.serial != other.serial and ("eval_program", "lobes") in lib.memo


MIXED = ["lobes(lobes=2)", "lambert", "lut_diffuse", "lut_diffuse+blinn_phong_normalized", "lobes(lobes=1)"]


GPU = [pytest.param(x, marks=[pytest.mark.lavapipe, pytest.mark.toolchain]) for x in LANGS]


@pytest.mark.parametrize("target", ["numpy"] + GPU)
def test_switch_over_arrays_counts_and_a_shared_texture(lib, frame, lut, target):
    """Each BRDF keeps its own parameters (b<k>_<name>); a texture sampled by two BRDFs is bound once;
    per sample the switch equals that BRDF's own program (NumPy float64; on lavapipe bit for bit)."""
    from generator.eval.evaluate import evaluate
    from generator.eval.switch import evaluate_switch, switch_kernel_program

    if target != "numpy":
        from generator.runtime.probe import lavapipe_present
        from tests.conftest import require
        require(lavapipe_present(), "no lavapipe Vulkan device")
    ep = switch_kernel_program(MIXED, lib)
    assert [t.param for t in ep.interface.textures] == ["lut"]
    L, V, N, _, _ = frame
    ids = np.arange(len(L)) % len(MIXED)
    p = {"rho_d": 0.7, "b0_lobes": LOBES, "b4_lobes": LOBES[::-1]}
    got = evaluate_switch(MIXED, ids, L, V, N, params=p, target=target, lib=lib, textures={"lut": lut})
    for k, spec in enumerate(MIXED):
        own = {n: p[f"b{k}_{n}"] if f"b{k}_{n}" in p else p[n] for n in ep.own[k] if f"b{k}_{n}" in p or n in p}
        m = ids == k
        want = evaluate(spec, L[m], V[m], N[m], params=own, target=target, lib=lib,
                        textures={"lut": lut} if "lut" in spec else None)
        if target == "numpy":
            np.testing.assert_allclose(got[m], want, rtol=1e-12, atol=0.0)
        else:
            assert np.array_equal(got[m], want), spec


@pytest.mark.toolchain
def test_one_brick_at_two_array_counts_links_into_one_program(lib):
    from generator.link import Program
    from generator.spec.permutation import parse_brdf

    prog = Program()
    for spec in ("lobes(lobes=1)", "lobes(lobes=2)", "lobes"):
        prog.link(parse_brdf(spec, lib)[0])
    names = [f.name for f in prog.functions]
    assert len(names) == len(set(names)) == 3 and all(n.startswith("lobes_") for n in names)


def test_loader_refuses_what_the_link_stage_cannot_bind(tmp_path):
    buf = _brick(tmp_path, "diffuse/buf.py", '"""Buf."""\nBRICK = {"kind": "diffuse", "cite": "x"}\n\n\n'
                 'class Entry:\n    v: vec4\n\n\ntable: uniform_buffer[Entry, 4]\n\n\n'
                 'def diffuse(N: vec3) -> vec3:\n    return table[0].v.xyz\n')
    with pytest.raises(SourceError, match=r"buf\.py:9:\d+: buffer 'table' is declared .* binds no brick buffers"):
        load_brick(buf)
    arr = _brick(tmp_path, "light/arr.py", '"""Arr."""\nBRICK = {"kind": "light", "cite": "x", "params": '
                 '{"w": {"type": "float", "count": 2, "default": [1.0, 2.0]}}}\n\n\n'
                 'def light_dir(P: vec3) -> vec3:\n    return P\n\n\ndef light_radiance(P: vec3) -> vec3:\n    return P\n')
    with pytest.raises(SourceError, match="of a light brick has a count"):
        load_brick(arr)


def test_packing_that_provides_a_parameter_with_the_wrong_type_is_a_clear_error(tmp_path):
    from generator.link import link_permutation
    from generator.spec.permutation import LightKey, Permutation

    d = tmp_path / "b"
    _brick(d, "packing/rough.py", '"""Rough."""\nBRICK = {"kind": "packing", "cite": "x", '
           '"slots": {"normal": {"kind": "normal", "default": "vertex"}}}\n\n\n'
           'def get_alpha(uv: vec2) -> vec3:\n    return vec3(uv, 0.0)\n')
    lib = load_library([d])
    with pytest.raises(SourceError) as e:
        link_permutation(Permutation("microfacet", (LightKey("point", "none"),), "rough"), lib)
    assert "provides alpha as vec3" in str(e.value) and "rough.py:5" in str(e.value)
    assert "make get_alpha return float" in str(e.value)


@pytest.mark.toolchain
def test_scene_sets_output_parameters_per_material_and_the_upload_carries_them(lib, tmp_path):
    from generator.assemble import BuildContext, build
    from generator.scene.load import load_scene
    import json
    import struct as st

    scene = tmp_path / "s.toml"
    scene.write_text('[scene]\nname = "t"\noutput = "exposure"\n[materials.m]\nbrdf = "lambert"\n'
                     'params = { ev = 1.5 }\n[lights.sun]\ntype = "directional"\n[light_sets]\nall = ["sun"]\n'
                     '[[objects]]\nname = "o"\nmaterial = "m"\nlights = "all"\n')
    s = load_scene(scene, lib)
    res = build(s, tmp_path / "out", BuildContext(lib, languages=("glsl",)))
    assert res.ok, res.failures
    m = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert m["materials"]["m"]["params"]["ev"] == 1.5
    perm = m["permutations"][0]
    ev = next(x for x in perm["interface"]["frag"]["uniform_blocks"][-1]["parameters"] if x["name"] == "ev")
    assert st.unpack_from("<f", bytes.fromhex(perm["uploads"][0]["Material"]), ev["offset"])[0] == 1.5


# ------------------------------------------------------------------ the fragment glue on lavapipe (shade kernels)

SHADE_BRDF = "lambert+blinn_phong_normalized"


@pytest.fixture(scope="module")
def surface():
    rng = np.random.default_rng(5)
    n = 256
    P = rng.uniform(-1.0, 1.0, (n, 3))
    Ng, V = _unit(rng, n), _unit(rng, n)
    lights = {"position": rng.uniform(-3.0, 3.0, (3, 3)), "color": rng.uniform(0.1, 2.0, (3, 3))}
    return P, Ng, V, lights


@pytest.mark.lavapipe
@pytest.mark.toolchain
@pytest.mark.parametrize("language", LANGS)
def test_buffer_light_loop_and_exposure_run_on_lavapipe(lib, surface, language):
    """shade() of a fragment shader, run per sample in a compute kernel on lavapipe:
    a storage buffer of 3 point lights with a runtime count equals 3 static point lights,
    an exposure of +1 stop doubles the output, and both agree with the float64 NumPy glue."""
    from generator.eval.shade import shade_samples
    from generator.spec.permutation import LightKey, Permutation
    from generator.runtime.probe import lavapipe_present
    from tests.conftest import require

    require(lavapipe_present(), "no lavapipe Vulkan device")
    P, Ng, V, lights = surface
    packing = "constants(normal=vertex)"
    dyn = Permutation(SHADE_BRDF, (LightKey("point", "none", dynamic=True),), packing, "exposure")
    static = Permutation(SHADE_BRDF, (LightKey("point", "none"),) * 3, packing, "exposure")
    mat = {"m_rho_d": [0.6, 0.5, 0.4], "m_n": 32.0, "m_f0": [0.04, 0.04, 0.04]}
    lv = {f"l{i}_{k}": lights[k][i] for i in range(3) for k in ("position", "color")}
    got = shade_samples(dyn, P, Ng, V, values={**mat, "o_ev": 0.0}, buffers={0: lights}, target=language, lib=lib)
    want = shade_samples(static, P, Ng, V, values={**mat, **lv, "o_ev": 0.0}, target=language, lib=lib)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-7)  # the same sums, a loop against unrolled code
    ref = shade_samples(dyn, P, Ng, V, values={**mat, "o_ev": 0.0}, buffers={0: lights}, target="numpy", lib=lib)
    np.testing.assert_allclose(got, ref, rtol=1e-5, atol=1e-6 * np.abs(ref).max())
    up = shade_samples(dyn, P, Ng, V, values={**mat, "o_ev": 1.0}, buffers={0: lights}, target=language, lib=lib)
    np.testing.assert_allclose(up[:, :3], 2.0 * got[:, :3], rtol=1e-6)
    assert np.all(got[:, 3] == 1.0) and got[:, :3].max() > 0.0
    one = shade_samples(dyn, P, Ng, V, values={**mat, "o_ev": 0.0},
                        buffers={0: {k: v[:1] for k, v in lights.items()}}, target=language, lib=lib)
    assert np.all(one[:, :3] <= got[:, :3] + 1e-6) and np.any(one[:, :3] < got[:, :3])  # the count is read at run time


def test_stress_set_covers_the_extremes_of_every_tangent_row_of_the_inputs_table():
    from generator.eval.accuracy import stress_geometry
    from generator.library.inputs import INPUTS, float64_geometry

    L, V, labels = stress_geometry()
    n = len(L)
    N, T = np.tile([0.0, 0.0, 1.0], (n, 1)), np.tile([1.0, 0.0, 0.0], (n, 1))
    g = float64_geometry(L, V, N, T)
    for row in INPUTS:
        if row.tangent and row.expr:
            hi = [i for i, s in enumerate(labels) if s.startswith(f"{row.name} ≈ 1")]
            zero = [i for i, s in enumerate(labels) if s.startswith(f"{row.name} = 0")]
            assert hi and zero, row.name
            assert np.all(np.abs(g[row.name][hi]) > 0.99) and np.all(np.abs(g[row.name][zero]) < 1e-12), row.name


def test_bricks_linked_once_and_shared_compose_what_a_fresh_library_composes():
    """Library.memo shares linked brick functions between programs and the emitters replay their text
    (link/program.py, backends/clike/walk.py): sound only while nothing changes a linked function afterwards.
    Composing the example's permutations in two orders on one library, after its ubershader, must give
    exactly what a fresh library gives for each."""
    from generator.compose import compose_permutation
    from generator.compose.uber import compose_ubershader
    from generator.scene.load import load_scene

    def sources(lib, perm):
        return [(s.language, s.stage, s.text) for s in compose_permutation(perm, lib).sources]

    scene = load_scene(REPO / "scenes" / "example.toml", load_library())
    perms = [p for _, p in sorted(scene.permutations.items())]
    fresh = {p.canonical(): sources(load_library(), p) for p in perms}
    shared = load_library()
    compose_ubershader(perms, shared)
    for p in [*perms, *reversed(perms)]:
        assert sources(shared, p) == fresh[p.canonical()], p.canonical()
    assert shared.memo  # the library did keep linked nodes
