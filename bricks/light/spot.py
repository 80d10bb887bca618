"""Spot light: inverse square, smooth range window, inner and outer cone with a smooth falloff.

    c_light = color · (saturate(1 − (d/r)⁴))² / d² · a(cos θ_s)²,
    a = saturate((cos θ_s − cos θ_outer) / (cos θ_inner − cos θ_outer)),

θ_s the angle between the spot's axis `direction` and the ray from the light to the
surface point (cos θ_s = dot(direction, −l)). The angular term is the one of Lagarde &
de Rousiers 2014, "Moving Frostbite to PBR", section "Punctual lights" (getAngleAtt), the
reference code of glTF 2.0 KHR_lights_punctual ("Inner and Outer Cone Angles"): 1 inside the inner cone,
0 outside the outer one, and between them a squared linear ramp in cos θ_s (zero slope at
the outer edge, so the cone's border shows no ring). Distance term as `point_range`
(Karis 2013, eq. 9). Hoffman & Baker 2006: the game intensity i_l(d_l).

Angles are half-angles in radians, as glTF's innerConeAngle / outerConeAngle; their
cosines are computed here (two cos per light and pixel, that an engine would hoist to
the CPU as glTF's lightAngleScale / lightAngleOffset).

Guards: d² ≥ 1e-4 (as `point`); cos θ_inner − cos θ_outer ≥ 1e-3 (glTF's own
max(0.001, …)): with inner ≥ outer the cone has a hard edge 1e-3 wide in cos θ_s
instead of dividing by zero. `direction` is normalized here, so a scene may give
any non-zero vector; the ray from the light to P is −d·rsqrt(max(d², 1e-30)), so a
point on the light gets cos θ_s = 0 (then c_light is bounded by the d² floor) instead of NaN.
"""
BRICK = {
    "kind": "light",
    "cite": "Lagarde & de Rousiers 2014, Punctual lights (getAngleAtt, smoothDistanceAtt); KHR_lights_punctual cone angles",
    "params": {
        "position": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 2.0, 0.0], "doc": "world-space position"},
        "direction": {"type": "vec3", "range": [-1.0, 1.0], "default": [0.0, -1.0, 0.0], "doc": "the spot's axis: from the light into the scene"},
        "color": {"type": "vec3", "range": [0.0, 1000000.0], "default": [1.0, 1.0, 1.0], "doc": "linear RGB intensity at unit distance on the axis"},
        "radius": {"type": "float", "range": [0.001, 1000000.0], "default": 10.0, "doc": "range r: c_light is 0 from d = r on"},
        "inner_angle": {"type": "float", "range": [0.0, 1.5707963], "default": 0.0, "doc": "half-angle of full intensity (radians)"},
        "outer_angle": {"type": "float", "range": [0.0, 1.5707963], "default": 0.7853982, "doc": "half-angle where c_light reaches 0 (radians)"},
    },
}


def light_dir(P: vec3, position: vec3) -> vec3:
    return normalize(position - P)


def light_radiance(P: vec3, position: vec3, direction: vec3, color: vec3, radius: float, inner_angle: float,
                   outer_angle: float) -> vec3:
    d = position - P
    d2 = dot(d, d)
    q = d2 / (radius * radius)  # (d/r)^2
    w = saturate(1.0 - q * q)
    cos_outer = cos(outer_angle)
    # glTF's max(0.001, ...): inner >= outer gives a hard edge instead of a division by zero.
    scale = 1.0 / max(cos(inner_angle) - cos_outer, 0.001)
    # -d/|d|, the ray from the light to P; |d|^2 floored at 1e-30 so that P on the light gives cd = 0, not NaN
    cd = dot(normalize(direction), -d * rsqrt(max(d2, 1e-30)))
    a = saturate((cd - cos_outer) * scale)
    # d^2 floored at 1e-4 as in `point` (a surface point on the light).
    return color * (w * w * a * a / max(d2, 0.0001))

