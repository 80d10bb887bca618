"""Cook-Torrance: f_r = (1 - s) rho_d / pi + s F(l.h) D(h) G(l, v) / (4 (n.l)(n.v)).

Cook & Torrance 1982, "A Reflectance Model for Computer Graphics", as Hoffman & Baker 2006
print it: f_r = (1 - s) rho_d/pi + s p(w_h) G(w_i, w_e) R_F(alpha_h) / (pi cos theta_i
cos theta_e), s in [0, 1] the specular fraction (Cook & Torrance's s + d = 1). The diffuse
part is Lambert's, inside this brick. The specular part is the microfacet term with the 4
of the half-vector Jacobian, as RTR3 eq. 7.51 and Walter et al. 2007 eq. 20 write it (the
`microfacet` brick's), not the pi of the course and of Cook & Torrance 1982: their pi goes
with Cook & Torrance's Beckmann D = exp(-tan^2/m^2)/(m^2 cos^4), which lacks the 1/pi of a
normalized NDF; with a normalized p(w_h), as the slots are (∫ D cos theta_h = 1), the
printed pi would make the specular term 4/pi = 1.27 times too bright.
Slots as `microfacet`, defaults Cook & Torrance's choices: Beckmann NDF (m = alpha), the
V-cavity G of Torrance & Sparrow (Blinn 1977), and Schlick's Fresnel (RTR3's; the paper
used the exact dielectric Fresnel: a slot choice). Reciprocal.
"""
BRICK = {
    "kind": "specular",
    "cite": "Cook & Torrance 1982; Hoffman & Baker 2006 ((1-s) rho_d/pi + s specular); RTR3 eq. 7.51",
    "params": {
        "s": {"type": "float", "range": [0.0, 1.0], "default": 0.5, "doc": "specular fraction s (diffuse 1 - s)"},
        "rho_d": {"type": "vec3", "range": [0.0, 1.0], "default": [0.5, 0.5, 0.5], "doc": "diffuse albedo (linear RGB)"},
        "alpha": {"type": "float", "range": [0.0, 1.0], "default": 0.3, "doc": "roughness: Beckmann RMS slope m, GGX alpha"},
        "f0": {"type": "vec3", "range": [0.0, 1.0], "default": [0.04, 0.04, 0.04], "doc": "Fresnel reflectance at normal incidence"},
    },
    "slots": {
        "ndf": {"kind": "ndf", "default": "beckmann"},
        "fresnel": {"kind": "fresnel", "default": "schlick"},
        "vis": {"kind": "visibility", "default": "torrance_sparrow"},
    },
}


def specular(NdotL: float, NdotV: float, NdotH: float, NxH2: float, VdotH: float, s: float,
             rho_d: vec3, alpha: float, f0: vec3) -> vec3:
    D = ndf(NdotH, NxH2, alpha)
    Vis = vis(NdotL, NdotV, NdotH, VdotH, alpha)
    return (1.0 - s) * INV_PI * rho_d + s * (fresnel(f0, VdotH) * (D * Vis))
