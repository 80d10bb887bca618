"""No Fresnel variation: F = f0 at every angle.

RTR3 §7.6.1: dropping the angular Fresnel factor leaves R_F(0) as a constant
specular color (the "no Fresnel" column of Hoffman & Baker 2006's comparisons).
"""
BRICK = {
    "kind": "fresnel",
    "cite": "RTR3 §7.6.1 (constant R_F(0)); Hoffman & Baker 2006",
}


def fresnel(f0: vec3, VdotH: float) -> vec3:
    return f0
