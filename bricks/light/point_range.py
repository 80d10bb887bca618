"""Point light with inverse-square falloff and a smooth range window (Karis 2013, eq. 9; Frostbite).

    c_light(d) = color · (saturate(1 − (d/r)⁴))² / d²

`color` is the intensity at unit distance (as `point`), r the light's `radius` (glTF
KHR_lights_punctual's `range`, UE4's attenuation radius): the window is 1 − 2(d/r)⁴ + …
near the light, so the light is the physical 1/d² one there, and it reaches exactly 0 with
zero slope at d = r, so a light can be culled at its radius without a visible edge.
Sources: Karis 2013, "Real Shading in Unreal Engine 4", eq. 9 (there with 1/(d² + 1));
Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", section "Punctual lights"
(smoothDistanceAtt, with 1/d²: the form used here). glTF KHR_lights_punctual recommends the
window unsquared, max(min(1 − (d/r)⁴, 1), 0) / d², whose slope at d = r is not 0; the squared
one is below it by at most 0.25 (at (d/r)⁴ = 1/2). Hoffman & Baker 2006: this is the light's
game intensity i_l(d_l).

Guard: d² is floored at 1e-4 (as `point`: a surface point on the light would divide by
zero); it changes c_light only within 1 cm of the light at metre scale. The window needs
no guard: (d/r)⁴ is computed as (d²/r²)², finite for r ≥ 1e-3 (the range's floor).
"""
BRICK = {
    "kind": "light",
    "cite": "Karis 2013 eq. 9; Lagarde & de Rousiers 2014, Punctual lights (smoothDistanceAtt, 1/d^2)",
    "params": {
        "position": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 2.0, 0.0], "doc": "world-space position"},
        "color": {"type": "vec3", "range": [0.0, 1000000.0], "default": [1.0, 1.0, 1.0], "doc": "linear RGB intensity at unit distance"},
        "radius": {"type": "float", "range": [0.001, 1000000.0], "default": 10.0, "doc": "range r: c_light is 0 from d = r on"},
    },
}


def light_dir(P: vec3, position: vec3) -> vec3:
    return normalize(position - P)


def light_radiance(P: vec3, position: vec3, color: vec3, radius: float) -> vec3:
    d = position - P
    d2 = dot(d, d)
    q = d2 / (radius * radius)  # (d/r)^2
    w = saturate(1.0 - q * q)
    # d^2 floored at 1e-4 as in `point` (a surface point on the light).
    return color * (w * w / max(d2, 0.0001))
