"""Anisotropic GGX / Trowbridge-Reitz normal distribution.

D = 1 / (pi alpha_u alpha_v cos^4 theta_h (1 + tan^2 theta_h (cos^2 phi_h / alpha_u^2 + sin^2 phi_h / alpha_v^2))^2)
(Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
eq. 85; Burley 2012, "Physically-Based Shading at Disney", appendix B, GTR2_aniso), with
cos^4 multiplied out: D = 1 / (pi au av (sin^2 theta_h e + cos^2 theta_h)^2),
e = cos^2 phi_h / au^2 + sin^2 phi_h / av^2. sin^2 theta_h = |n x h|^2 comes from the glue
(NxH2), as in ggx.py, so the form stays exact in float32 as alpha -> 0 (ACCURACY-FACTS
pitfall 4); phi_h is the azimuth of h in the tangent frame: cos^2 phi_h = (h.t)^2 /
((h.t)^2 + (h.b)^2). With alpha_u = alpha_v = alpha it is ggx.py's D exactly, and it
follows the same shading policy (n.h <= 0: NxH2 = 1, theta_h = 90 degrees).

The microfacet host passes its own `alpha` to the visibility slot: an isotropic Smith
term sees that alpha, not (alpha_u, alpha_v). Pair it with
vis=smith_ggx_height_correlated_anisotropic, which reads alpha_u and alpha_v (the
projected roughness of Heitz 2014 eq. 80 in Lambda, eq. 86), for a consistent anisotropic GGX.
Measured in float32 against the float64 reference (`shadermatrix accuracy`, numpy/GLSL/HLSL/WGSL):
1.5e-6 max relative error on the hemisphere, 3.2e-4 on the stress set (alpha_v = 1e-3, h near T at grazing).
"""
BRICK = {
    "kind": "ndf",
    "cite": "Heitz 2014 eq. 85; Burley 2012 GTR2_aniso; Walter et al. 2007 eq. 33 (isotropic case)",
    "params": {
        "alpha_u": {"type": "float", "range": [0.0, 1.0], "default": 0.2,
                    "doc": "GGX roughness along the tangent T"},
        "alpha_v": {"type": "float", "range": [0.0, 1.0], "default": 0.4,
                    "doc": "GGX roughness along the bitangent B"},
    },
}

# alpha_u, alpha_v are floored at 1e-4 (Mitsuba's floor, as ggx.py): alpha = 0 is a Dirac peak
# (0/0 at h = n). Cost: a roughness below 1e-4 renders as 1e-4.
ALPHA_MIN = 0.0001
# (h.t)^2 + (h.b)^2 is floored at 1e-30 before dividing by it: it is 0 at h = n (where NxH2 = 0
# makes e irrelevant) and for the undefined half vector h = 0 (l = -v). Cost: where the tangent
# component of h vanishes (h = 0 or h.t, h.b below 1e-15), phi_h is taken as 0 (e = 1/alpha_u^2);
# the reference makes the same choice for h = 0, and at h = n the value does not depend on it.
TB2_MIN = 1e-30


def ndf(NdotH: float, NxH2: float, HdotT: float, HdotB: float, alpha_u: float, alpha_v: float) -> float:
    au = max(alpha_u, ALPHA_MIN)
    av = max(alpha_v, ALPHA_MIN)
    t2 = HdotT * HdotT
    b2 = HdotB * HdotB
    tb2 = t2 + b2
    e = (t2 / (au * au) + b2 / (av * av)) / tb2 if tb2 > TB2_MIN else 1.0 / (au * au)
    d = NxH2 * e + NdotH * NdotH
    return 1.0 / (PI * au * av * d * d)


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


def sample_h(u: vec2, V: vec3, N: vec3, T: vec3, B: vec3, alpha_u: float, alpha_v: float) -> vec3:
    return vndf_sample(u, V, N, T, B, max(alpha_u, ALPHA_MIN), max(alpha_v, ALPHA_MIN))


def pdf_h(H: vec3, V: vec3, N: vec3, T: vec3, B: vec3, alpha_u: float, alpha_v: float) -> float:
    return vndf_pdf(H, V, N, T, B, max(alpha_u, ALPHA_MIN), max(alpha_v, ALPHA_MIN))
