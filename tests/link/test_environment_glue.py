"""The glue's ambient term (link/glue.py ambient): shade() of a permutation with an environment, run on the NumPy
target, adds after the lights what the float64 split sum (reference/environment.py) gives with kd as
spec/ambient.py's DIFFUSE_HOW says: ρ_d (1 − f0) for Gotanda's diffuse, ρ_d for Lambert, 0 with no diffuse term;
the environment's values are the Lights block's last group, from a new vec4 after the lights'."""
from __future__ import annotations

import numpy as np
import pytest

GGX = "microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"


@pytest.fixture(scope="module")
def lib():
    from generator.library.bricks import load_library
    return load_library()


@pytest.mark.parametrize("diffuse,kd", [("gotanda_fitted+", lambda rho, f0: rho * (1 - f0)),
                                        ("lambert+", lambda rho, f0: rho), ("", lambda rho, f0: 0 * rho)])
def test_shade_adds_the_split_sum_with_the_diffuse_terms_kd(lib, diffuse, kd):
    from generator.backends import get_target
    from generator.link import link_permutation
    from generator.reference.environment import split_sum
    from generator.spec.permutation import Permutation

    lp = link_permutation(Permutation(diffuse + GGX, (), "constants", "linear", environment="split_sum"), lib)
    assert [s.environment for s in lp.environment] == [True] * 11 and lp.environment[0].index == 0
    assert {t.param: (t.set, t.environment) for t in lp.interface.textures} == {"radiance": (0, True),
                                                                              "ambient_brdf": (1, True)}
    nt = get_target("numpy")
    fns = nt.load(nt.emit(lp.program.structs, lp.program.functions), np.float64)
    rng = np.random.default_rng(3)
    m = 64
    N = rng.normal(size=(m, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    V = N + 0.5 * rng.normal(size=(m, 3))
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    rho, f0, alpha = np.array([0.7, 0.4, 0.2]), np.array([0.05, 0.5, 0.9]), 0.3
    sh = rng.normal(size=(9, 3))
    levels = [rng.uniform(0, 1, (6, s, s, 4)) for s in (4, 2, 1)]
    table = rng.uniform(0, 1, (32, 32, 4))
    values = {"P": np.zeros((m, 3)), "Ng": N, "V": V, "m_rho_d": rho, "m_f0": f0, "m_alpha": alpha,
              **{f"e_sh{k}": sh[k] for k in range(9)}, "e_intensity": 0.8, "e_radiance_levels": 3.0,
              "e_radiance": levels, "e_ambient_brdf": table}
    got = fns["shade"](*(values[n] for n, _ in lp.glue.signature))[:, :3]
    want = split_sum(N, V, kd(rho, f0), f0, alpha, sh, 0.8, levels, table)
    np.testing.assert_allclose(got, want, rtol=2e-6, atol=2e-6 * np.abs(want).max())
