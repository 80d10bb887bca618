"""The microfacet slot fillers: NDF normalization, Fresnel closed forms, visibility identities,
white furnace figures (ACCURACY-FACTS §4.4, §4.5, §4.11, §4.12).

Bricks run through their NumPy emission (float64 unless said otherwise) inside the microfacet
host; a slot's value is isolated by dividing by the same spec with a neutral filler
(fresnel=none with f0 = 1, vis=implicit = 1/4). The references run from generator.reference.
The general checks (emission = reference, float32 tolerance, reciprocity, no NaN/Inf on the
stress set) are tests/reference/test_reference.py's and tests/eval/test_accuracy.py's, over every filler.
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from generator.eval.evaluate import evaluate
from generator.reference import exact, fresnel_dielectric, reference_brdf
from generator.reference.fillers import (gotanda_eq2, lambda_ggx_anisotropic, ndf_ward, schlick_k_ggx)
from tests.library.test_energy import albedo_microfacet

Z = np.array([0.0, 0.0, 1.0])
X = np.array([1.0, 0.0, 0.0])


@functools.lru_cache(maxsize=None)
def _nodes(n: int):
    return np.polynomial.legendre.leggauss(n)


def _gl(a: float, b: float, n: int):
    x, w = _nodes(n)
    return (x + 1) * (b - a) / 2 + a, w * (b - a) / 2


def _dirs(theta, phi):
    theta, phi = np.broadcast_arrays(np.asarray(theta, float), np.asarray(phi, float))
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)


def _f(spec, L, V, params, dtype="float64"):
    N = np.broadcast_to(Z, np.shape(L))
    T = np.broadcast_to(X, np.shape(L))
    return evaluate(spec, L, V, N, T, params=params, target="numpy", dtype=dtype)


def _mirror(cos_d):
    """(L, V) mirrored about n = z in the x-z plane: h = n, v·h = cos_d."""
    t = np.arccos(np.asarray(cos_d, float))
    return _dirs(t, 0.0), _dirs(t, np.pi)


# ------------------------------------------------------------------ NDF normalization (§4.4)

def _slope_quadrature(au, av, n=400):
    """h over the hemisphere through its slopes (x, y) = (au ρ cos ψ, av ρ sin ψ), ρ = tan u: returns h and the
    weights of ∫ g(h) cos θ_h dω_h = ∫ g cos⁴θ_h dx dy (dω = cos³θ dx dy)."""
    u, wu = _gl(0.0, math.pi / 2, n)
    psi, wp = _gl(0.0, 2 * math.pi, n)
    rho = np.tan(u)
    U, P = np.meshgrid(rho, psi, indexing="ij")
    W = (wu / np.cos(u) ** 2 * rho)[:, None] * wp[None, :] * au * av
    x, y = au * U * np.cos(P), av * U * np.sin(P)
    H = np.stack([-x, -y, np.ones_like(x)], -1)
    H /= np.linalg.norm(H, axis=-1, keepdims=True)
    return H.reshape(-1, 3), (W * H[..., 2] ** 4).reshape(-1)


@pytest.mark.parametrize("ndf", ["ggx_anisotropic", "beckmann_anisotropic"])
@pytest.mark.parametrize("au,av", [(0.05, 0.5), (0.3, 0.1), (1e-3, 0.2), (1.0, 1.0)])
def test_anisotropic_ndf_brick_is_normalized(ndf, au, av):
    # f(h, h) = F D V = D / 4 with F = 1 (fresnel=none, f0 = 1) and V = 1/4 (implicit)
    H, W = _slope_quadrature(au, av)
    ok = H[:, 2] > 1e-6
    f = _f(f"microfacet(ndf={ndf},fresnel=none,vis=implicit)", H[ok], H[ok],
           {"alpha_u": au, "alpha_v": av, "f0": 1.0})[:, 0]
    assert np.sum(4 * f * W[ok]) == pytest.approx(1.0, abs=2e-6)


@pytest.mark.parametrize("iso,aniso", [("ggx", "ggx_anisotropic"), ("beckmann", "beckmann_anisotropic")])
@pytest.mark.parametrize("alpha", [1e-3, 0.1, 0.7])
def test_anisotropic_ndf_with_equal_roughness_is_the_isotropic_one(iso, aniso, alpha):
    rng = np.random.default_rng(3)
    L = _dirs(np.arccos(rng.uniform(0.01, 1, 500)), rng.uniform(0, 2 * np.pi, 500))
    V = _dirs(np.arccos(rng.uniform(0.01, 1, 500)), rng.uniform(0, 2 * np.pi, 500))
    a = _f(f"microfacet(ndf={iso},fresnel=none,vis=implicit)", L, V, {"alpha": alpha, "f0": 1.0})
    b = _f(f"microfacet(ndf={aniso},fresnel=none,vis=implicit)", L, V, {"alpha_u": alpha, "alpha_v": alpha, "f0": 1.0})
    np.testing.assert_allclose(b, a, rtol=1e-12, atol=1e-300)


def test_anisotropic_ndf_stretches_along_the_rougher_axis():
    # a half vector tilted 20° towards T sees alpha_u, towards B alpha_v
    t = math.radians(20.0)
    for ndf in ("ggx_anisotropic", "beckmann_anisotropic"):
        spec = f"microfacet(ndf={ndf},fresnel=none,vis=implicit)"
        along_t, along_b = _dirs(t, 0.0)[None], _dirs(t, np.pi / 2)[None]
        p = {"alpha_u": 0.5, "alpha_v": 0.1, "f0": 1.0}
        assert _f(spec, along_t, along_t, p)[0, 0] > 50 * _f(spec, along_b, along_b, p)[0, 0]


# Ward's D is normalized in solid angle, not in projected area (bricks/brdf/microfacet/ndf/ward.py).
WARD_PROJECTED = {0.05: 0.998755, 0.1: 0.995073, 0.2: 0.981094, 0.5: 0.905354, 1.0: 0.757872}


def _ward_integrals(f_of_h, alpha, n=600):
    u, w = _gl(0.0, math.pi / 2, n)
    t = np.arctan(alpha * np.tan(u))
    dt = alpha / np.cos(u) ** 2 / (1 + (alpha * np.tan(u)) ** 2)
    D = f_of_h(t)
    d_omega = 2 * math.pi * np.sin(t) * w * dt
    return np.sum(D * d_omega), np.sum(D * np.cos(t) * d_omega)


@pytest.mark.parametrize("alpha", sorted(WARD_PROJECTED))
def test_ward_ndf_is_a_density_in_solid_angle(alpha):
    ref = _ward_integrals(lambda t: ndf_ward(np.cos(t), np.sin(t) ** 2, alpha), alpha)
    brick = _ward_integrals(lambda t: 4 * _f("microfacet(ndf=ward,fresnel=none,vis=implicit)", _dirs(t, 0.0),
                                             _dirs(t, 0.0), {"alpha": alpha, "f0": 1.0})[:, 0], alpha)
    for total, projected in (ref, brick):
        assert total == pytest.approx(1.0, abs=1e-9)
        assert projected == pytest.approx(WARD_PROJECTED[alpha], abs=2e-6)
    # D_ward = D_beckmann cos θ_h: "a modified Beckmann NDF" (Hoffman & Baker 2006)
    c = np.linspace(0.05, 1.0, 50)
    s2 = (1 - c) * (1 + c)
    np.testing.assert_allclose(ndf_ward(c, s2, alpha), exact.d_beckmann(c, s2, alpha) * c, rtol=1e-13)


# ------------------------------------------------------------------ Fresnel (§4.12)

def _fresnel(filler, cos_d, params, dtype="float64"):
    """F(v·h) of a fresnel brick, isolated: the microfacet spec at h = n divided by the same with F = 1."""
    L, V = _mirror(cos_d)
    f = _f(f"microfacet(ndf=ggx,fresnel={filler},vis=implicit)", L, V, {"alpha": 0.5, **params}, dtype)
    one = _f("microfacet(ndf=ggx,fresnel=none,vis=implicit)", L, V, {"alpha": 0.5, "f0": 1.0}, dtype)
    return f / one


def test_dielectric_exact_closed_forms():
    c = np.array([1.0, 0.5, 0.2, math.cos(math.atan(1.5)), 1e-3])
    F = _fresnel("dielectric_exact", c, {"f0": [0.04, 0.04, 0.04]})[:, 0]
    np.testing.assert_allclose(F[:4], [0.04, 0.089187, 0.338894, 0.0739645], atol=1e-6)  # Brewster: R_s / 2
    np.testing.assert_allclose(F, fresnel_dielectric(c, 1.5), rtol=1e-13)
    # Gotanda 2014 eq. 2 as printed, in float64, is the same function
    cc = np.linspace(0.01, 1.0, 100)
    for f0 in (1e-4, 0.04, 0.5, 0.9):
        np.testing.assert_allclose(_fresnel("dielectric_exact", cc, {"f0": [f0] * 3})[:, 0], gotanda_eq2(f0, cc),
                                   rtol=1e-12)
    # f0 = 0: no interface, F = 0; f0 = 1: a perfect mirror, F = 1 (at every angle, grazing included)
    cz = np.array([1.0, 0.5, 1e-2, 1e-4, 1e-7])
    F = _fresnel("dielectric_exact", cz, {"f0": [0.0, 1.0, 0.04]})
    assert np.all(F[:, 0] == 0.0) and np.allclose(F[:, 1], 1.0, rtol=1e-12)


def test_dielectric_exact_float32_keeps_f0_zero_at_grazing():
    # Eq. 2 as printed gives F = 1.0 in float32 at f0 = 0, v·h = 1e-4 (a = sqrt(1 - (1 - c²)) != c);
    # the brick's cancellation-free form gives 0 there and agrees with float64 elsewhere.
    c = np.array([1e-4, 1e-2, 0.3, 1.0])
    F = _fresnel("dielectric_exact", c, {"f0": [0.0, 1e-4, 0.04]}, "float32")
    assert np.all(F[:, 0] == 0.0)
    ref = _fresnel("dielectric_exact", c, {"f0": [0.0, 1e-4, 0.04]})
    np.testing.assert_allclose(F[:, 1:], ref[:, 1:], rtol=2e-6)


@pytest.mark.parametrize("eta,max_err", [(1.5, 0.0075), (2.0, 0.0130), (1.33, 0.0230)])
def test_spherical_gaussian_tracks_the_normalized_exact_dielectric(eta, max_err):
    c = np.linspace(0.0, 1.0, 2001)[1:]
    F = _fresnel("spherical_gaussian", c, {"f0": [0.0, 1.0, 0.5]})
    f0 = ((eta - 1) / (eta + 1)) ** 2
    norm = (fresnel_dielectric(c, eta) - f0) / (1 - f0)
    assert np.abs(F[:, 0] - norm).max() == pytest.approx(max_err, abs=2e-4)
    np.testing.assert_allclose(F[:, 1], 1.0, rtol=1e-14)  # f0 = 1
    np.testing.assert_allclose(F[:, 2], 0.5 + 0.5 * F[:, 0], rtol=1e-14)  # f0 + (1 - f0) w
    # and it is not an approximation of Schlick's (1 - c)^5
    assert np.abs(F[:, 0] - (1 - c) ** 5).max() == pytest.approx(0.0388, abs=2e-4)


def test_conductor_exact_closed_forms():
    c = np.array([1.0, 0.7, 0.3, 0.05])
    F = _fresnel("conductor_exact", c, {"eta": [0.2, 1.5, 1.0], "k": [3.0, 0.0, 0.0], "f0": 0.5})
    assert F[0, 0] == pytest.approx(0.923372, abs=1e-6)  # ((n-1)² + k²)/((n+1)² + k²)
    np.testing.assert_allclose(F[:, 1], fresnel_dielectric(c, 1.5), rtol=1e-13)  # k = 0: the dielectric
    assert np.all(np.abs(F[:, 2]) <= 1e-16)  # eta = 1, k = 0: no interface
    np.testing.assert_allclose(F[:, 0], exact.fresnel_conductor(c, 0.2, 3.0), rtol=1e-13)
    # f0 is ignored; the default is gold, f0 = (0.967, 0.802, 0.324) at R, G, B
    g = _fresnel("conductor_exact", np.array([1.0]), {})[0]
    np.testing.assert_allclose(g, [0.967, 0.802, 0.324], atol=5e-4)
    assert np.all(_fresnel("conductor_exact", np.array([1.0]), {"f0": 0.0}) == g)


def test_conductor_exact_float32_against_float64():
    c = np.concatenate([np.linspace(1e-3, 1.0, 400), [1e-7, 1e-4]])
    for eta, k in (([0.18, 0.42, 1.37], [3.42, 2.35, 1.77]), ([1.0, 1.5, 0.2], [0.0, 0.0, 0.0]),
                   ([2.9, 0.05, 9.0], [3.0, 8.0, 0.1])):
        p = {"eta": eta, "k": k}
        np.testing.assert_allclose(_fresnel("conductor_exact", c, p, "float32"), _fresnel("conductor_exact", c, p),
                                   rtol=3e-6, atol=1e-7)


# ------------------------------------------------------------------ visibility identities (§4.11)

VIS = ["kelemen_szirmay_kalos", "neumann", "ashikhmin_premoze", "smith_schlick_ggx", "smith_ggx_separable",
       "smith_ggx_height_correlated", "smith_beckmann", "smith_ggx_height_correlated_anisotropic"]


def _vis(filler, L, V, params, dtype="float64"):
    """V of a visibility brick, isolated: the spec divided by the same with V = 1/4 (implicit), times 1/4."""
    p = {"alpha": 0.3, "f0": 1.0, **params}
    if "anisotropic" not in filler:
        p = {k: v for k, v in p.items() if k not in ("alpha_u", "alpha_v")}
    f = _f(f"microfacet(ndf=ggx,fresnel=none,vis={filler})", L, V, p, dtype)[:, 0]
    q = _f("microfacet(ndf=ggx,fresnel=none,vis=implicit)", L, V, {"alpha": p["alpha"], "f0": 1.0}, dtype)[:, 0]
    return 0.25 * f / q


@pytest.mark.parametrize("vis", VIS)
@pytest.mark.parametrize("alpha", [1e-3, 0.3, 1.0])
def test_every_visibility_filler_is_a_quarter_at_normal_incidence(vis, alpha):
    L = Z[None]
    assert _vis(vis, L, L, {"alpha": alpha, "alpha_u": alpha, "alpha_v": 0.5})[0] == pytest.approx(0.25, rel=1e-12)


def _pairs(n=300, lo=0.01, seed=5):
    rng = np.random.default_rng(seed)
    L = _dirs(np.arccos(rng.uniform(lo, 1, n)), rng.uniform(0, 2 * np.pi, n))
    V = _dirs(np.arccos(rng.uniform(lo, 1, n)), rng.uniform(0, 2 * np.pi, n))
    return L, V, L[:, 2], V[:, 2]


def test_visibility_closed_forms():
    L, V, nl, nv = _pairs()
    lv = np.einsum("ij,ij->i", L, V)
    np.testing.assert_allclose(_vis("kelemen_szirmay_kalos", L, V, {}), 1 / (2 * (1 + lv)), rtol=1e-12)
    np.testing.assert_allclose(_vis("neumann", L, V, {}), 1 / (4 * np.maximum(nl, nv)), rtol=1e-13)
    np.testing.assert_allclose(_vis("ashikhmin_premoze", L, V, {}), 1 / (4 * (nl + nv - nl * nv)), rtol=1e-13)
    for a in (0.05, 0.3, 1.0):
        k = a / 2
        np.testing.assert_allclose(_vis("smith_schlick_ggx", L, V, {"alpha": a}),
                                   1 / (4 * (nl * (1 - k) + k) * (nv * (1 - k) + k)), rtol=1e-13)
        g = exact.smith_g_separable(nl, nv, a, exact.lambda_ggx)
        np.testing.assert_allclose(_vis("smith_ggx_separable", L, V, {"alpha": a}), g / (4 * nl * nv), rtol=1e-12)
        g = exact.smith_g_correlated(nl, nv, a, exact.lambda_ggx)
        np.testing.assert_allclose(_vis("smith_ggx_height_correlated", L, V, {"alpha": a}), g / (4 * nl * nv),
                                   rtol=1e-12)
        # the anisotropic filler with alpha_u = alpha_v is the isotropic one
        np.testing.assert_allclose(_vis("smith_ggx_height_correlated_anisotropic", L, V, {"alpha_u": a, "alpha_v": a}),
                                   g / (4 * nl * nv), rtol=1e-12)
    # correlated GGX: alpha = 1 gives 1/(2 (n·l + n·v)); alpha -> 0 gives 1/(4 n·l n·v)
    np.testing.assert_allclose(_vis("smith_ggx_height_correlated", L, V, {"alpha": 1.0}), 1 / (2 * (nl + nv)),
                               rtol=1e-13)
    np.testing.assert_allclose(_vis("smith_ggx_height_correlated", L, V, {"alpha": 1e-4}), 1 / (4 * nl * nv),
                               rtol=1e-4)  # relative deviation alpha² / (2 cos²) <= 5e-5 at cos >= 0.01
    assert schlick_k_ggx(0.5) == 0.25


@pytest.mark.parametrize("alpha", [1e-3, 0.05, 0.3, 0.7, 1.0])
def test_smith_beckmann_erfc_fit_error_is_below_its_bound(alpha):
    # A&S 7.1.26's |ε(erfc)| <= 1.5e-7 bounds the error of each G1 factor by 7.5e-8 (relative)
    L, V, nl, nv = _pairs(2000, lo=1e-4)
    got = _vis("smith_beckmann", L, V, {"alpha": alpha})
    want = exact.smith_g_separable(nl, nv, alpha, exact.lambda_beckmann) / (4 * nl * nv)
    assert np.abs(got / want - 1).max() <= 1.5e-7
    # float32 adds its rounding only
    got32 = _vis("smith_beckmann", L, V, {"alpha": alpha}, "float32")
    assert np.abs(got32 / want - 1).max() <= 2e-6


def test_smith_beckmann_is_finite_at_grazing_light():
    # n·l -> 0: n·l Λ(l) -> alpha / (2 sqrt(pi)), so V(n·l = 0, n·v = 1) = sqrt(pi) / (2 alpha)
    for a in (1e-3, 0.3, 1.0):
        L = _dirs(np.pi / 2, 0.0)[None]
        assert _vis("smith_beckmann", L, Z[None], {"alpha": a})[0] == pytest.approx(math.sqrt(math.pi) / (2 * a),
                                                                                  rel=1e-6)
        for nl in (0.0, 1e-7, 1e-4):
            L = _dirs(np.arccos(nl), 0.0)[None]
            for dtype in ("float64", "float32"):
                f = _f("microfacet(ndf=ggx,fresnel=none,vis=smith_beckmann)", L, Z[None], {"alpha": a, "f0": 1.0},
                       dtype)
                assert np.all(np.isfinite(f))


@pytest.mark.parametrize("vis", ["kelemen_szirmay_kalos", "neumann", "ashikhmin_premoze", "smith_schlick_ggx",
                                 "smith_ggx_separable", "smith_ggx_height_correlated", "smith_beckmann",
                                 "smith_ggx_height_correlated_anisotropic"])
def test_f_cos_vanishes_at_grazing_light(vis):
    # ACCURACY-FACTS pitfall 1: f cos θ_l is finite and -> 0 as n·l -> 0 (V at 45°, away from the mirror)
    V = _dirs(math.pi / 4, np.pi / 2)[None]
    spec = f"microfacet(ndf=ggx,fresnel=none,vis={vis})"
    vals = []
    for nl in (1e-2, 1e-4, 1e-6):
        L = _dirs(np.arccos(nl), 0.0)[None]
        vals.append(_f(spec, L, V, {"alpha": 0.3, "f0": 1.0})[0, 0] * nl)
    assert np.all(np.isfinite(vals)) and vals[2] < vals[1] < vals[0] and vals[2] < 1e-4


# ------------------------------------------------------------------ white furnace, F = 1 (§4.5)

# E(μ) at μ = 1, 0.5, 0.1 (ACCURACY-FACTS §4.5; the separable GGX and Beckmann columns are tests/library/test_energy.py's)
FURNACE = {
    ("ggx", "smith_ggx_separable"): {0.1: (0.9883, 0.9691, 0.8728), 0.5: (0.6878, 0.6860, 0.7723),
                                     1.0: (0.3069, 0.4091, 0.5579)},
    ("ggx", "smith_ggx_height_correlated"): {0.1: (0.9883, 0.9692, 0.8835), 0.5: (0.6878, 0.6983, 0.8601),
                                             1.0: (0.3069, 0.4507, 0.7602)},
    ("beckmann", "smith_beckmann"): {0.1: (1.0000, 0.9998, 0.9123), 0.5: (0.9430, 0.8689, 0.9361),
                                     1.0: (0.4616, 0.7563, 0.9019)},
}
# Measured with this quadrature (the bricks' float64 emission): Schlick's G1 with k = α/2 shadows more than
# exact Smith GGX (identical at α = 1, where k = 1/2 makes it exact).
SCHLICK_GGX = {0.1: (0.98428, 0.88972, 0.65772), 0.5: (0.66139, 0.60772, 0.68710), 1.0: (0.30689, 0.40914, 0.55791)}
MUS = (1.0, 0.5, 0.1)


@pytest.mark.parametrize("key", sorted(FURNACE))
@pytest.mark.parametrize("alpha", [0.1, 0.5, 1.0])
def test_white_furnace_of_the_exact_smith_fillers_matches_the_table(key, alpha):
    ndf, vis = key
    spec = f"microfacet(ndf={ndf},fresnel=none,vis={vis})"
    for mu, want in zip(MUS, FURNACE[key][alpha]):
        e = albedo_microfacet(lambda L, V: _f(spec, L, V, {"alpha": alpha, "f0": 1.0})[:, 0], mu, alpha)
        assert e == pytest.approx(want, abs=1.5e-4)  # table rounding 5e-5


@pytest.mark.parametrize("alpha", [0.1, 0.5, 1.0])
def test_white_furnace_of_smith_schlick_ggx_is_pinned_and_below_exact_smith(alpha):
    spec = "microfacet(ndf=ggx,fresnel=none,vis=smith_schlick_ggx)"
    for mu, measured, exact_e in zip(MUS, SCHLICK_GGX[alpha], FURNACE[("ggx", "smith_ggx_separable")][alpha]):
        e = albedo_microfacet(lambda L, V: _f(spec, L, V, {"alpha": alpha, "f0": 1.0})[:, 0], mu, alpha)
        assert e == pytest.approx(measured, abs=1e-4)
        assert e <= exact_e + 1.5e-4


@pytest.mark.parametrize("alpha,worst", [(0.1, 0.14012), (0.3, 0.10013), (0.5, 0.06635), (1.0, 0.0)])
def test_smith_schlick_ggx_g1_error_against_exact_smith_ggx(alpha, worst):
    c = np.linspace(1e-6, 1.0, 200001)
    d = exact.smith_schlick_g1(c, schlick_k_ggx(alpha)) - exact.smith_g1_ggx(c, alpha)
    assert np.all(d <= 1e-15)  # never less shadowing than exact Smith
    assert -d.min() == pytest.approx(worst, abs=1e-5)


@pytest.mark.parametrize("vis", ["kelemen_szirmay_kalos", "neumann", "ashikhmin_premoze"])
@pytest.mark.parametrize("alpha", [0.1, 0.5, 1.0])
def test_white_furnace_of_the_empirical_visibility_terms_never_gains_energy(vis, alpha):
    spec = f"microfacet(ndf=ggx,fresnel=none,vis={vis})"
    for mu in MUS:
        e = albedo_microfacet(lambda L, V: _f(spec, L, V, {"alpha": alpha, "f0": 1.0})[:, 0], mu, alpha)
        assert 0.0 < e <= 1.0


# ------------------------------------------------------------------ anisotropic Smith (Heitz 2014 eq. 80, 86)

@pytest.mark.parametrize("au,av", [(0.05, 0.5), (0.4, 0.1), (0.3, 0.3)])
@pytest.mark.parametrize("theta_deg,phi_deg", [(0.0, 0.0), (60.0, 0.0), (60.0, 90.0), (80.0, 35.0)])
def test_weak_white_furnace_anisotropic_ggx(au, av, theta_deg, phi_deg):
    # Heitz 2014: ∫ G1(v) max(0, v·h) D(h) dω_h = cos θ_v for the exact anisotropic Smith G1 and D
    H, W = _slope_quadrature(au, av, n=500)
    v = _dirs(math.radians(theta_deg), math.radians(phi_deg))
    cos_v = v[2]
    g1 = 1.0 / (1.0 + lambda_ggx_anisotropic(cos_v, v[0], v[1], au, av))
    c = H[:, 2]
    d = 1.0 / (math.pi * au * av * ((H[:, 0] / au) ** 2 + (H[:, 1] / av) ** 2 + c * c) ** 2)
    integral = np.sum(g1 * np.maximum(H @ v, 0.0) * d * W / c)
    assert integral == pytest.approx(cos_v, abs=2e-5)


def test_anisotropic_ndf_reference_equals_the_slope_form():
    # the (θ_h, φ_h) form of the reference = Heitz's slope form 1/(π au av ((h·t/au)² + (h·b/av)² + (h·n)²)²)
    L, V, _, _ = _pairs(500, seed=9)
    N, T = np.broadcast_to(Z, L.shape), np.broadcast_to(X, L.shape)
    p = {"alpha_u": 0.15, "alpha_v": 0.6, "f0": 1.0}
    f = reference_brdf("microfacet(ndf=ggx_anisotropic,fresnel=none,vis=implicit)", L, V, N, T, p)[:, 0]
    H = (L + V) / np.linalg.norm(L + V, axis=1, keepdims=True)
    d = 1.0 / (math.pi * 0.15 * 0.6 * ((H[:, 0] / 0.15) ** 2 + (H[:, 1] / 0.6) ** 2 + H[:, 2] ** 2) ** 2)
    np.testing.assert_allclose(4 * f, d, rtol=1e-12)
