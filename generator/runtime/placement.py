"""Where the renderer puts a scene's objects: a placement file beside the scene, or a row of spheres.

`<scene>.placement.toml` (scenes/example.placement.toml is the example's courtyard): per object
mesh sphere|plane|box, translate, scale (half-extents), rotate_y in degrees, and a camera;
mistakes are `path:line:col: what — what to do`. Without a file, objects are unit spheres in a
row along x, SPACING apart, and camera() looks at them from above and in front.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

SPACING = 2.5  # the fallback row: object centres this far apart along x
MESHES = ("sphere", "plane", "box")  # every one spans [-1, 1] on its axes (the plane: y = 0)

def camera(n: int, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(eye, view_proj) looking at a row of n objects (the fallback placement; see the module docstring)."""
    from . import graphics as gx

    eye = np.array([0.0, 2.5, 3.0 + 1.6 * n])
    return eye, gx.perspective(40.0, width / height, 0.1, 100.0) @ gx.look_at(eye, (0.0, 0.0, 0.0))


def placement(i: int, n: int) -> np.ndarray:
    """The model matrix of object i of n in the fallback row: a unit sphere along x."""
    model = np.eye(4)
    model[0, 3] = (i - (n - 1) / 2.0) * SPACING
    return model


def make_mesh(kind, mirrored: bool = False):
    """The mesh a placement names: a unit UV sphere (24 × 48), a plane of side 2 in y = 0, or a box [−1, 1]³;
    a glTF primitive's mesh is itself. mirrored (Placed.mirrored): each triangle's winding reversed, so that
    under a model matrix of negative determinant its front face stays counter-clockwise (glTF 2.0: "the
    determinant of the node's global transform defines the winding order of that primitive")."""
    from .meshes import box, plane, uv_sphere

    if isinstance(kind, str):
        kind = {"sphere": lambda: uv_sphere(24, 48), "plane": lambda: plane(2.0), "box": lambda: box(2.0)}[kind]()
    if mirrored:
        kind = replace(kind, indices=np.ascontiguousarray(np.asarray(kind.indices).reshape(-1, 3)[:, ::-1].ravel()))
    return kind


