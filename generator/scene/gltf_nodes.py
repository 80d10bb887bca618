"""A glTF scene's node trees → its node instances and their world matrices.

Each root of the scene, then each node's children, depth first with parents before children, walked
without recursion (a deep hierarchy is no stack overflow); a node reached twice in one scene is an error
(the nodes must form trees). A node's local matrix is its `matrix` (column-major) or its translation ·
rotation (a unit quaternion, normalized on reading) · scale, never both; the world matrix is the parent's
world matrix times it.
"""
from __future__ import annotations

import json
import math

import numpy as np

from .gltf_read import Reader
from .jsonpos import pointer


def instances(rd: Reader, si: int, s: dict) -> list[tuple[int, np.ndarray]]:
    """(node index, world matrix) of every node that glTF scene si (`s`) instances, depth first."""
    sptr = pointer("scenes", si)
    nodes = rd.array("nodes")
    roots = rd.get(s, "nodes", sptr, "arr", [])
    out = []
    seen_here: set[int] = set()
    stack = [(_elem_ref(rd, roots, j, f"{sptr}/nodes", "nodes"), np.eye(4), f"{sptr}/nodes/{j}")
             for j in reversed(range(len(roots)))]
    while stack:
        ni, parent, ptr = stack.pop()
        if ni in seen_here:
            raise rd.err(ptr, f"node {ni} is reached twice (the nodes must form trees)",
                         "give each node one parent")
        seen_here.add(ni)
        node = nodes[ni]
        world = parent @ _local_matrix(rd, node, pointer("nodes", ni))
        out.append((ni, world))
        children = rd.get(node, "children", pointer("nodes", ni), "arr", [])
        stack += [(_child(rd, node, ni, j), world, pointer("nodes", ni, "children", j))
                  for j in reversed(range(len(children)))]
    return out


def _child(rd: Reader, node: dict, ni: int, j: int) -> int:
    return _elem_ref(rd, node["children"], j, pointer("nodes", ni, "children"), "nodes")


def _elem_ref(rd: Reader, arr: list, j: int, ptr: str, target: str) -> int:
    v = arr[j]
    n = len(rd.array(target))
    if not isinstance(v, int) or isinstance(v, bool) or not 0 <= v < n:
        raise rd.err(f"{ptr}/{j}", f"{json.dumps(v)[:30]} is not an index of {target} (the file has {n})",
                     f"use an index from 0 to {n - 1}" if n else f"add the {target} it refers to")
    return v


def _local_matrix(rd: Reader, node: dict, ptr: str) -> np.ndarray:
    if "matrix" in node:
        for k in ("translation", "rotation", "scale"):
            if k in node:
                raise rd.err(f"{ptr}/{k}", "a node has either matrix or translation/rotation/scale, not both",
                             "keep one")
        return np.array(rd.nums(node, "matrix", ptr, 16), dtype=np.float64).reshape(4, 4).T  # column-major
    t = rd.nums(node, "translation", ptr, 3, [0.0, 0.0, 0.0])
    r = rd.nums(node, "rotation", ptr, 4, [0.0, 0.0, 0.0, 1.0])
    s = rd.nums(node, "scale", ptr, 3, [1.0, 1.0, 1.0])
    m = np.eye(4)
    m[:3, :3] = _quat_matrix(r) @ np.diag(s)
    m[:3, 3] = t
    return m


def _quat_matrix(q) -> np.ndarray:
    x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
