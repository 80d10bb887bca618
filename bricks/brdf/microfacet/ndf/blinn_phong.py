"""Blinn-Phong normal distribution: D = (n + 2) / (2 pi) * (n.h)^n, n = 2 / alpha^2 - 2.

RTR3 §7.6.1 eq. 7.48 (normalized Blinn-Phong NDF, (n+2)/2pi); the exponent
is derived from the Beckmann roughness alpha by the equivalence n = 2/alpha^2 - 2
of Walter et al. 2007, eq. 30, so all NDF fillers share one roughness parameter.
(n.h)^n is evaluated as exp(n/2 ln(1 - sin^2 theta_h)) with sin^2 theta_h = |n x h|^2
from the glue: near h = n a float32 n.h is quantized to steps of 6e-8, which an
exponent of 2e6 (alpha = 1e-3) turns into 12 % errors (GPU pow, exp2(n log2 x), is
worse still: Vulkan allows log2 an absolute error of 2^-21 near 1). Below x = 1e-2,
ln(1 - x) is summed as a series (truncation x^5/5 < 2e-11: a relative error in D of
(n x) x^4/10, under 4e-8 wherever D exceeds 1e-14 of its peak).
Measured in float32 against the float64 reference (stress set): 18 % max error at
alpha = 1e-3 with pow(n.h, n), 4e-5 with this form.

fp16: unsafe. n = 2/alpha^2 - 2 overflows half (65504) below alpha = 0.0055, and the
cosine floor becomes 0, so 0 * log 0 = NaN at alpha = 1.
"""
BRICK = {
    "kind": "ndf",
    "fp16": "unsafe: n overflows half below alpha = 0.0055 and the cosine floor is 0 in half: NaN at alpha = 1",
    "cite": "RTR3 eq. 7.48; exponent from alpha by Walter et al. 2007 eq. 30",
}

# alpha is floored at 1e-4 (as GGX and Beckmann): n <= 2e8 stays finite. Cost: alpha < 1e-4
# renders as 1e-4.
ALPHA_MIN = 0.0001
# n.h is floored at 1e-30 inside the logarithm: at alpha = 1 (n = 0) and n.h = 0, (n.h)^n is
# 0^0, undefined in GLSL/SPIR-V (exp2(0 * -inf) = NaN); floored it is 1, the limit. Cost: for
# n > 0, D(n.h = 0) is (n+2)/2pi 1e-30^n instead of 0: below 1e-30 for n >= 1 (alpha <= 0.82);
# for n -> 0 it tends to 1/pi, as D(n.h) does at every n.h > 0.
COS_MIN = 1e-30


def ndf(NdotH: float, NxH2: float, alpha: float) -> float:
    a = max(alpha, ALPHA_MIN)
    n = 2.0 / (a * a) - 2.0
    x = NxH2
    ln_c2 = -x * (1.0 + x * (0.5 + x * (1.0 / 3.0 + x * 0.25))) if x < 0.01 else 2.0 * log(max(NdotH, COS_MIN))
    return (n + 2.0) * INV_TWO_PI * exp(0.5 * n * ln_c2)


# Sampling (the contract: library/kinds.py): h drawn proportional to D(h) cos theta_h, the course's cos^alpha
# sampler with alpha = n + 1 (Bikker 2017; Walter et al. 2007 eq. 30: cos theta_h = xi^(1/(n+2))), density
# (n + 2)/(2 pi) (n.h)^(n+1) per unit solid angle of h.
def sample_h(u: vec2, N: vec3, T: vec3, B: vec3, alpha: float) -> vec3:
    a = max(alpha, ALPHA_MIN)
    n = 2.0 / (a * a) - 2.0
    c = pow(u.x, 1.0 / (n + 2.0))
    s = sqrt(max(1.0 - c * c, 0.0))
    phi = TWO_PI * u.y
    return T * (s * cos(phi)) + B * (s * sin(phi)) + N * c


def pdf_h(H: vec3, N: vec3, alpha: float) -> float:
    a = max(alpha, ALPHA_MIN)
    n = 2.0 / (a * a) - 2.0
    c = dot(N, H)
    return (n + 2.0) * INV_TWO_PI * pow(c, n + 1.0) if c > 0.0 else 0.0
