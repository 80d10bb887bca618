"""generator.evaluate and `shadermatrix eval`: GPU kernels on lavapipe agree with the NumPy emission.

Every BRDF spec of tests/golden/cases.toml, in GLSL, HLSL and WGSL on lavapipe
(validation layer on: any message fails), against the NumPy emission of the
same IR in float64 and float32, over random upper-hemisphere samples around
random normals, with T (a random tangent) passed for completeness.

Tolerance, per sample: |gpu - ref| <= ATOL_SCALE * max|f64| + rtol(kappa) * |f64|
with rtol(kappa) = EPS32 * (32 + 4 kappa):
- Inputs are rounded to float32 first, so every target sees the same numbers
  and only arithmetic differs.
- 32 ulp cover a chain of ~30 float32 operations plus Vulkan's allowed errors
  (exp2/log2: 3 ulp; pow = exp2(y log2 x); rsqrt 2 ulp) and LLVM's fused
  multiply-adds.
- kappa is the lobe's sharpness: the exponent n of (Blinn-)Phong lobes, or
  2/alpha^2 for microfacet lobes (the equivalent Blinn-Phong exponent, Walter
  et al. 2007 eq. 30). It is the first-order condition number of x^n
  (d ln x^n = n d ln x) and of the GGX/Beckmann peaks: a cosine near 1 carries
  an absolute rounding error of ~1 ulp, which the lobe amplifies kappa times;
  4 leaves room for the few roundings that feed n.h.
- The absolute floor 2^-20 of the batch's largest value absorbs the tail of
  pow/exp (the exp2 allowance grows with |log2 f|), where f is a millionth of
  the peak: invisible in any image. Exact zeros (light below the horizon) fall
  under it too, and are also checked to be exactly zero on the GPU.
Measured worst case over every spec, parameter set and language (4096
samples): 0.4 of the bound (GPU vs float64, sharp lobes).
"""
from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import require, require_tool
from tests.lavapipe import device, no_validation_messages  # noqa: F401 (fixtures)

pytestmark = pytest.mark.lavapipe

REPO = Path(__file__).resolve().parents[2]
SPECS = tomllib.loads((REPO / "tests/golden/cases.toml").read_text())["eval"]


def _samples_a_table(spec: str) -> bool:
    from generator.eval.evaluate import program
    return any(d.get("table") for _n, _ty, d in program(spec).textures)


# The ulp-level agreement below is for arithmetic; a baked table is filtered by the sampler (lavapipe weighs
# texels with 8 subtexel bits, filters across cube faces) and by NumPy exactly, so the table bricks' own tests
# compare the GPU with NumPy at the sampler's precision (tests/library/test_factored.py, test_painted.py,
# test_homomorphic.py, test_tables.py).
ALU_SPECS = [s for s in SPECS if not _samples_a_table(s)]
LANGS = ("glsl", "hlsl", "wgsl")
EPS32 = float(np.finfo(np.float32).eps)
ATOL_SCALE = 2.0 ** -20
SAMPLES = 4096
PARAM_SETS = {
    "defaults": {},
    "sharp": {"alpha": 0.05, "n": 1000.0, "f0": [0.9, 0.6, 0.3], "rho_d": [0.8, 0.1, 0.05]},
    "rough": {"alpha": 1.0, "n": 1.0, "f0": 1.0, "rho_d": 0.0},
}


