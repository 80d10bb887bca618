"""Test brick: anisotropic GGX normal distribution, reading the tangent frame.

D = 1 / (π α_u α_v ((h·t/α_u)² + (h·b/α_v)² + (h·n)²)²) (Burley 2012, eq. 13; Heitz 2014
eq. 13 with the slope form multiplied out). With α_u = α_v = α it is the isotropic GGX of
Walter et al. 2007 eq. 33, since (h·t)² + (h·b)² = sin²θ_h. A slot filler reading shading
inputs its host does not pass (HdotT, HdotB): the link stage threads them.
"""
BRICK = {
    "kind": "ndf",
    "cite": "Burley 2012 eq. 13; Heitz 2014 eq. 13",
    "params": {
        "alpha_u": {"type": "float", "range": [0.0001, 1.0], "default": 0.2, "doc": "roughness along T"},
        "alpha_v": {"type": "float", "range": [0.0001, 1.0], "default": 0.4, "doc": "roughness along B"},
    },
}


def ndf(NdotH: float, HdotT: float, HdotB: float, alpha_u: float, alpha_v: float) -> float:
    x = HdotT / alpha_u
    y = HdotB / alpha_v
    d = x * x + y * y + NdotH * NdotH
    return 1.0 / (PI * alpha_u * alpha_v * d * d)
