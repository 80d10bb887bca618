"""Float64 references of the light bricks: the direction to the light and the game intensity i_l(d_l).

Hoffman & Baker 2006, "Physically-Based Reflectance for Games": the light loop adds
π f_r(l, v) ⊙ c_light cos θ_l, with c_light = i_l(d_l) the light's intensity at the point.
Each function takes surface points P (n, 3) and the light's parameters (by the bricks'
names, as the scene gives them) and returns (l, c): l the unit vector from P toward the
light (n, 3) and c_light (n, 3). Written from the sources cited per function, independent
of the brick code; the bricks' guards (d² floors, …) are not reproduced (docs/design/accuracy.md,
"Accuracy"), so compare away from the light's position (d ≫ 1 cm).

LIGHTS maps a light brick id to its function.
"""
from __future__ import annotations

import numpy as np


def _rows(a, n):
    return np.broadcast_to(np.asarray(a, np.float64), (n, 3))


def _unit(a):
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def _toward(P, position):
    P = np.asarray(P, np.float64)
    d = _rows(position, len(P)) - P
    dist = np.linalg.norm(d, axis=1)
    return d / dist[:, None], dist


def _smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def directional(P, direction, color):
    """i_l = c_light, constant (Hoffman & Baker 2006: "for a directional light, simply a constant")."""
    n = len(P)
    return _unit(_rows(direction, n)).copy(), _rows(color, n).copy()


def point(P, position, color):
    """Inverse-square falloff, `color` the intensity at unit distance: i_l = color / d² (the radiometric
    falloff of a point source, Hoffman & Baker 2006's i_l(d_l))."""
    l, d = _toward(P, position)
    return l, _rows(color, len(l)) / (d * d)[:, None]


def range_window(d, radius):
    """(saturate(1 − (d/r)⁴))²: Karis 2013, "Real Shading in Unreal Engine 4", eq. 9 (the window);
    Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", "Punctual lights" (smoothDistanceAtt). (glTF
    KHR_lights_punctual's recommended window is the same without the square.)"""
    return np.clip(1.0 - (d / radius) ** 4, 0.0, 1.0) ** 2


def point_range(P, position, color, radius):
    """color · (saturate(1 − (d/r)⁴))² / d²: Lagarde & de Rousiers 2014, "Punctual lights" (1/d² times the
    window of Karis 2013 eq. 9)."""
    l, d = _toward(P, position)
    return l, _rows(color, len(l)) * (range_window(d, radius) / (d * d))[:, None]


def spot_angle(cos_s, inner_angle, outer_angle):
    """Angular attenuation of Lagarde & de Rousiers 2014, "Punctual lights" (getAngleAtt), the reference code of
    KHR_lights_punctual ("Inner and Outer Cone Angles"):
    (saturate((cos θ_s − cos θ_o) / (cos θ_i − cos θ_o)))²."""
    ci, co = np.cos(inner_angle), np.cos(outer_angle)
    return np.clip((cos_s - co) / (ci - co), 0.0, 1.0) ** 2


def spot(P, position, direction, color, radius, inner_angle, outer_angle):
    """point_range times spot_angle(cos θ_s), θ_s between the axis and the ray from the light to P."""
    l, d = _toward(P, position)
    cos_s = -(l @ _unit(np.asarray(direction, np.float64)))
    falloff = range_window(d, radius) / (d * d) * spot_angle(cos_s, inner_angle, outer_angle)
    return l, _rows(color, len(l)) * falloff[:, None]


def clip_superellipse(Qx, Qy, a, b, A, B, roundness):
    """Barzel 1997, "Lighting Controls for Computer Cinematography", shaping; the `clipSuperellipse` of the
    uberlight shader (Apodaca & Gritz 2000, "Advanced RenderMan", ch. 14), rounded-corner and circle cases
    (roundness in (0, 1]): 0 inside the a × b superellipse, 1 outside the A × B one, smoothstep between,
    along the ray from the axis through Q."""
    x, y = np.abs(Qx), np.abs(Qy)
    out = np.zeros_like(x)
    nz = (x != 0.0) | (y != 0.0)
    x, y = x[nz], y[nz]
    if roundness > 0.9999:
        q = a * b / np.sqrt(b * b * x * x + a * a * y * y)
        r = A * B / np.sqrt(B * B * x * x + A * A * y * y)
    else:
        re = 2.0 / roundness
        with np.errstate(divide="ignore", over="ignore"):
            q = a * b * (((b * x) ** re + (a * y) ** re) ** (-1.0 / re))
            r = A * B * (((B * x) ** re + (A * y) ** re) ** (-1.0 / re))
    out[nz] = _smoothstep(q, r, 1.0)
    return out


def uberlight(P, position, direction, up, color, radius, width, height, width_edge, height_edge, roundness):
    """Barzel 1997 shaped light: point_range's falloff times (1 − clip_superellipse(x/z, y/z)) in the light's
    frame (z along `direction`, y along `up` made orthogonal, x = y × z); 0 behind the light (z ≤ 0)."""
    l, d = _toward(P, position)
    z_axis = _unit(np.asarray(direction, np.float64))
    x_axis = _unit(np.cross(np.asarray(up, np.float64), z_axis))
    y_axis = np.cross(z_axis, x_axis)
    s = np.asarray(P, np.float64) - _rows(position, len(l))  # light -> P
    x, y, z = s @ x_axis, s @ y_axis, s @ z_axis
    shape = np.zeros_like(z)
    front = z > 0.0
    shape[front] = 1.0 - clip_superellipse(x[front] / z[front], y[front] / z[front], width, height,
                                           width + width_edge, height + height_edge, roundness)
    c = _rows(color, len(l)) * (range_window(d, radius) / (d * d) * shape)[:, None]
    return l, c


LIGHTS = {"directional": directional, "point": point, "point_range": point_range, "spot": spot,
          "uberlight": uberlight}