def frames(rng, n):
    """Random orthonormal frames (T, B, N) as three (n, 3) arrays."""
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    a = np.where(np.abs(N[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    T = np.cross(a, N)
    T /= np.linalg.norm(T, axis=1, keepdims=True)
    return T, np.cross(N, T), N


def hemisphere(rng, T, B, N):
    """Uniform directions over the hemisphere around N (cos theta uniform in [0, 1))."""
    n = len(N)
    z, phi = rng.random(n), 2.0 * np.pi * rng.random(n)
    r = np.sqrt(1.0 - z * z)
    return (r * np.cos(phi))[:, None] * T + (r * np.sin(phi))[:, None] * B + z[:, None] * N


def f32(a):
    return a.astype(np.float32).astype(np.float64)


@pytest.fixture(scope="module")
def samples():
    rng = np.random.default_rng(20240611)
    T, B, N = frames(rng, SAMPLES)
    L, V = hemisphere(rng, T, B, N), hemisphere(rng, T, B, N)
    return tuple(f32(x) for x in (L, V, N, T))


# Bricks that divide by a cosine (the original Phong's 1/cos θ_i, Ward's 1/(cos θ_i cos θ_e), Ashikhmin-Shirley's
# 1/max(n·l, n·v)) or raise a product of float32-rounded cosines to a power (Lafortune): near grazing their
# float32 error is the rounding of n·l amplified, measured up to ~300 ulp (3.3e-5) on these samples.
GRAZING = ("phong", "ward_isotropic", "ward_anisotropic", "ashikhmin_shirley", "lafortune")
GRAZING_KAPPA = 100.0


def sharpness(ep, values) -> float:
    """kappa: the largest lobe exponent among the parameters (n, or 2/alpha^2 for microfacet lobes), or
    GRAZING_KAPPA for a BRDF with a brick of GRAZING."""
    k = GRAZING_KAPPA if set(re.findall(r"[a-z_]+", ep.spec)) & set(GRAZING) else 1.0
    if "n" in values:
        k = max(k, values["n"][0])
    if "alpha" in values and "microfacet" in ep.spec:
        k = max(k, 2.0 / max(values["alpha"][0], 1e-3) ** 2)
    return k


def assert_close(got, want, kappa, what):
    scale = float(np.max(np.abs(want)))
    rtol = EPS32 * (32.0 + 4.0 * kappa)
    bound = ATOL_SCALE * scale + rtol * np.abs(want)
    err = np.abs(got - want)
    bad = ~(err <= bound)
    if bad.any():
        i = int(np.argmax(np.where(bad, err / np.maximum(bound, 1e-300), 0.0)))
        r, c = divmod(i, 3)
        pytest.fail(f"{what}: {int(bad.sum())} of {got.size} values outside the tolerance "
                    f"(rtol {rtol:.2e}, atol {ATOL_SCALE * scale:.2e}); worst sample {r} channel {c}: "
                    f"got {got[r, c]!r}, want {want[r, c]!r}")


@pytest.mark.parametrize("params", list(PARAM_SETS), ids=list(PARAM_SETS))
@pytest.mark.parametrize("spec", ALU_SPECS)
@pytest.mark.toolchain  # compiles eval kernels
def test_gpu_kernels_agree_with_numpy(device, eval_session, samples, spec, params):
    from generator.eval.evaluate import evaluate, program, resolve_params

    ep = program(spec)
    p = {k: v for k, v in PARAM_SETS[params].items() if k in ep.params}
    kappa = sharpness(ep, resolve_params(ep, p))
    L, V, N, T = samples
    want64 = evaluate(spec, L, V, N, T, params=p, target="numpy", dtype="float64")
    want32 = evaluate(spec, L, V, N, T, params=p, target="numpy", dtype="float32")
    assert want64.shape == (SAMPLES, 3) and want64.dtype == np.float64
    assert np.isfinite(want64).all()
    assert_close(want32, want64, kappa, f"numpy float32 vs float64 ({spec}, {params})")
    zero = want64 == 0.0
    for lang in LANGS:
        got = evaluate(spec, L, V, N, T, params=p, target=lang, session=eval_session)
        assert got.shape == (SAMPLES, 3) and got.dtype == np.float64
        assert np.isfinite(got).all(), f"{lang}: NaN/Inf for {spec} ({params})"
        assert (got[zero] == 0.0).all(), f"{lang}: nonzero f_r where the numpy emission gives exactly 0"
        assert_close(got, want64, kappa, f"{lang} vs numpy float64 ({spec}, {params})")
        assert_close(got, want32, kappa, f"{lang} vs numpy float32 ({spec}, {params})")


@pytest.fixture(scope="module")
def probe_lib():
    from generator.library.bricks import load_library

    return load_library([REPO / "tests" / "bricks" / "eval"])


@pytest.mark.parametrize("target", ("numpy",) + LANGS)
@pytest.mark.toolchain  # compiles eval kernels
def test_tangent_frame_and_parameter_layout(device, eval_session, samples, probe_lib, target):
    """T is read from the fourth vec4 with B = cross(N, T); float, vec3 and mat4 parameters land in place."""
    from generator.eval.evaluate import evaluate

    L, V, N, T = (x[:256] for x in samples)
    w, c, m = -1.5, [0.25, -2.0, 4.0], [float(i) / 8.0 - 1.0 for i in range(16)]  # m: columns, column-major
    got = evaluate("tangent_probe", L, V, N, T, params={"w": w, "c": c, "m": m},
                   target=target, dtype="float32", lib=probe_lib, session=eval_session)
    B = np.cross(N, T)
    M = np.asarray(m).reshape(4, 4).T
    want = np.stack([np.sum(T * L, 1), np.sum(B * V, 1), np.full(len(L), w)], 1) * c
    want += (np.concatenate([L, np.ones((len(L), 1))], 1) @ M.T)[:, :3]
    want[np.sum(N * L, 1) <= 0.0] = 0.0
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-5)


def test_errors_say_what_and_what_to_do(probe_lib):
    from generator.eval.evaluate import EvalError, evaluate

    L = V = N = np.tile([0.0, 0.0, 1.0], (4, 1))
    cases = [
        (dict(target="numpy", params={"rho": 0.5}), "unknown parameter 'rho'", "rho_d"),
        (dict(target="numpy", params={"rho_d": 1.5}), "outside the range", "[0.0, 1.0]"),
        (dict(target="numpy", params={"rho_d": [0.1, 0.2]}), "expected 3 numbers", "splat"),
        (dict(target="numpy", params={"rho_d": "red"}), "not numeric", "RGB"),
        (dict(target="glsl", dtype="float64"), "float32", "--dtype float32"),
        (dict(target="reference", dtype="float16"), "float64 only", "--target numpy"),
        (dict(target="numpy", dtype="float128"), "unknown dtype", "float16"),
        (dict(target="vulkan"), "unknown target", "wgsl"),
    ]
    for kwargs, what, todo in cases:
        with pytest.raises(EvalError) as e:
            evaluate("lambert", L, V, N, **kwargs)
        assert what in str(e.value) and todo in str(e.value) and " — " in str(e.value), str(e.value)
    with pytest.raises(EvalError, match="shape"):
        evaluate("lambert", L[:, :2], V, N, target="numpy")
    with pytest.raises(EvalError, match="different lengths"):
        evaluate("lambert", L[:3], V, N, target="numpy")
    with pytest.raises(EvalError, match=r"tangent frame.*\(N, 12\)"):
        evaluate("tangent_probe", L, V, N, target="numpy", lib=probe_lib)


def test_scalar_splats_and_defaults_apply():
    from generator.eval.evaluate import evaluate

    L = V = N = np.tile([0.0, 0.0, 1.0], (2, 1))
    np.testing.assert_allclose(evaluate("lambert", L, V, N, params={"rho_d": 0.25}, target="numpy"),
                               np.full((2, 3), 0.25 / np.pi))
    np.testing.assert_allclose(evaluate("lambert", L, V, N, target="numpy"), np.full((2, 3), 0.5 / np.pi))
    assert evaluate("lambert", L[:0], V[:0], N[:0], target="numpy").shape == (0, 3)


def test_generator_evaluate_stays_the_function_after_the_module_import():
    code = ("import numpy as np, generator; x = np.tile([0.0, 0.0, 1.0], (1, 1)); "
            "a = generator.evaluate('lambert', x, x, x, target='numpy'); "
            "import generator.eval.evaluate as m; b = generator.evaluate('lambert', x, x, x, target='numpy'); "
            "from generator import evaluate; c = evaluate('lambert', x, x, x, target='numpy'); "
            "assert (a == b).all() and (b == c).all() and a.shape == (1, 3); print('ok')")
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr


# ------------------------------------------------------------------ CLI

def cli(*args):
    return subprocess.run([sys.executable, "-m", "generator.cli", "eval", *map(str, args)],
                          cwd=REPO, capture_output=True, text=True, timeout=300)


def save(path, a):
    np.save(path, a)
    return path


@pytest.mark.toolchain  # compiles eval kernels
def test_cli_round_trip_matches_the_python_function(tmp_path, samples, eval_session):
    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    from generator.eval.evaluate import evaluate
    from generator.runtime.probe import lavapipe_present

    L, V, N, T = (x[:300] for x in samples)
    s9 = save(tmp_path / "s9.npy", np.hstack([L, V, N]).astype(np.float32))
    s12 = save(tmp_path / "s12.npy", np.hstack([L, V, N, T]))
    spec = "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_schlick)"
    params = ["--param", "alpha=0.2", "--param", "f0=0.9,0.6,0.3", "--param", "rho_d=0.5"]
    runs = [("numpy", "float64", s12), ("numpy", "float16", s9)]
    require(lavapipe_present(), "no lavapipe device — install mesa-vulkan-drivers (`make setup`)")
    runs += [(lang, None, s12) for lang in LANGS]
    for target, dtype, inp in runs:
        out = tmp_path / f"f_{target}_{dtype}.npy"
        r = cli(spec, "--input", inp, "--out", out, "--target", target, *params,
                *(["--dtype", dtype] if dtype else []))
        assert r.returncode == 0, r.stderr
        f = np.load(out)
        assert f.dtype == np.float64 and f.shape == (300, 3)
        want = evaluate(spec, L, V, N, T, params={"alpha": 0.2, "f0": [0.9, 0.6, 0.3], "rho_d": 0.5},
                        target=target, dtype=dtype, session=eval_session)
        np.testing.assert_array_equal(f, want)
        assert list(tmp_path.glob(".*.tmp")) == []


DIVIDE_BY_ZERO = '''"""A diffuse term that naga rejects (constant division by zero); glslang folds it."""
BRICK = {"kind": "diffuse", "cite": "test probe",
         "params": {"rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5]}}}


def diffuse(rho_d: vec3) -> vec3:
    k: int = 1 / 0
    return rho_d * INV_PI * float(k)
'''


@pytest.mark.toolchain  # compiles eval kernels
def test_cli_kernel_that_does_not_compile_is_one_line_error(tmp_path):
    for t in ("glslc", "naga", "spirv-val", "spirv-opt"):
        require_tool(t)
    from generator.runtime.probe import lavapipe_present
    require(lavapipe_present(), "no lavapipe device — install mesa-vulkan-drivers (`make setup`)")

    bricks = tmp_path / "bricks"
    bricks.mkdir()
    (bricks / "div_zero.py").write_text(DIVIDE_BY_ZERO)
    good = save(tmp_path / "s.npy", np.tile([0.0, 0.0, 1.0], (4, 3)))
    r = cli("div_zero", "--bricks", bricks, "--input", good, "--out", tmp_path / "f.npy", "--target", "wgsl")
    assert r.returncode == 1, r.stderr
    assert r.stderr.startswith("error: the wgsl eval kernel does not compile: ")
    assert "bricks/div_zero.py:7:" in r.stderr and " — " in r.stderr, r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr, r.stderr
    assert not (tmp_path / "f.npy").exists()


def test_cli_errors_exit_1_or_2_and_leave_the_output_alone(tmp_path):
    good = save(tmp_path / "s.npy", np.tile([0.0, 0.0, 1.0], (4, 3)))
    out = tmp_path / "f.npy"
    out.write_bytes(b"earlier result")
    bad_shape = save(tmp_path / "bad_shape.npy", np.zeros((4, 10)))
    ints = save(tmp_path / "ints.npy", np.zeros((4, 9), np.int64))
    (tmp_path / "junk.npy").write_text("not an array")
    cases = [
        (["lambert", "--input", good, "--param", "rho=1"], "unknown parameter 'rho'"),
        (["lambert", "--input", good, "--param", "rho_d=7"], "outside the range"),
        (["lambert", "--input", good, "--param", "rho_d=0.1,x"], "not a number"),
        (["lambert", "--input", good, "--param", "rho_d"], "NAME=VALUE"),
        (["lambert", "--input", good, "--param", "rho_d=0.1", "--param", "rho_d=0.2"], "given twice"),
        (["lambert", "--input", tmp_path / "missing.npy"], "no such file"),
        (["lambert", "--input", bad_shape], "(N, 9)"),
        (["lambert", "--input", ints], "not a float array"),
        (["lambert", "--input", tmp_path / "junk.npy"], "not a readable .npy"),
        (["lambert", "--input", good, "--dtype", "float64", "--target", "wgsl"], "float32"),
        (["nonesuch", "--input", good], "unknown diffuse/specular brick 'nonesuch'"),
    ]
    for args, msg in cases:
        target = [] if "--target" in args else ["--target", "numpy"]
        r = cli(*args, "--out", out, *target)
        usage = any(w in msg for w in ("not a number", "NAME=VALUE", "given twice"))  # of --param's form: exit 2
        assert r.returncode == (2 if usage else 1), (args, r.stderr)
        assert msg in r.stderr and " — " in r.stderr, (args, r.stderr)
        assert "Traceback" not in r.stderr
        assert out.read_bytes() == b"earlier result"
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


def test_non_finite_and_non_unit_samples_are_refused_naming_the_row(tmp_path):
    """Every target treats a NaN its own way (the reference returned 0, NumPy and the GPU 0.189 for an all-NaN row):
    the samples are checked first, and --unchecked passes them through as they are."""
    good = np.tile([0.0, 0.0, 1.0], (5, 3))
    nan = good.copy()
    nan[3, 4] = np.nan
    r = cli("lambert", "--input", save(tmp_path / "nan.npy", nan), "--out", tmp_path / "f.npy", "--target", "numpy")
    assert r.returncode == 1 and "row 3 holds a NaN or infinity" in r.stderr and "--unchecked" in r.stderr, r.stderr
    long = good.copy()
    long[2, 6:9] = [0.0, 0.0, 2.0]
    r = cli("lambert", "--input", save(tmp_path / "long.npy", long), "--out", tmp_path / "f.npy", "--target", "numpy")
    assert r.returncode == 1 and "row 2: N has length 2, not 1" in r.stderr, r.stderr
    r = cli("lambert", "--input", tmp_path / "long.npy", "--out", tmp_path / "f.npy", "--target", "numpy",
            "--unchecked")
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("shape,words", [((10 ** 12, 9), "1000000000000 samples declared"),
                                         ((1, 10 ** 12), "samples are (N, 9)"), ((10 ** 12,), "samples are (N, 9)"),
                                         ((1000, 9), "the file is shorter")])
def test_a_header_declaring_what_the_file_cannot_be_allocates_nothing(tmp_path, shape, words):
    import io

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": shape})
    (tmp_path / "huge.npy").write_bytes(buf.getvalue())  # a header, no data
    r = cli("lambert", "--input", tmp_path / "huge.npy", "--out", tmp_path / "f.npy", "--target", "numpy")
    assert r.returncode == 1 and words in r.stderr and "Traceback" not in r.stderr, r.stderr
