"""Cameras and lights in Vulkan's clip space (y down, depth 0 … 1), and the per-frame / per-draw block bytes.

perspective, look_at, orthographic; a directional or point light's shadow matrix fitted to points;
frame_bytes (link/interface.FRAME_BLOCK) and object_bytes (OBJECT_BLOCK: the model matrix and its
inverse transpose), written column-major as every target reads a mat4.
"""
from __future__ import annotations

import numpy as np


def perspective(fovy_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """A right-handed perspective projection (camera looks down −z) into Vulkan's clip space: x right,
    y down (world up is image up), depth 0 at `near` … 1 at `far`. Row-major math matrix (M @ v), float64."""
    f = 1.0 / np.tan(np.radians(fovy_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = -f  # Vulkan's y points down
    m[2, 2] = far / (near - far)
    m[2, 3] = near * far / (near - far)
    m[3, 2] = -1.0
    return m


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """The view matrix of a camera at `eye` looking at `target` (right-handed, −z forward), row-major, float64."""
    eye, target, up = (np.asarray(x, np.float64) for x in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    if np.linalg.norm(s) < 1e-6:  # looking along `up`: any perpendicular up vector will do
        s = np.cross(f, (1.0, 0.0, 0.0) if abs(f[0]) < 0.9 else (0.0, 0.0, 1.0))
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def orthographic(left: float, right: float, bottom: float, top: float, near: float, far: float) -> np.ndarray:
    """An orthographic projection of view space (looking down −z) into Vulkan's clip space: x in [left, right]
    → [−1, 1], y in [bottom, top] → [−1, 1] (not flipped), depth: z = −near → 0, z = −far → 1. Row-major,
    float64; w stays 1."""
    m = np.eye(4)
    m[0, 0], m[0, 3] = 2.0 / (right - left), -(right + left) / (right - left)
    m[1, 1], m[1, 3] = 2.0 / (top - bottom), -(top + bottom) / (top - bottom)
    m[2, 2], m[2, 3] = -1.0 / (far - near), -near / (far - near)
    return m


def _light_up(d) -> np.ndarray:
    """An up vector for a light's view that is not parallel to its direction d."""
    return np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.99 * np.linalg.norm(d) else np.array([0.0, 0.0, 1.0])


def directional_shadow_matrix(direction, points, margin: float = 0.02) -> np.ndarray:
    """World → light clip space for a directional light: an orthographic projection along the light.

    `direction` points from the surface toward the light (the directional brick's parameter); `points`
    ((n, 3) world positions, e.g. the corners of every object's bounds) are all mapped inside clip space:
    x, y in [−1, 1] (padded by `margin` of their extent on each side), depth in [0, 1], 0 nearest the light.
    The shadow brick reads uv = p.xy · 0.5 + 0.5, the texel the depth pass rasterized p to. Row-major, float64
    (:func:`column_major` gives the mat4 parameter's 16 numbers)."""
    d = np.asarray(direction, np.float64).reshape(3)
    if not np.linalg.norm(d) > 0:
        raise ValueError(f"a directional light needs a non-zero direction, got {list(d)}")
    d = d / np.linalg.norm(d)
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    centre = 0.5 * (pts.min(0) + pts.max(0))
    view = look_at(centre + d, centre, _light_up(d))  # looks along −d: the way the light travels
    q = (view[:3, :3] @ pts.T).T + view[:3, 3]
    lo, hi = q.min(0), q.max(0)
    pad = margin * (hi - lo) + 1e-4
    lo, hi = lo - pad, hi + pad
    # view z is negative in front: near = −max z, far = −min z
    return orthographic(lo[0], hi[0], lo[1], hi[1], -hi[2], -lo[2]) @ view


def point_shadow_matrix(position, points, max_half_angle_deg: float = 75.0) -> np.ndarray:
    """World → light clip space for a point light: a perspective projection from `position` toward the centre of
    `points`, its field of view and depth range fitted to them (one map, not a cube: a light among the
    points sees at most ±`max_half_angle_deg`; what lies outside is not shadowed correctly). Row-major."""
    eye = np.asarray(position, np.float64).reshape(3)
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    centre = 0.5 * (pts.min(0) + pts.max(0))
    d = centre - eye
    if not np.linalg.norm(d) > 1e-9:
        d = np.array([0.0, -1.0, 0.0])
    view = look_at(eye, eye + d, _light_up(d))
    q = (view[:3, :3] @ pts.T).T + view[:3, 3]
    depth = -q[:, 2]
    far = max(float(depth.max()), 1e-3) * 1.02 + 1e-3
    near = max(float(depth.min()) * 0.98, far * 1e-3)
    ahead = depth > near
    limit = np.tan(np.radians(max_half_angle_deg))
    tx = min(float(np.max(np.abs(q[ahead, 0]) / depth[ahead], initial=0.1)) * 1.02, limit)
    ty = min(float(np.max(np.abs(q[ahead, 1]) / depth[ahead], initial=0.1)) * 1.02, limit)
    return perspective(2.0 * np.degrees(np.arctan(ty)), tx / ty, near, far) @ view


def column_major(m) -> list[float]:
    """A 4×4 math matrix as the 16 numbers of a mat4 parameter (column-major, as every block reads it)."""
    return [float(x) for x in _columns(m)]


def _columns(m) -> np.ndarray:
    """A 4×4 math matrix as std140 reads a mat4: column-major (every target reads the same bytes)."""
    return np.asarray(m, np.float64).reshape(4, 4).T.reshape(-1)


def frame_bytes(view_proj, camera_pos) -> bytes:
    """The Frame block (link/interface.FRAME_BLOCK: view_proj mat4, camera_pos vec4; 80 bytes)."""
    cam = np.zeros(4)
    c = np.asarray(camera_pos, np.float64).reshape(-1)
    cam[:len(c)] = c
    if len(c) < 4:
        cam[3] = 1.0
    return np.concatenate([_columns(view_proj), cam]).astype("<f4").tobytes()


def object_bytes(model) -> bytes:
    """The per-draw Object block (link/interface.OBJECT_BLOCK: model, and its inverse transpose for normals)."""
    m = np.asarray(model, np.float64).reshape(4, 4)
    n = np.eye(4)
    n[:3, :3] = np.linalg.inv(m[:3, :3]).T
    return np.concatenate([_columns(m), _columns(n)]).astype("<f4").tobytes()
