"""Ward's normal distribution (isotropic): D = exp(-tan^2 theta_h / m^2) / (pi m^2 cos^3 theta_h), m = alpha.

Ward 1992, "Measuring and Modeling Anisotropic Reflection", eq. 4 (isotropic Gaussian
lobe exp(-tan^2 delta / alpha^2) / (4 pi alpha^2 sqrt(cos theta_i cos theta_r))), whose
half-vector density (Walter 2005, "Notes on the Ward BRDF", Cornell PCG-05-06) is
this D. Hoffman & Baker 2006 describe Ward's model as using "a modified Beckmann NDF"; this
D is Beckmann's (beckmann.py) times cos theta_h.

Decisions:
- Isotropic, with Ward's slope parameter m read from the host's `alpha` (the slot contract
  passes one roughness; Beckmann's alpha is also the RMS slope m, so ndf=ward and
  ndf=beckmann are comparable at one alpha). The anisotropic Gaussian of Ward's eq. 5a is
  ndf=beckmann_anisotropic.
- Normalization: Ward's D is a density in solid angle, integral of D d omega_h = 1, not in
  projected area: integral of D cos theta_h d omega_h = 1 - O(m^2) (quadrature: 0.99507 at
  m = 0.1, 0.98109 at 0.2, 0.90535 at 0.5, 0.75787 at 1; tests/library/test_library_fillers.py), so
  it reflects less than a projected-area-normalized NDF (Beckmann) at the same m.
- Seed typos: Hoffman & Baker 2006 (seed 000), "Ward - Anisotropic", print the exponent as
  e^{tan^2 theta_h (cos^2 phi / m_u + sin^2 phi / m_v)}: Ward 1992 eq. 5a has a minus sign
  and m_u^2, m_v^2 (their own second form, with (cos a_u / m_u)^2, has the squares).
sin^2 theta_h = |n x h|^2 from the glue (NxH2) keeps the lobe exact in float32 as m -> 0
(ACCURACY-FACTS pitfall 4).
Measured in float32 (`shadermatrix accuracy`, every target): 7.4e-6 on the hemisphere, 4.1e-5 on the
stress set.
"""
BRICK = {
    "kind": "ndf",
    "cite": "Ward 1992 eq. 4; Walter 2005 (Notes on the Ward BRDF); Hoffman & Baker 2006",
}

# m^2 is floored at 1e-8 (alpha >= 1e-4, as the other NDFs). Cost: alpha < 1e-4 renders as 1e-4.
ALPHA2_MIN = 1e-8
# cos^2 theta_h is floored at 1e-8 (cos at 1e-4) so that at n.h = 0 D is exp(-huge) / positive = 0
# instead of 0/0 (ACCURACY-FACTS pitfall 9). Cost: none; exp(-tan^2 / m^2) has underflowed
# (< 1e-38) long before, once cos^2 < 0.012 at m = 1.
COS2_MIN = 1e-8


def ndf(NdotH: float, NxH2: float, alpha: float) -> float:
    a2 = max(alpha * alpha, ALPHA2_MIN)
    c2 = max(NdotH * NdotH, COS2_MIN)
    return exp(-NxH2 / (a2 * c2)) / (PI * a2 * c2 * sqrt(c2))
