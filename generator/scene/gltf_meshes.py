"""A glTF mesh primitive → the mesh its object draws (scene/mesh.py: positions, normals, tangents, uvs, indices).

The attributes read are POSITION, NORMAL, TANGENT, TEXCOORD_0 and COLOR_0 (VEC3 or VEC4; RGB gets
alpha 1), every one with one element per vertex; the indices (unsigned bytes, shorts or ints, or none:
0 … n−1) become uint32 triangle-list indices, TRIANGLES as they are and strips and fans unrolled (MODES:
points and lines are skipped by the import, with a note). A primitive without NORMAL gets flat normals
(its triangles unwelded), as glTF requires; one without TEXCOORD_0 gets zero UVs, unless its material
samples a texture (then an error).
Tangents. A primitive whose material has a normal map and whose mesh has no TANGENT gets per-vertex
tangents generated on import from the UV gradients (Lengyel 2001: per-triangle ∂P/∂u, ∂P/∂v summed
per vertex, Gram-Schmidt against N, w = handedness) — NOT MikkTSpace-exact (MikkTSpace splits vertices
at tangent-space seams and weights by angle). The shader is the same with file or generated tangents,
so the key is too; the object records `tangents` = "file" | "generated".
"""
from __future__ import annotations

import numpy as np

from .gltf_materials import GltfMaterial, textures_need_uv
from .gltf_read import Reader
from .jsonpos import pointer

MODES = {0: "POINTS", 1: "LINES", 2: "LINE_LOOP", 3: "LINE_STRIP", 4: "TRIANGLES", 5: "TRIANGLE_STRIP",
         6: "TRIANGLE_FAN"}


def primitive_mesh(rd: Reader, prim: dict, pptr: str, mode: int, m: GltfMaterial):
    """(runtime Mesh, tangents "file" | "generated", has COLOR_0) of one primitive."""
    from .mesh import Mesh

    aptr = f"{pptr}/attributes"
    attrs = rd.get(prim, "attributes", pptr, "obj")
    for k, v in attrs.items():
        rd.ref(attrs, k, pptr + "/attributes", "accessors")
    if "POSITION" not in attrs:
        raise rd.err(f"{aptr}/POSITION", "'POSITION' is required here", "export the mesh with positions")
    pos = rd.accessor(attrs["POSITION"], f"{aptr}/POSITION", ("VEC3",), float_only=True)
    n = len(pos)

    def attr(key, types):
        if key not in attrs:
            return None
        a = rd.accessor(attrs[key], f"{aptr}/{key}", types, float_only=True)
        if len(a) != n:
            raise rd.err(f"{aptr}/{key}", f"{len(a)} elements, but POSITION has {n}",
                         "give every attribute one per vertex")
        return a

    nrm, tan, uv = attr("NORMAL", ("VEC3",)), attr("TANGENT", ("VEC4",)), attr("TEXCOORD_0", ("VEC2",))
    colors = attr("COLOR_0", ("VEC3", "VEC4"))
    if colors is not None and colors.shape[1] == 3:  # RGB: alpha 1 (glTF 3.7.2.1)
        colors = np.concatenate([colors, np.ones((len(colors), 1), np.float32)], axis=1)
    idx = _triangles(rd, prim, pptr, mode, n)
    if textures_need_uv(m) and uv is None:
        raise rd.err(f"{aptr}", f"material '{m.name}' samples textures but the primitive has no TEXCOORD_0",
                     "export the mesh with texture coordinates")
    if nrm is None:  # flat normals: unweld the triangles (glTF 2.0 §3.7.2.1)
        pos, idx_old = pos[idx], idx
        uv = uv[idx_old] if uv is not None else None
        colors = colors[idx_old] if colors is not None else None
        tan = None
        idx = np.arange(len(pos), dtype=np.int64)
        tri = pos.reshape(-1, 3, 3).astype(np.float64)
        fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-30)
        nrm = np.repeat(fn, 3, axis=0).astype(np.float32)
    if uv is None:
        uv = np.zeros((len(pos), 2), np.float32)
    source = "file"
    if tan is None:
        tan = generate_tangents(pos, nrm, uv, idx) if idx.size else np.zeros((len(pos), 4), np.float32)
        source = "generated" if "normal_map" in m.textures else "none"
    f = lambda x: np.ascontiguousarray(x, dtype=np.float32)  # noqa: E731
    mesh = Mesh(f(pos), f(nrm), f(tan), f(uv), np.ascontiguousarray(idx, dtype=np.uint32),
                f(colors) if colors is not None else None)
    return mesh, source, colors is not None


