"""Beckmann normal distribution: D = exp(-tan^2 theta_h / m^2) / (pi m^2 cos^4 theta_h).

Beckmann & Spizzichino 1963; Cook & Torrance 1982 eq. 5 (with the 1/pi that
normalizes the projected area, Walter et al. 2007 eq. 25); alpha is the RMS slope m.
tan^2 theta_h = sin^2 / cos^2 with sin^2 theta_h = |n x h|^2 from the glue (NxH2),
which keeps its digits as h -> n where 1 - cos^2 does not (ACCURACY-FACTS pitfall 4).
Measured in float32 against the float64 reference (stress set, `shadermatrix
accuracy`): max error 18 % at alpha = 1e-3 with (1 - cos^2)/cos^2, 4e-5 with NxH2.

fp16 (measured on lavapipe, `accuracy --dtypes float16`): unsafe. COS2_MIN = 1e-8 is 0 in
half and (n.h)^4 underflows below n.h = 0.016, so D is 0/0 = NaN there (black specks on grazing
ground). A floor of 2.5e-4 on (n.h)^2 would guard it; the brick language has no precision-
conditional constant yet, so fp16 permutations that use it get a build warning.
"""
BRICK = {
    "kind": "ndf",
    "fp16": "unsafe: COS2_MIN 1e-8 is 0 in half and (n.h)^4 underflows below n.h = 0.016: 0/0 = NaN",
    "cite": "Cook & Torrance 1982 eq. 5; normalized form Walter et al. 2007 eq. 25",
}

# m^2 is floored at 1e-8 (alpha >= 1e-4, as GGX): alpha = 0 is a Dirac peak.
# Cost: alpha < 1e-4 renders as 1e-4.
ALPHA2_MIN = 1e-8
# cos^2 is floored at 1e-8 so that at n.h = 0 D is exp(-huge) / positive = 0 instead of
# 0/0 (ACCURACY-FACTS pitfall 9). Cost: none; D underflows to 0 long before
# (exp(-tan^2 / m^2) < 1e-38 once tan^2 > 88 m^2, i.e. cos^2 < 0.012 for m = 1).
COS2_MIN = 1e-8


def ndf(NdotH: float, NxH2: float, alpha: float) -> float:
    a2 = max(alpha * alpha, ALPHA2_MIN)
    c2 = max(NdotH * NdotH, COS2_MIN)
    return exp(-NxH2 / (a2 * c2)) / (PI * a2 * c2 * c2)


# Sampling (the contract: library/kinds.py): h drawn proportional to D(h) cos theta_h (Walter et al. 2007
# eqs. 28-29; the anisotropic case as Walter 2005, "Notes on the Ward BRDF", eqs. 6-7), through the slopes:
# the Beckmann slope density is the Gaussian exp(-(x^2/ax^2 + y^2/ay^2)) / (pi ax ay), so
# (x/ax, y/ay) = sqrt(-log(1 - xi)) (cos 2 pi xi', sin 2 pi xi') and h = normalize(-x, -y, 1); the density
# per unit solid angle of h is D(h) cos theta_h = exp(-tan^2 theta_h (cos^2 phi/ax^2 + sin^2 phi/ay^2)) /
# (pi ax ay cos^3 theta_h). Not by visible normals: the mass the host's reflection sends below the horizon
# is lost (the caller scores it 0) and the estimator's weight carries G.
def slope_sample(u: vec2, N: vec3, T: vec3, B: vec3, ax: float, ay: float) -> vec3:
    r = sqrt(-log(max(1.0 - u.x, 1e-30)))
    phi = TWO_PI * u.y
    return normalize(T * (-ax * r * cos(phi)) + B * (-ay * r * sin(phi)) + N)


def slope_pdf(H: vec3, N: vec3, T: vec3, B: vec3, ax: float, ay: float) -> float:
    c = dot(N, H)
    x = dot(H, T) / ax
    y = dot(H, B) / ay
    c2 = max(c * c, COS2_MIN)
    return exp(-min((x * x + y * y) / c2, 1000.0)) / (PI * ax * ay * c2 * c) if c > 0.0 else 0.0


def sample_h(u: vec2, N: vec3, T: vec3, B: vec3, alpha: float) -> vec3:
    a = sqrt(max(alpha * alpha, ALPHA2_MIN))
    return slope_sample(u, N, T, B, a, a)


def pdf_h(H: vec3, N: vec3, T: vec3, B: vec3, alpha: float) -> float:
    a = sqrt(max(alpha * alpha, ALPHA2_MIN))
    return slope_pdf(H, N, T, B, a, a)
