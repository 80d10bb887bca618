"""Meshes for the offscreen renderer, generated in NumPy: a UV sphere, a plane and a box.

A :class:`Mesh` holds separate float32 arrays, one per vertex attribute, named as the
vertex shaders' inputs (link/interface.VERTEX_INPUTS): ``a_position`` (vec3),
``a_normal`` (vec3, unit), ``a_tangent`` (vec4: xyz the unit tangent along +u, w the
bitangent sign) and ``a_uv`` (vec2), and uint32 ``indices`` (a triangle list).

Conventions (the fragment templates' own): the shaders rebuild the bitangent as
``B = cross(N, T.xyz) * T.w``; ``w`` is chosen so that B points along +v, the
direction of increasing texture coordinate v (Vulkan's: v = 0 is the image's first
row). Triangles are counter-clockwise seen from the side the normal points to
(right-handed world space): ``cross(p1 - p0, p2 - p0)`` points along the normal.
Pure functions of their arguments: the same call gives the same bytes.
"""
from __future__ import annotations

import numpy as np

from ..scene.mesh import ATTRIBUTES, Mesh  # noqa: F401  (the scene stage's mesh data; here re-exported)


def _mesh(p, n, t, uv, idx) -> Mesh:
    f = lambda x: np.ascontiguousarray(x, dtype=np.float32)  # noqa: E731
    return Mesh(f(p), f(n), f(t), f(uv), np.ascontiguousarray(idx, dtype=np.uint32).reshape(-1))


def uv_sphere(rings: int = 16, segments: int = 32, radius: float = 1.0) -> Mesh:
    """A sphere centred at the origin: `rings` bands from the north pole (+y) to the south pole, `segments` around.

    Vertex (i, j), i = 0 … rings, j = 0 … segments, sits at polar angle θ = π i / rings and azimuth
    φ = 2π j / segments: P = radius (sin θ sin φ, cos θ, sin θ cos φ) (φ = 0 faces +z), N = P / radius,
    uv = (j / segments, i / rings), T = ∂P/∂φ normalized = (cos φ, 0, −sin φ) (defined at the poles too),
    w = −1 (cross(N, T) points to the north pole, v grows to the south). The seam (j = 0 and
    j = segments) and the poles are duplicated vertices; triangles that would be degenerate at the
    poles are left out: 2 · segments · (rings − 1) triangles.
    """
    if rings < 2 or segments < 3:
        raise ValueError(f"a UV sphere needs rings ≥ 2 and segments ≥ 3, got {rings}, {segments}")
    i, j = np.meshgrid(np.arange(rings + 1), np.arange(segments + 1), indexing="ij")
    theta, phi = np.pi * i / rings, 2.0 * np.pi * j / segments
    st, ct, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
    # Exact poles (sin π is 1.2e-16, not 0): the pole vertices of every segment coincide.
    st[0, :] = st[-1, :] = 0.0
    ct[0, :], ct[-1, :] = 1.0, -1.0
    n = np.stack([st * sp, ct, st * cp], -1).reshape(-1, 3)
    t = np.stack([cp, np.zeros_like(cp), -sp, -np.ones_like(cp)], -1).reshape(-1, 4)
    uv = np.stack([j / segments, i / rings], -1).reshape(-1, 2)
    idx = []
    row = segments + 1
    for r in range(rings):
        for s in range(segments):
            a, b, c, d = r * row + s, (r + 1) * row + s, r * row + s + 1, (r + 1) * row + s + 1
            if r > 0:
                idx.append((a, b, c))
            if r < rings - 1:
                idx.append((c, b, d))
    return _mesh(radius * n, n, t, uv, np.array(idx))


def plane(size: float = 2.0, divisions: int = 1, height: float = 0.0) -> Mesh:
    """A square in the plane y = `height`, centred on the y axis, side `size`, facing +y.

    divisions × divisions quads. uv = (0, 0) at (−size/2, −size/2) in (x, z), u along +x and v along +z;
    T = (1, 0, 0), w = −1 (cross(N, T) = −z, v grows along +z); triangles counter-clockwise seen from +y.
    """
    if divisions < 1:
        raise ValueError(f"a plane needs divisions ≥ 1, got {divisions}")
    k = divisions
    zi, xi = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
    u, v = xi / k, zi / k
    m = (k + 1) ** 2
    p = np.stack([(u - 0.5) * size, np.full(u.shape, float(height)), (v - 0.5) * size], -1).reshape(-1, 3)
    nrm = np.tile([0.0, 1.0, 0.0], (m, 1))
    t = np.tile([1.0, 0.0, 0.0, -1.0], (m, 1))
    uv = np.stack([u, v], -1).reshape(-1, 2)
    idx = []
    row = k + 1
    for r in range(k):
        for s in range(k):
            a, b, c, d = r * row + s, (r + 1) * row + s, r * row + s + 1, (r + 1) * row + s + 1
            # a → b is +z, a → c is +x: (a, b, c) winds counter-clockwise seen from +y.
            idx += [(a, b, c), (c, b, d)]
    return _mesh(p, nrm, t, uv, np.array(idx))


# Faces of box(): (normal, u direction, v direction), seen from outside u runs to the right and v down
# (v = 0 is the top edge of the side faces, as an image's first row).
_BOX_FACES = (((1, 0, 0), (0, 0, -1), (0, -1, 0)), ((-1, 0, 0), (0, 0, 1), (0, -1, 0)),
              ((0, 1, 0), (1, 0, 0), (0, 0, 1)), ((0, -1, 0), (1, 0, 0), (0, 0, -1)),
              ((0, 0, 1), (1, 0, 0), (0, -1, 0)), ((0, 0, -1), (-1, 0, 0), (0, -1, 0)))


def box(size=2.0) -> Mesh:
    """An axis-aligned box centred at the origin, sides `size` (a number, or (x, y, z)); default 2: the box
    spans [−1, 1]³ like the unit sphere.

    Six faces of 4 vertices each (24 vertices, 12 triangles), flat normals. Per face, uv = (0, 0) … (1, 1);
    seen from outside, u runs to the right and v down (side faces: v = 0 at the top; the top face: v along
    +z; the bottom face: v along −z). T = the u direction, w = ±1 such that cross(N, T) · w is the
    v direction. Triangles counter-clockwise seen from outside.
    """
    half = np.broadcast_to(np.asarray(size, np.float64), (3,)) / 2.0
    if (half <= 0).any():
        raise ValueError(f"a box needs sides > 0, got {size}")
    p, nrm, tan, uv, idx = [], [], [], [], []
    for f, (n, t, b) in enumerate(_BOX_FACES):
        n, t, b = (np.asarray(x, np.float64) for x in (n, t, b))
        w = float(np.sign(np.cross(n, t) @ b))
        base = 4 * f
        for v in (0.0, 1.0):
            for u in (0.0, 1.0):
                p.append((n + (2 * u - 1) * t + (2 * v - 1) * b) * half)
                nrm.append(n)
                tan.append((*t, w))
                uv.append((u, v))
        a, c, d, e = base, base + 1, base + 2, base + 3  # (u, v) = (0, 0), (1, 0), (0, 1), (1, 1)
        # a → c is +t, a → d is +b: (a, c, d) winds counter-clockwise seen from n when cross(t, b) = n.
        if np.cross(t, b) @ n > 0:
            idx += [(a, c, d), (d, c, e)]
        else:
            idx += [(a, d, c), (c, d, e)]
    return _mesh(np.array(p), np.array(nrm), np.array(tan), np.array(uv), np.array(idx))