def _triangles(rd: Reader, prim: dict, pptr: str, mode: int, n: int) -> np.ndarray:
    """The primitive's triangle-list indices (int64) into its n vertices: strips and fans unrolled."""
    if "indices" in prim:
        ii = rd.ref(prim, "indices", pptr, "accessors")
        a = rd.array("accessors")[ii]
        if a.get("componentType") not in (5121, 5123, 5125):
            raise rd.err(pointer("accessors", ii, "componentType"), "indices must be unsigned bytes, shorts or ints",
                         "use componentType 5121, 5123 or 5125")
        idx = rd.accessor(ii, f"{pptr}/indices", ("SCALAR",)).reshape(-1).astype(np.int64)
        if idx.size and int(idx.max()) >= n:
            raise rd.err(f"{pptr}/indices", f"index {int(idx.max())} is past the {n} vertices", "fix the index buffer")
    else:
        idx = np.arange(n, dtype=np.int64)
    if mode in (5, 6):  # glTF 2.0 §3.7.2.1: strip triangle i = (v_i, v_i+1+i%2, v_i+2-i%2); fan: (v_i+1, v_i+2, v_0)
        k = np.arange(max(len(idx) - 2, 0))
        if mode == 5:
            odd = k % 2
            idx = np.stack([idx[k], idx[k + 1 + odd], idx[k + 2 - odd]], axis=1).reshape(-1)
        else:
            idx = np.stack([idx[k + 1], idx[k + 2], np.full_like(k, idx[0])], axis=1).reshape(-1)
    if idx.size % 3:
        raise rd.err(f"{pptr}/indices", f"{idx.size} indices do not form whole triangles",
                     "give 3 indices per triangle")
    return idx


def generate_tangents(p: np.ndarray, n: np.ndarray, uv: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Per-vertex tangents (n, 4) from UV gradients (Lengyel 2001), w = handedness so that B = cross(N, T) w
    points along +v (runtime/meshes.py). Not MikkTSpace-exact. Degenerate UVs fall back to any unit T ⊥ N."""
    tri = idx.reshape(-1, 3).astype(np.int64)
    p, n, uv = p.astype(np.float64), n.astype(np.float64), uv.astype(np.float64)
    e1, e2 = p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]
    d1, d2 = uv[tri[:, 1]] - uv[tri[:, 0]], uv[tri[:, 2]] - uv[tri[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    r = np.where(np.abs(det) > 1e-20, 1.0 / np.where(det == 0, 1.0, det), 0.0)[:, None]
    sdir = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r
    tdir = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r
    ts, bs = np.zeros_like(p), np.zeros_like(p)
    for k in range(3):
        np.add.at(ts, tri[:, k], sdir)
        np.add.at(bs, tri[:, k], tdir)
    t = ts - n * np.sum(n * ts, axis=1, keepdims=True)
    length = np.linalg.norm(t, axis=1, keepdims=True)
    # fallback: any unit vector perpendicular to N
    helper = np.where(np.abs(n[:, 0:1]) < 0.9, np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
    alt = np.cross(helper, n)
    alt /= np.maximum(np.linalg.norm(alt, axis=1, keepdims=True), 1e-30)
    t = np.where(length > 1e-12, t / np.maximum(length, 1e-30), alt)
    w = np.where(np.sum(np.cross(n, t) * bs, axis=1) < 0.0, -1.0, 1.0)
    return np.concatenate([t, w[:, None]], axis=1).astype(np.float32)
