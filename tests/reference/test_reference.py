"""The float64 references: closed-form values, agreement with the bricks' emission, reciprocity, the policy.

The references are written from the papers and the bricks from their own
sources; both compute the same formula, so the NumPy float64 emission of a
brick agrees with its reference to rounding wherever no brick guard is active.
Guards act only below n·l or n·v of 1e-4 and alpha of 1e-3, so the comparison
keeps n·l, n·v >= 1e-3 and alpha >= 1e-2.

Tolerances scale with the lobe's sharpness kappa (the exponent n, or 2/alpha²
for microfacet lobes, Walter et al. 2007 eq. 30): a cosine near 1 carries an
absolute rounding error of about one ulp, which x^kappa (and the GGX/Beckmann
peaks) amplify kappa times (see tests/eval/test_eval.py).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from generator.eval import accuracy
from generator.library.bricks import load_library
from generator.eval.evaluate import evaluate
from generator.reference import (d_beckmann, d_blinn_phong, d_ggx, exact, fresnel_conductor,
                                 fresnel_dielectric, fresnel_dielectric_f0, fresnel_schlick, lambda_beckmann,
                                 lambda_ggx, missing_references, reference_brdf, shading_geometry,
                                 smith_g1_beckmann, smith_g1_ggx)

LIB = load_library()
SPECS = accuracy.default_specs(LIB)  # every slot filler at least once
# The whole filler product, the combinations beyond SPECS under the `slow` marker.
ALL_SPECS = SPECS + [pytest.param(s, marks=pytest.mark.slow)
                     for s in accuracy.default_specs(LIB, full=True) if s not in SPECS]
# Bricks whose approximation error is of order 1 (a 3-factor fit: homomorphic_factorization, tolerance 36): an
# emission-vs-reference bound widened by it would pass anything finite, so the two emission tests leave them to
# their own tests (tests/library/test_homomorphic.py) and to accuracy's verdict.
EMISSION_SPECS = [s for s in ALL_SPECS if accuracy.spec_tolerance(getattr(s, "values", (s,))[0], LIB, 0.0) < 1.0]
EPS32 = float(np.finfo(np.float32).eps)
EPS64 = float(np.finfo(np.float64).eps)
PARAMS = [{}, {"alpha": 0.02, "f0": [1.0, 0.5, 0.0]}, {"alpha": 1.0}, {"n": 1000.0}, {"n": 1.0, "rho_d": [0.2, 0.9, 0.0]}]


def _params_for(spec: str) -> list[dict]:
    names = set(accuracy.declared_params(spec, LIB))
    out = []
    for p in PARAMS:
        q = {k: v for k, v in p.items() if k in names}
        if q not in out:
            out.append(q)
    return out


@pytest.fixture(scope="module")
def hemi():
    s = accuracy.hemisphere(k=10)
    g = shading_geometry(s.L, s.V, s.N)
    keep = (g.NdotL >= 1e-3) & (np.einsum("ij,ij->i", s.N, s.V) >= 1e-3)
    return s, keep


def test_every_brdf_brick_has_a_reference():
    assert missing_references(LIB) == []


def _kappa(spec: str, p: dict) -> float:
    q = {**{k: d for k, (_, d, _) in accuracy.declared_params(spec, LIB).items()}, **p}
    if "n" in q:
        return q["n"]
    return 2.0 / q["alpha"] ** 2 if "alpha" in q else 0.0


@pytest.mark.parametrize("spec", EMISSION_SPECS)
def test_reference_equals_the_float64_emission_of_the_brick(spec, hemi):
    # |f64 - ref| <= max(1e-12, 8 ulp kappa) |ref| + 1e-15 max|ref|: the absolute term covers
    # values 1e-15 below the peak, where cancelling differences (1 - v·h in Schlick's
    # Fresnel at f0 = 0, r·v near 0) and the Beckmann tail exp(-tan²/α²) lose relative digits.
    s, keep = hemi
    for p in _params_for(spec):
        ref = reference_brdf(spec, s.L, s.V, s.N, s.T, p)
        got = evaluate(spec, s.L, s.V, s.N, s.T, p, target="numpy", dtype="float64")
        assert np.all(np.isfinite(ref)) and np.all(ref >= 0.0) and np.all(np.isfinite(got))
        rtol = max(1e-12, 8 * EPS64 * _kappa(spec, p))
        if "ndf=blinn_phong" in spec:  # its series for ln(1 - x) is exact to float32, not float64
            rtol += _kappa(spec, p) * 2e-11
        if "vis=smith_beckmann" in spec:  # its erfc is Abramowitz & Stegun 7.1.26: G1 to 7.5e-8 per factor
            rtol += 2e-7
        approx = accuracy.spec_tolerance(spec, LIB, 0.0)  # a baked table's (a fit's) declared approximation error,
        rtol += approx  # relative as accuracy measures it: to max(|ref|, REL_FLOOR)
        bound = rtol * np.abs(ref) + 1e-15 * np.abs(ref).max() + approx * accuracy.REL_FLOOR
        worst = (np.abs(got - ref) / bound)[keep].max()
        assert worst <= 1.0, (spec, p, float(worst))


# Bricks whose f_r carries 1/n·l alone (no n·v beside it to keep the lobe's peak the batch's maximum).
OVER_COS_L = {"phong"}


@pytest.mark.parametrize("spec", EMISSION_SPECS)
def test_float32_emission_is_within_a_stated_tolerance_of_the_reference(spec, hemi):
    # |f32 - ref| <= 64 ulp (1 + kappa/16) |ref| + 2^-20 max|ref|: a ~30-operation chain
    # amplified by the lobe (see the module docstring); the absolute term covers dot
    # products that cancel (r·v, n·h near 0: an absolute error of ~1 ulp of their terms).
    s, keep = hemi
    given = accuracy.rounded_inputs(s, "float32")
    for p in _params_for(spec):
        ref = reference_brdf(spec, *given, p)
        got = evaluate(spec, *given, p, target="numpy", dtype="float32")
        rtol = 64 * EPS32 * (1.0 + _kappa(spec, p) / 16.0)
        if spec in OVER_COS_L:  # f ∝ 1/n·l: the float32 n·l's rounding (~1 ulp of 1, relative 8 ε32/n·l at most)
            rtol = rtol + 8 * EPS32 / shading_geometry(*given).NdotL[:, None]
        rtol = rtol + accuracy.spec_tolerance(spec, LIB, 0.0)  # a baked table's declared approximation error
        bound = rtol * np.abs(ref) + 2.0 ** -20 * np.abs(ref).max()
        worst = (np.abs(got - ref) / bound)[keep].max()
        assert worst <= 1.0, (spec, p, float(worst))


# Bricks that are not reciprocal by design, and why (ACCURACY-FACTS §4.6); their tests say so.
NOT_RECIPROCAL = {
    "phong": "the course's original Phong, k_s (cos α_r)^n / (π cos θ_i): the 1/cos θ_i is the light's alone "
             "(tests/library/test_library_specular.py asserts the asymmetry)",
    "gotanda_fitted": "Gotanda 2014 eq. 8 is a fit: F_r reads n·e only, L_m n·l only "
                      "(tests/library/test_library_diffuse.py asserts the asymmetry)",
}


@pytest.mark.parametrize("spec", [s for s in ALL_SPECS if getattr(s, "values", (s,))[0] not in NOT_RECIPROCAL])
def test_reciprocity(spec):
    # Every brick present is reciprocal (ACCURACY-FACTS §4.6) but NOT_RECIPROCAL; the n·v clamp
    # of the shading policy is not, so both cosines stay above 1e-3. T = x (tangent-frame bricks).
    rng = np.random.default_rng(7)
    L = accuracy.direction(rng.uniform(1e-3, 1, 2000), rng.uniform(0, 2 * np.pi, 2000))
    V = accuracy.direction(rng.uniform(1e-3, 1, 2000), rng.uniform(0, 2 * np.pi, 2000))
    N = np.broadcast_to([0.0, 0.0, 1.0], L.shape)
    T = np.broadcast_to([1.0, 0.0, 0.0], L.shape)
    for target in ("reference", "numpy"):
        a = evaluate(spec, L, V, N, T, target=target, dtype="float64")
        b = evaluate(spec, V, L, N, T, target=target, dtype="float64")
        rel = np.abs(a - b) / np.maximum(np.abs(a), 1e-300)
        assert rel.max() <= 1e-12, (spec, target, float(rel.max()))


# ------------------------------------------------------------------ shading policy

def test_policy_no_light_from_below_and_view_below_the_horizon_shades_as_grazing():
    N = np.array([[0.0, 0.0, 1.0]])
    L = accuracy.direction(np.array([0.6]), np.array([0.0]))
    below = accuracy.direction(np.array([-0.2]), np.array([np.pi]))
    graze = accuracy.direction(np.array([1e-4]), np.array([np.pi]))
    T = np.array([[1.0, 0.0, 0.0]])  # for the tangent-frame bricks
    for spec in SPECS:
        assert np.all(reference_brdf(spec, -L, graze, N, T) == 0.0), spec
        f = reference_brdf(spec, L, below, N, T)
        assert np.all(np.isfinite(f)) and np.all(f >= 0.0), spec
    # n·v is clamped, h comes from the true v: Lambert ignores v, Smith-Schlick sees n·v = 1e-4
    g = shading_geometry(L, below, N)
    assert g.NdotV[0] == 1e-4 and g.NdotH[0] > 0.0


def test_undefined_half_vector_is_zero_and_gives_finite_values():
    L = np.array([[0.6, 0.0, 0.8]])
    g = shading_geometry(L, -L, [0.0, 0.0, 1.0])
    assert g.NdotH[0] == 0.0 and g.VdotH[0] == 0.0 and g.NxH2[0] == 1.0
    for spec in SPECS:
        f = reference_brdf(spec, L, -L, [0.0, 0.0, 1.0], [0.0, 1.0, 0.0])  # T for the tangent-frame bricks
        assert np.all(np.isfinite(f)), spec


# ------------------------------------------------------------------ closed forms (ACCURACY-FACTS §4.11, §4.12)

def test_dielectric_fresnel_values():
    c = np.array([1.0, 0.5, 0.2, 0.0])
    np.testing.assert_allclose(fresnel_dielectric(c, 1.5), [0.04, 0.089187, 0.338894, 1.0], atol=1e-6)
    brewster = math.cos(math.atan(1.5))
    assert fresnel_dielectric(brewster, 1.5) == pytest.approx(0.0739645, abs=1e-7)
    # f0-parameterized form equals the eta form; f0 = 1 is a perfect mirror
    np.testing.assert_allclose(fresnel_dielectric_f0(np.full((4, 3), 0.04), c)[:, 0],
                               fresnel_dielectric(c, 1.5), rtol=1e-14)
    assert np.all(fresnel_dielectric_f0(np.ones((4, 3)), c) == 1.0)
    # total internal reflection from the dense side
    assert fresnel_dielectric(0.2, 1 / 1.5) == 1.0


def test_conductor_fresnel_values_and_dielectric_limit():
    assert fresnel_conductor(1.0, 0.2, 3.0) == pytest.approx(0.923372, abs=1e-6)
    c = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(fresnel_conductor(c, 1.5, 0.0), fresnel_dielectric(c, 1.5), atol=1e-15)
    np.testing.assert_allclose(fresnel_conductor(c, 1 / 1.33, 0.0), fresnel_dielectric(c, 1 / 1.33), atol=1e-15)


@pytest.mark.parametrize("eta,max_err", [(1.33, 0.0599), (1.5, 0.0357), (2.0, 0.0444)])
def test_schlick_error_against_exact_fresnel(eta, max_err):
    c = np.linspace(0.0, 1.0, 20001)
    f0 = ((eta - 1) / (eta + 1)) ** 2
    err = np.abs(fresnel_schlick(f0, c) - fresnel_dielectric(c, eta)).max()
    assert err == pytest.approx(max_err, abs=5e-4)


def test_smith_lambda_limits_and_stability():
    a = np.array([1e-3, 0.1, 0.5, 1.0])
    for lam, g1 in ((lambda_ggx, smith_g1_ggx), (lambda_beckmann, smith_g1_beckmann)):
        assert np.all(lam(1.0, a) == 0.0) and np.all(g1(1.0, a) == 1.0)
        assert np.all(np.isinf(lam(0.0, a))) and np.all(g1(0.0, a) == 0.0)
        c = np.linspace(1e-6, 1.0, 1000)
        g = g1(c, 0.3)
        assert np.all(np.diff(g) >= 0.0) and np.all((g >= 0) & (g <= 1))
    # GGX, alpha = 1: Lambda = (1/cos - 1)/2
    c = np.linspace(0.01, 1, 50)
    np.testing.assert_allclose(lambda_ggx(c, 1.0), (1 / c - 1) / 2, rtol=1e-13)


def _h_quadrature(alpha, n_u=800, n_phi=256):
    """Nodes over the half-vector hemisphere, theta_h = atan(alpha tan u), with dω weights."""
    u, w = np.polynomial.legendre.leggauss(n_u)
    u = (u + 1) * np.pi / 4
    w = w * np.pi / 4
    t = np.arctan(alpha * np.tan(u))
    dt = alpha / np.cos(u) ** 2 / (1 + (alpha * np.tan(u)) ** 2)
    phi = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    T, P = np.meshgrid(t, phi, indexing="ij")
    W = (w * dt * np.sin(t))[:, None] * np.full(n_phi, 2 * np.pi / n_phi)
    H = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    return H, W.reshape(-1)


@pytest.mark.parametrize("ndf", [d_ggx, d_beckmann, d_blinn_phong])
@pytest.mark.parametrize("alpha", [1e-3, 0.1, 0.5, 1.0])
def test_reference_ndfs_are_normalized(ndf, alpha):
    H, W = _h_quadrature(alpha, n_phi=1)
    c = H[:, 2]
    s2 = H[:, 0] ** 2 + H[:, 1] ** 2
    assert np.sum(ndf(c, s2, alpha) * c * W) == pytest.approx(1.0, abs=1e-8)


@pytest.mark.parametrize("name", ["ggx", "beckmann"])
@pytest.mark.parametrize("alpha", [1e-3, 0.2, 1.0])
@pytest.mark.parametrize("theta_deg", [0.0, 60.0, 85.0])
def test_weak_white_furnace_with_exact_smith_g1(name, alpha, theta_deg):
    # Heitz 2014: ∫ G1(v) max(0, v·h) D(h) dω_h = cos θ_v for the exact Smith G1
    D, G1 = {"ggx": (d_ggx, smith_g1_ggx), "beckmann": (d_beckmann, smith_g1_beckmann)}[name]
    H, W = _h_quadrature(alpha, n_u=400, n_phi=128)
    t = math.radians(theta_deg)
    v = np.array([math.sin(t), 0.0, math.cos(t)])
    vh = np.maximum(H @ v, 0.0)
    integral = np.sum(G1(math.cos(t), alpha) * vh * D(H[:, 2], H[:, 0] ** 2 + H[:, 1] ** 2, alpha) * W)
    assert integral == pytest.approx(math.cos(t), abs=2e-5)


def test_dirac_limit_at_alpha_zero():
    c = np.array([1.0, 0.999, 0.5])
    s2 = (1 - c) * (1 + c)
    for D in (d_ggx, d_beckmann, d_blinn_phong):
        d = D(c, s2, 0.0)
        assert np.isinf(d[0]) and np.all(d[1:] == 0.0)
    assert exact.cos_power(0.0, 1.0, 0.0) == 1.0  # 0^0 = 1: the alpha = 1 Blinn-Phong NDF is 1/pi
