"""Shaped spot light in the spirit of the "überlight": a superellipse cone with soft edges (Barzel 1997).

    c_light = color · (saturate(1 − (d/r)⁴))² / d² · (1 − clip(Q)),
    clip(Q) = smoothstep(q, r̂, 1),   Q = (x/z, y/z),
    q  = 1 / ((|Q_x|/a)^e + (|Q_y|/b)^e)^(1/e),   r̂ = the same with A = a + Δa, B = b + Δb,   e = 2 / roundness,

(x, y, z) the surface point in the light's frame: z along `direction`, y along `up`
(made orthogonal to it), x = y × z. Barzel 1997, "Lighting Controls for Computer
Cinematography" (JGT 2(1)), section "Shape": the light's cross-section is a
superellipse of half-width a and half-height b at unit distance (the tangents of the
cone's half-angles), with a soft edge out to A, B; roundness 1 is an ellipse (a round or
elliptic spot), roundness → 0 a rectangle (symmetric barn doors). The formula is the
`clipSuperellipse` of the uberlight shader (Apodaca & Gritz 2000, "Advanced RenderMan",
ch. 14, after Barzel); the notes (Hoffman & Baker 2006) name the überlight as the costly
end of i_l(d_l). Distance term as `point_range` (Karis 2013, eq. 9); points behind the
light (z ≤ 0) get nothing.

Written without the division by z and without 1/q: with the superellipse norm
ρ(x, y) = ((x/a)^e + (y/b)^e)^(1/e) (1-homogeneous) and ρ_i, ρ_o for the inner and outer
shape at (|x|, |y|), smoothstep's argument (1 − q)/(r̂ − q) is ρ_o (ρ_i − z) / (z (ρ_i − ρ_o)),
algebraically equal. ρ is evaluated as m · ((u/m)^e + (v/m)^e)^(1/e), m = max(u, v),
so pow never overflows (e reaches 100) and pow's base is in [0, 1].

Guards and their cost:
- d² ≥ 1e-4 as in `point` (a surface point on the light).
- m ≥ 1e-30 in ρ: on the axis (x = y = 0) ρ = 0 instead of 0/0; exact elsewhere.
- z (ρ_i − ρ_o) ≥ 1e-30: on the axis smoothstep's argument is 0 (full intensity) instead
  of 0/0; for z ≤ 0 the value is discarded by the z > 0 select. Exact elsewhere.
- |up × direction|² ≥ 1e-30: an `up` parallel to `direction` gives a zero frame, x = y = 0,
  so the light is unshaped (full intensity inside z > 0) instead of NaN.
- roundness ≥ 0.02 (its range): e ≤ 100. Barzel's square case (roundness 0: a product of
  two smoothsteps) is not reproduced; at roundness 0.02 the shape's radius differs from
  the max-norm rectangle's by at most 2^(1/100) − 1 = 0.7 % (at the corners).
Left out of Barzel's light: asymmetric barn doors (independent left/right/top/bottom
blockers), cut-on/cut-off distances, and a projected cookie texture (a texture per light
is not bound for storage-buffer lights, and the renderer binds only shadow maps to lights).
"""
BRICK = {
    "kind": "light",
    "fp16": "unsafe: its 1e-30 floors are 0 in float16, so on the light's axis the superellipse divides 0 by 0 (NaN), and (u/m)^e with e up to 100 underflows",
    "cite": "Barzel 1997 (uberlight shaping: superellipse with soft edges); Apodaca & Gritz 2000 ch. 14 clipSuperellipse",
    "params": {
        "position": {"type": "vec3", "range": [-1000000.0, 1000000.0], "default": [0.0, 2.0, 0.0], "doc": "world-space position"},
        "direction": {"type": "vec3", "range": [-1.0, 1.0], "default": [0.0, -1.0, 0.0], "doc": "the light's axis z: from the light into the scene"},
        "up": {"type": "vec3", "range": [-1.0, 1.0], "default": [0.0, 0.0, 1.0], "doc": "the light's y axis (made orthogonal to direction); not parallel to it"},
        "color": {"type": "vec3", "range": [0.0, 1000000.0], "default": [1.0, 1.0, 1.0], "doc": "linear RGB intensity at unit distance on the axis"},
        "radius": {"type": "float", "range": [0.001, 1000000.0], "default": 10.0, "doc": "range r: c_light is 0 from d = r on"},
        "width": {"type": "float", "range": [0.001, 1000.0], "default": 0.5, "doc": "a: half-width of the full-intensity shape at unit distance (tan of the half-angle)"},
        "height": {"type": "float", "range": [0.001, 1000.0], "default": 0.5, "doc": "b: half-height of the full-intensity shape at unit distance"},
        "width_edge": {"type": "float", "range": [0.001, 1000.0], "default": 0.1, "doc": "A - a: width of the soft edge in x"},
        "height_edge": {"type": "float", "range": [0.001, 1000.0], "default": 0.1, "doc": "B - b: width of the soft edge in y"},
        "roundness": {"type": "float", "range": [0.02, 1.0], "default": 1.0, "doc": "1: ellipse; toward 0: rectangle (barn doors)"},
    },
}


def light_dir(P: vec3, position: vec3) -> vec3:
    return normalize(position - P)


def superellipse(u: float, v: float, e: float) -> float:
    # ((u)^e + (v)^e)^(1/e) for u, v >= 0, scaled by m = max(u, v) so pow never overflows;
    # m floored at 1e-30: 0 on the axis instead of 0/0.
    m = max(max(u, v), 1e-30)
    return m * pow(pow(u / m, e) + pow(v / m, e), 1.0 / e)


def light_radiance(P: vec3, position: vec3, direction: vec3, up: vec3, color: vec3, radius: float, width: float,
                   height: float, width_edge: float, height_edge: float, roundness: float) -> vec3:
    d = position - P
    d2 = dot(d, d)
    q = d2 / (radius * radius)  # (d/r)^2
    w = saturate(1.0 - q * q)
    zl = normalize(direction)
    c = cross(up, zl)
    # |up x direction|^2 floored: an up parallel to the axis gives an unshaped light, not NaN.
    xl = c * rsqrt(max(dot(c, c), 1e-30))
    yl = cross(zl, xl)
    x = abs(dot(d, xl))
    y = abs(dot(d, yl))
    z = -dot(d, zl)
    e = 2.0 / roundness
    ri = superellipse(x / width, y / height, e)
    ro = superellipse(x / (width + width_edge), y / (height + height_edge), e)
    # smoothstep(q, r, 1) of Barzel's clipSuperellipse, with its argument (1 - q) / (r - q) written
    # without dividing by z or by rho: rho_o (rho_i - z) / (z (rho_i - rho_o)); floored denominator on the axis.
    t = saturate(ro * (ri - z) / max(z * (ri - ro), 1e-30))
    shape = 1.0 - t * t * (3.0 - 2.0 * t)
    s = shape if z > 0.0 else 0.0
    # d^2 floored at 1e-4 as in `point` (a surface point on the light).
    return color * (w * w * s / max(d2, 0.0001))