@dataclass(frozen=True)
class Placed:
    """One object's placement: its mesh and model = translate · rotate_y · scale (scale: half-extents), or a
    glTF primitive: its own mesh (matrix.mesh.Mesh) and its node's world matrix."""

    name: str
    mesh: object = "sphere"  # a MESHES name, or a Mesh read from a glTF file
    translate: tuple = (0.0, 0.0, 0.0)
    scale: tuple = (1.0, 1.0, 1.0)
    rotate_y: float = 0.0  # degrees, counter-clockwise seen from +y
    matrix: tuple | None = None  # the model matrix given whole (16 numbers, row-major): a glTF node's world

    @property
    def model(self) -> np.ndarray:
        if self.matrix is not None:
            return np.array(self.matrix, np.float64).reshape(4, 4)
        c, s = np.cos(np.radians(self.rotate_y)), np.sin(np.radians(self.rotate_y))
        m = np.eye(4)
        m[:3, :3] = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) @ np.diag(self.scale)
        m[:3, 3] = self.translate
        return m

    @property
    def mirrored(self) -> bool:
        """The model matrix reverses orientation (negative determinant: a glTF node scaled by −1 on an axis)."""
        return bool(np.linalg.det(self.model[:3, :3]) < 0.0)

    def corners(self) -> np.ndarray:
        """The world positions of the corners of the mesh's bounds, (8, 3) (a plane's are 4, given twice)."""
        if not isinstance(self.mesh, str):  # a glTF primitive: the box of its positions
            p = np.asarray(self.mesh.positions, np.float64).reshape(-1, 3)
            lo, hi = (p.min(0), p.max(0)) if len(p) else (np.zeros(3), np.zeros(3))
            local = np.array([(x, y, z, 1.0) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
            return (self.model @ local.T).T[:, :3]
        y = (0.0,) if self.mesh == "plane" else (-1.0, 1.0)
        local = np.array([(x, yy, z, 1.0) for x in (-1.0, 1.0) for yy in y for z in (-1.0, 1.0)])
        local = np.concatenate([local] * (8 // len(local)))
        return (self.model @ local.T).T[:, :3]


@dataclass
class Placement:
    """Every object of a scene placed, in scene order, and the camera.

    `source`: the placement file, or None for the fallback row (whose camera is :func:`camera`). `eye` /
    `target` None: the camera frames the objects' bounds from above and in front."""

    objects: list[Placed]
    source: Path | None = None
    eye: tuple | None = None
    target: tuple | None = None
    fov_y: float = 40.0

    def model(self, i: int) -> np.ndarray:
        return self.objects[i].model

    def points(self) -> np.ndarray:
        """Corners of every object's bounds, (8 n, 3): what a light's shadow matrix must cover."""
        return np.concatenate([o.corners() for o in self.objects]) if self.objects else np.zeros((1, 3))

    def camera(self, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """(eye, view_proj) for a width × height image."""
        from . import graphics as gx

        if self.source is None:
            return camera(len(self.objects), width, height)
        pts = self.points()
        lo, hi = pts.min(0), pts.max(0)
        target = np.array(self.target if self.target is not None else 0.5 * (lo + hi), np.float64)
        if self.eye is not None:
            eye = np.array(self.eye, np.float64)
        else:
            r = 0.5 * float(np.linalg.norm(hi - lo)) + 1e-3
            half = np.radians(self.fov_y) / 2.0 * min(1.0, width / height)
            direction = np.array([0.0, 0.6, 1.0]) / np.linalg.norm([0.0, 0.6, 1.0])
            eye = target + direction * r / np.sin(half)
        far = max(100.0, 2.0 * float(np.linalg.norm(pts - eye, axis=1).max()))
        return eye, gx.perspective(self.fov_y, width / height, 0.1, far) @ gx.look_at(eye, target)


def row_placement(names) -> Placement:
    """The fallback: unit spheres in a row along x (:func:`placement`), the camera of :func:`camera`."""
    n = len(names)
    return Placement([Placed(name, "sphere", tuple(placement(i, n)[:3, 3])) for i, name in enumerate(names)])


def placement_path(scene_path) -> Path:
    """Where a scene's placement file lives: beside it, SCENE.placement.toml (scenes/example.placement.toml)."""
    p = Path(scene_path)
    return p.with_name(p.stem + ".placement.toml")


_OBJECT_KEYS = ("mesh", "translate", "scale", "rotate_y")
_CAMERA_KEYS = ("eye", "target", "fov_y")


def load_placement(scene, path=None) -> Placement:
    """The placement of `scene`'s objects: from `path` (default :func:`placement_path` of the scene), or the
    fallback row when that file does not exist (an explicit `path` must exist). A glTF scene without an
    explicit `path` draws its own meshes at their nodes' world matrices.

    Schema (TOML)::

        [objects.NAME]            # one table per object of the scene: every object, no others
        mesh = "box"              # "sphere" | "plane" | "box"; each spans [-1, 1] (a plane: in y = 0)
        translate = [x, y, z]     # default [0, 0, 0]
        scale = [sx, sy, sz]      # or one number; > 0; half-extents (default 1)
        rotate_y = 30.0           # degrees about +y, counter-clockwise seen from above (default 0)

        [camera]                  # optional
        eye = [x, y, z]           # default: framing the objects' bounds from above and in front
        target = [x, y, z]        # default: the centre of the bounds
        fov_y = 40.0              # vertical field of view in degrees (default 40)

    model = translate · rotate_y · scale. Every mistake is a SourceError ``path:line:col: what — what to do``.
    """
    from ..lang.errors import UserError
    from ..scene.load import read_toml

    names = [o["name"] for o in scene.objects]
    explicit = path is not None
    if not explicit and scene.objects and all(o.get("mesh") is not None and not isinstance(o.get("mesh"), str)
                                              and o.get("model") is not None for o in scene.objects):
        # a glTF scene: every object is a primitive with its mesh and its node's world matrix; the camera
        # frames their bounds
        return Placement([Placed(o["name"], o["mesh"], matrix=tuple(np.asarray(o["model"], np.float64).ravel()))
                          for o in scene.objects], source=Path(scene.path))
    path = Path(path) if explicit else placement_path(scene.path)
    if not path.exists():
        if explicit:
            raise UserError(f"{path}: no such placement file — give an existing file, or none for the row")
        return row_placement(names)
    data, loc = read_toml(path, "placement file", "fix the placement file's syntax")
    top = loc.top

    def unknown(what, key, known, where):
        close = difflib.get_close_matches(key, known, 1)
        hint = f"did you mean '{close[0]}'? " if close else ""
        return loc.error(where, f"unknown {what} '{key}'", f"{hint}known: {', '.join(known)}")

    for key in data:
        if key not in ("objects", "camera"):
            raise unknown("section", key, ["camera", "objects"], top(key))
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise loc.error((1, 1), f"the scene {scene.path} names more than one object '{dupes[0]}': a placement "
                                "cannot tell them apart", "give the scene's objects distinct names")
    objects = data.get("objects", {})
    if not isinstance(objects, dict):
        raise loc.error(top("objects"), "'objects' must be a table of tables", "write [objects.NAME] sections")

    def vec3(header, key, value, default):
        if value is None:
            return default
        ok = (isinstance(value, list) and len(value) == 3
              and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value))
        if not ok:
            raise loc.error(loc.find(header, key), f"{key} must be three numbers, got {value!r}",
                            f"write {key} = [x, y, z]")
        return tuple(float(x) for x in value)

    def number(header, key, value, default):
        if value is None:
            return default
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise loc.error(loc.find(header, key), f"{key} must be a number, got {value!r}", f"write {key} = 30.0")
        return float(value)

    placed = {}
    for name, t in objects.items():
        header = f"objects.{name}"
        if name not in names:
            close = difflib.get_close_matches(name, names, 1)
            raise loc.error(loc.find(header), f"the scene has no object '{name}'",
                            (f"did you mean '{close[0]}'? " if close else "") + f"objects: {', '.join(names)}")
        if not isinstance(t, dict):
            raise loc.error(top("objects"), f"objects.{name} must be a table", f"write [objects.{name}]")
        for key in t:
            if key not in _OBJECT_KEYS:
                raise unknown(f"key of objects.{name}", key, list(_OBJECT_KEYS), loc.find(header, key))
        mesh = t.get("mesh", "sphere")
        if mesh not in MESHES:
            raise loc.error(loc.find(header, "mesh"), f"unknown mesh {mesh!r}", f"use one of {', '.join(MESHES)}")
        scale = t.get("scale")
        if isinstance(scale, (int, float)) and not isinstance(scale, bool):
            scale = [scale] * 3
        scale = vec3(header, "scale", scale, (1.0, 1.0, 1.0))
        if not all(np.isfinite(scale)) or min(scale) <= 0:
            raise loc.error(loc.find(header, "scale"), f"scale must be > 0 on every axis, got {list(scale)}",
                            "give half-extents > 0 (a flat object: a plane, or a small scale)")
        translate = vec3(header, "translate", t.get("translate"), (0.0, 0.0, 0.0))
        if not all(np.isfinite(translate)):
            raise loc.error(loc.find(header, "translate"), f"translate {list(translate)} is not finite",
                            "give three finite numbers")
        placed[name] = Placed(name, mesh, translate, scale,
                              number(header, "rotate_y", t.get("rotate_y"), 0.0))
    missing = [n for n in names if n not in placed]
    if missing:
        raise loc.error((1, 1), f"object '{missing[0]}' of the scene has no placement",
                        f"add [objects.{missing[0]}] with mesh, translate, scale, rotate_y")
    cam = data.get("camera", {})
    if not isinstance(cam, dict):
        raise loc.error(top("camera"), "'camera' must be a table", "write [camera] with eye, target, fov_y")
    for key in cam:
        if key not in _CAMERA_KEYS:
            raise unknown("key of camera", key, list(_CAMERA_KEYS), loc.find("camera", key))
    fov = number("camera", "fov_y", cam.get("fov_y"), 40.0)
    if not 0.0 < fov < 180.0:
        raise loc.error(loc.find("camera", "fov_y"), f"fov_y {fov} is not between 0 and 180 degrees",
                        "write e.g. fov_y = 40.0")
    eye, target = vec3("camera", "eye", cam.get("eye"), None), vec3("camera", "target", cam.get("target"), None)
    for key, v in (("eye", eye), ("target", target)):
        if v is not None and not all(np.isfinite(v)):
            raise loc.error(loc.find("camera", key), f"{key} {list(v)} is not finite", "give three finite numbers")
    if eye is not None and target is not None and np.allclose(eye, target):
        raise loc.error(loc.find("camera", "eye"), "the camera's eye and target coincide", "move the eye away")
    return Placement([placed[n] for n in names], path, eye, target, fov)
