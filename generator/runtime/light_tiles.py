"""The LightTiles buffer of a tiled dynamic light set (culling = "tiles"), filled as an engine's light culling
would: each light's bounds against each screen tile, on the CPU. The layout is link/tiles.py's.

The culling is conservative, so a tiled set draws what the untiled one draws: a light whose brick has a range
(`position` and `radius`: point_range, spot) is in the tiles its bounding cube's eight projected corners cover
(the sphere of radius `radius` lies inside the cube, and a point inside a convex hull in front of the camera
projects inside the hull's projection); a corner at or behind the camera plane, or a light without a range
(point, directional, uberlight), puts it in every tile. The light's radiance is exactly 0 from d = radius on
(bricks/light/point_range.py), so a tile it misses loses nothing.
"""
from __future__ import annotations

import numpy as np

from ..link.tiles import HEADER_WORDS, RECORD_WORDS

TILE = 16  # pixels: the renderer's tile size (the buffer's header says it; the shader reads it from there)
NEAR_W = 1e-6  # a projected corner with clip w at or below this is at or behind the camera plane


def light_range(lib, light) -> tuple[np.ndarray, float] | None:
    """(world position, radius) of a light whose brick has a range, else None (it reaches everywhere)."""
    brick = lib.get("light", light.type)
    params = brick.params if brick is not None else {}
    if "position" not in params or "radius" not in params:
        return None
    pos = light.params.get("position", params["position"].default)
    return np.asarray(pos, np.float64), float(light.params.get("radius", params["radius"].default))


def covered(vp, bounds, size: tuple[int, int], tile: int) -> tuple[int, int, int, int] | None:
    """The tiles (x0, y0, x1, y1, inclusive) a light's bounds cover in a size = (W, H) image; None for every tile;
    an empty range (x1 < x0) when the bounds are off screen."""
    (w, h), nx, ny = size, -(-size[0] // tile), -(-size[1] // tile)
    if bounds is None:
        return None
    centre, r = bounds
    corners = centre + r * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float64)
    clip = np.asarray(vp, np.float64) @ np.c_[corners, np.ones(8)].T
    if (clip[3] <= NEAR_W).any():
        return None
    px = (clip[0] / clip[3] + 1.0) * 0.5 * w  # Vulkan's viewport: x right, y down (camera.perspective)
    py = (clip[1] / clip[3] + 1.0) * 0.5 * h
    x0, x1 = max(int(np.floor(px.min() / tile)), 0), min(int(np.floor(px.max() / tile)), nx - 1)
    y0, y1 = max(int(np.floor(py.min() / tile)), 0), min(int(np.floor(py.max() / tile)), ny - 1)
    return x0, y0, x1, y1


def cull(lib, scene, lights: list[str], dyn, vp, size, tile: int = TILE) -> list[list[list[int]]]:
    """Per tile (x + y · tiles_x), per pair of the set's model: the elements of the pair's buffer lit there (a
    pair's element k is its k-th light in `lights`' order, as link/values.py light_buffers lays them)."""
    nx, ny = -(-size[0] // tile), -(-size[1] // tile)
    lists = [[[] for _ in dyn.model] for _ in range(nx * ny)]
    seen = [0] * len(dyn.model)
    for ln in lights:
        light = scene.lights[ln]
        p = dyn.pair_of(light)
        k, seen[p] = seen[p], seen[p] + 1
        rect = covered(vp, light_range(lib, light), size, tile)
        x0, y0, x1, y1 = rect if rect is not None else (0, 0, nx - 1, ny - 1)
        for y in range(y0, y1 + 1):
            for x in range(x0, x1 + 1):
                lists[x + y * nx][p].append(k)
    return lists


def tile_words(lists: list[list[list[int]]], size: tuple[int, int], tile: int = TILE) -> np.ndarray:
    """The LightTiles buffer (uint32 words) of `lists` (cull's): header, per-(tile, pair) records, index lists."""
    nx, ny = -(-size[0] // tile), -(-size[1] // tile)
    pairs = len(lists[0]) if lists else 0
    at = HEADER_WORDS + RECORD_WORDS * pairs * nx * ny
    words = [nx, ny, tile, pairs]
    flat = []
    for per_pair in lists:
        for ks in per_pair:
            words += [at + len(flat), len(ks)]
            flat += ks
    words += flat
    words += [0] * (-len(words) % 4)  # whole uvec4 elements
    return np.asarray(words, np.uint32)


__all__ = ["TILE", "covered", "cull", "light_range", "tile_words"]
