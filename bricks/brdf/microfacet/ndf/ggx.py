"""GGX / Trowbridge-Reitz normal distribution: D = alpha^2 / (pi (alpha^2 cos^2 theta_h + sin^2 theta_h)^2).

Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces",
eq. 33, D = alpha^2 / (pi cos^4 theta_h (alpha^2 + tan^2 theta_h)^2), with cos^4
multiplied out; Trowbridge & Reitz 1975. sin^2 theta_h = |n x h|^2 comes from the
glue (NxH2): the textbook (n.h)^2 (alpha^2 - 1) + 1 cancels catastrophically near
the peak in float32 (ACCURACY-FACTS pitfall 4: -2.6 % at alpha = 1e-3, inf at 1e-4).
Measured in float32 against the float64 reference (stress set, `shadermatrix
accuracy`): max error 22 % at alpha = 1e-3 and 0.3 % at 1e-2 with the textbook form,
4e-5 and 5e-6 with this one (2e-4 at alpha = 1e-4).

fp16: d^2 underflows once d < 2.4e-4, so the peak is inf for alpha < 0.016 (well before
1/(pi alpha^2) itself overflows 65504, below alpha = 0.0022); at alpha >= 0.3 the hemisphere
error is 1e-2 (measured on lavapipe). Safe above alpha = 0.016, which is where a half-precision
material should stay.
"""
BRICK = {
    "kind": "ndf",
    "cite": "Walter et al. 2007 eq. 33; Trowbridge & Reitz 1975",
}

# alpha is floored at 1e-4 (Mitsuba's floor): alpha = 0 is a Dirac peak, 0/0 at h = n.
# The peak 1/(pi alpha^2) = 3.2e7 stays finite in float32 times any visibility term.
# Cost: alpha < 1e-4 renders as 1e-4 (a mirror as a lobe 1e-4 rad wide).
ALPHA_MIN = 0.0001


def ndf(NdotH: float, NxH2: float, alpha: float) -> float:
    a = max(alpha, ALPHA_MIN)
    a2 = a * a
    d = a2 * NdotH * NdotH + NxH2
    return a2 / (PI * d * d)


# Sampling (the contract: library/kinds.py): h drawn from the distribution of normals visible from v,
# D_v(h) = G1(v) max(0, v.h) D(h) / (n.v) (Heitz 2018, "Sampling the GGX Distribution of Visible Normals",
# JCGT 7(4), listing 1 and eq. 3), with Smith's G1(v) = 2 / (1 + sqrt(1 + (ax^2 v_t^2 + ay^2 v_b^2) / v_n^2))
# (Heitz 2014 eqs. 43, 86). n.v is clamped at 1e-4 as the shading policy clamps it. The microfacet host
# reflects v about h; directions it sends below the horizon are the masked part, which the caller scores 0.
def vndf_sample(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, ax: float, ay: float) -> vec3:
    vh = normalize(vec3(ax * dot(V, T), ay * dot(V, B), max(dot(V, N), 0.0001)))
    lensq = vh.x * vh.x + vh.y * vh.y
    # the same bound on both sides: v = n leaves lensq ~1e-35 of rounding, which a floor of the rsqrt alone
    # turned into a t1 of length 3e-3 (a lobe shrunk to 0.4° at alpha = 0.25)
    t1 = vec3(-vh.y, vh.x, 0.0) * rsqrt(max(lensq, 1e-30)) if lensq > 1e-30 else vec3(1.0, 0.0, 0.0)
    t2 = cross(vh, t1)
    r = sqrt(u.x)
    phi = TWO_PI * u.y
    p1 = r * cos(phi)
    s = 0.5 * (1.0 + vh.z)
    p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * (r * sin(phi))
    nh = t1 * p1 + t2 * p2 + vh * sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0))
    ne = normalize(vec3(ax * nh.x, ay * nh.y, max(nh.z, 0.0)))
    return T * ne.x + B * ne.y + N * ne.z


def vndf_pdf(H: vec3, V: vec3, N: vec3, T: vec3, B: vec3, ax: float, ay: float) -> float:
    vn = max(dot(V, N), 0.0001)
    vt = ax * dot(V, T)
    vb = ay * dot(V, B)
    g1 = 2.0 / (1.0 + sqrt(1.0 + (vt * vt + vb * vb) / (vn * vn)))
    ht = dot(H, T) / ax
    hb = dot(H, B) / ay
    hn = dot(H, N)
    d = ht * ht + hb * hb + hn * hn
    vdh = dot(V, H)
    return g1 * vdh / (PI * ax * ay * d * d * vn) if hn > 0.0 and vdh > 0.0 else 0.0


def sample_h(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, alpha: float) -> vec3:
    a = max(alpha, ALPHA_MIN)
    return vndf_sample(u, V, N, T, B, a, a)


def pdf_h(H: vec3, V: vec3, N: vec3, T: vec3, B: vec3, alpha: float) -> float:
    a = max(alpha, ALPHA_MIN)
    return vndf_pdf(H, V, N, T, B, a, a)
