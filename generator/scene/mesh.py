"""A mesh as scenes carry it (glTF import, scene/gltf.py) and the renderer draws it (runtime/meshes.py).

Separate float32 arrays, one per vertex attribute, named as the vertex shaders' inputs
(link/interface.VERTEX_INPUTS), and uint32 triangle-list indices; the conventions (tangent
w, winding) are runtime/meshes.py's.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ATTRIBUTES = ("a_position", "a_normal", "a_tangent", "a_uv")


@dataclass(frozen=True, eq=False)
class Mesh:
    """Separate attribute arrays (float32, one row per vertex) and uint32 triangle indices."""

    positions: np.ndarray  # (n, 3)
    normals: np.ndarray    # (n, 3)
    tangents: np.ndarray   # (n, 4), w = bitangent sign
    uvs: np.ndarray        # (n, 2)
    indices: np.ndarray    # (3 t,) uint32
    colors: np.ndarray | None = None  # (n, 4) COLOR_0 (RGBA); None: white, as a mesh without COLOR_0 reads it

    @property
    def vertex_count(self) -> int:
        return len(self.positions)

    @property
    def index_count(self) -> int:
        return len(self.indices)

    def attributes(self) -> dict[str, np.ndarray]:
        """The arrays by vertex-input name (a_position, a_normal, a_tangent, a_uv, a_color)."""
        colors = self.colors if self.colors is not None else np.ones((self.vertex_count, 4), np.float32)
        return {"a_position": self.positions, "a_normal": self.normals, "a_tangent": self.tangents, "a_uv": self.uvs,
                "a_color": colors}

    def interleaved(self, names=ATTRIBUTES) -> np.ndarray:
        """The chosen attributes interleaved per vertex, (n, floats per vertex) float32, in `names` order."""
        a = self.attributes()
        return np.ascontiguousarray(np.concatenate([a[n] for n in names], axis=1), dtype=np.float32)
