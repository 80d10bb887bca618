"""Banks anisotropic specular: f_r = (k_s / pi) max(0, sqrt(1 - (l.t)^2) sqrt(1 - (v.t)^2) - (l.t)(v.t))^n.

Banks 1994, "Illumination in Diverse Codimensions" (SIGGRAPH 94), as presented by
Hoffman & Baker 2006 ("Banks - Anisotropic version of Blinn-Phong; surface model composed
of threads; uses projection of light vector onto plane perpendicular to tangent instead of
surface normal"). A thread has a circle of normals n' perpendicular to t; the diffuse term
uses the one nearest l, sqrt(1 - (l.t)^2) = max n'.l, and the specular kernel the mirror
direction of l nearest v: the mirror directions about all n' form the cone r.t = -(l.t), and
    max v.r = sqrt(1 - (l.t)^2) sqrt(1 - (v.t)^2) - (l.t)(v.t)
(Heidrich & Seidel 1998 write Banks' model with these two closed forms; ACCURACY-FACTS
§4.10). Banks writes the lighting equation I = k_s (v.r')^n without a cosine factor; read
as a BRDF it would carry 1/cos theta_i like the original Phong (brick `phong`). This brick
takes the course's first plausibility step for it (the cosine factor included, as
`phong_reciprocal`): f_r = (k_s / pi) (v.r')^n, symmetric in l and v, hence
reciprocal. No normalization is claimed (the kernel's maximum is a cone of directions,
the albedo of kernel^n decays like 1/sqrt(n), not like 1/n: ACCURACY-FACTS §4.10 has none to assert).
Self-shadowing (Banks; the course: "when the light is not in the hemisphere about the
original surface normal, the lighting is set to 0 ... the only effect the surface normal
has on this model"): f_r = 0 for n.l <= 0, written out here although the glue already
returns 0 there. The diffuse part of Banks, k_d sqrt(1 - (l.t)^2), is not in this brick.
Reads the tangent frame (LdotT, VdotT, T): a permutation needs a packing with tangents.
"""
BRICK = {
    "kind": "specular",
    "cite": "Banks 1994; Hoffman & Baker 2006 (anisotropic Blinn-Phong of threads, self-shadowing)",
    "params": {
        "n": {"type": "float", "range": [1.0, 100000.0], "default": 32.0, "doc": "Banks cosine power"},
        "k_s": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5],
                "doc": "specular coefficient k_s of Banks' lighting equation (not a reflectance)"},
    },
    "needs": ["NdotL", "LdotT", "VdotT", "L", "V", "T"],
}


def specular(NdotL: float, LdotT: float, VdotT: float, L: vec3, V: vec3, T: vec3, n: float,
             k_s: vec3) -> vec3:
    # sqrt(1 - (x.t)^2) is computed as |x × t|: near x = ±t, 1 - (x.t)^2 is all rounding in
    # float32 (5e-4 relative error at x.t = 0.99988, measured on the hemisphere), the cross
    # product keeps its digits (as NxH2 does for sin theta_h). The kernel is clamped to [0, 1]
    # before pow: a negative base is undefined, and rounding must not push the peak above 1.
    sl = length(cross(L, T))
    sv = length(cross(V, T))
    kernel = clamp(sl * sv - LdotT * VdotT, 0.0, 1.0)
    shadow = 1.0 if NdotL > 0.0 else 0.0
    return k_s * (INV_PI * shadow * pow(kernel, n))
