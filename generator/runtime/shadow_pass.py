"""The depth pass contract: what a shadowed light's depth pass is, stated once for the build and the renderer.

A light is shadowed when an object of the scene uses it and its shadow filter samples a texture
(bricks/shadow: shadow_map and pcf read `shadow_map`, pcf_hardware `shadow_depth` through a comparison
sampler, vsm `shadow_moments`). For each, :func:`depth_pass` gives the description the build writes into
the manifest (``lights.<name>.depth_pass``) and the renderer draws by (runtime/depth_passes.py reads the
same fields): the map's format, size, clear value and rasterizer depth bias, the bias the shadow brick
applies in the shader, the light matrix's convention and how it is fitted to the scene
(:func:`fit_shadow_matrix`), the shaders that draw each caster (compose/depth.py, named by unit), and
where the result binds in each permutation that reads it.

The matrix: `shadow_matrix` (the light's mat4 parameter, column-major in the Lights block; the build's
ready-to-upload blocks hold the brick's identity default, which the engine overwrites) maps world space to
the light's clip space in Vulkan's convention (x, y in [-1, 1], z / w in [0, 1], 0 nearest the light). The
brick reads the map at uv = clip.xy / clip.w · 0.5 + 0.5 and compares depth clip.z / clip.w. The depth
pass must write the texel the brick reads, so on each platform its Frame.view_proj is shadow_matrix
premultiplied by :func:`platform_premultiply` of the platform's conventions (assemble/platform_base.py):
a y flip where NDC +y is up and the framebuffer's row 0 is the top (D3D12, WebGPU: the map's first row
is then clip y = -1, as in Vulkan), and z' = 2z - w where the depth range is -1..1 (OpenGL without
glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), which makes it the identity instead). The colour pass keeps
shadow_matrix itself. A y flip reverses the triangles' winding; the depth pass culls nothing.

The casters: a shadowed light casts only onto and from the objects of its light sets, as the scene says: its
depth pass draws the objects whose light set holds it (:func:`casters`), and its fit covers only their bounds
(the manifest's ``matrix.fit.casters`` = "light_sets"; the frame export lists them per light). An object outside
those sets neither receives the light (its permutation has no slot for it) nor casts its shadow.

The fit (:func:`fit_shadow_matrix`, the method the renderer uses; an engine that fits to its own bounds
the same way gets the same matrix), per light brick:

- directional: an orthographic projection along its direction around the centre of the bounds, x and y padded
  by FIT_MARGIN of their extent, depth spanning them;
- point, point_range: six faces (:func:`cube_face_matrices`), one 90° perspective projection from its position per
  cube face in Vulkan's order (+X, -X, +Y, -Y, +Z, -Z), each face's axes those of Vulkan's cube-map face (so the six
  layers, bound as a cube view, are the cube an engine would sample by direction), all with one near and far: far =
  the farthest bounds corner's distance × 1.02 + 1e-3, near = max(the distance to the nearest caster's world box
  (the axis-aligned box of its corners; 0 inside it) × 0.98, far × 1e-3). The map is a texture2d_array of six
  layers, not a cube texture: the shadow bricks stay as they are (they project P with a matrix and compare
  depth), and 2D arrays exist in every target, GLSL ES 3.00/3.10 included, where cube arrays do not. The
  linker (link/faces.py) gives such a light six matrices (`shadow_matrix` is face 0's, `shadow_matrix_1` …
  `shadow_matrix_5` the others') and picks the face from the direction light → P (its major axis; ties to z,
  then y), calling the filter with that face's matrix and the face as the layer. The depth pass draws the
  casters once per face, each face into its layer (vsm: each layer's moments blurred alone);
- spot: a perspective projection from its position along its `direction`, square, its half-angle the cone's
  (`outer_angle`: outside it the brick gives no light, so nothing there needs a shadow), the tangent widened by
  FIT_PADDING so that the edge texels and pcf's taps around the cone's rim stay inside the map, at most
  ±FIT_MAX_HALF_ANGLE;
- uberlight: a perspective projection from its position along `direction`, its y axis the brick's `up` made
  orthogonal to it; its half-width and half-height tangents those of the soft edge's outer superellipse
  (width + width_edge, height + height_edge: the brick's light is 0 outside the rectangle that bounds it),
  each widened by FIT_PADDING and at most tan(FIT_MAX_HALF_ANGLE); an `up` parallel to the axis (the brick's
  unshaped light) takes the widest.

Lights in a buffer (a dynamic set's shadowed pair) are fitted and drawn as the static ones, each its own map or
six faces; their pair reads one 2D array of them, light k's layers from k × its layers (its element's
`shadow_first_layer`, link/values.py), the manifest's binds saying where (:func:`bindings`: `array`, with the
array's capacity, max × layers, and its bytes).

Near and far of every perspective fit: from the bounds' depths along the view axis, far = the farthest × 1.02 +
1e-3, near = max(the nearest × 0.98, far × 1e-3). The bounds are the world-space corners of every caster's
axis-aligned bounding box in its own space, transformed by its model matrix (runtime/placement.py,
Placement.points); `render` records the matrices it used in its report.

The limit: a perspective map covers less than a half-space. Where a caster's bounds reach outside the map while
the light may shine there (casters beyond ±FIT_MAX_HALF_ANGLE of a spot's or uberlight's axis when its cone is
wider), those parts are not shadowed correctly: :func:`uncovered` finds them, and `render` warns at the light's
scene line (a warning, not a refusal: the map is right wherever it reaches). A point light's six faces cover every
direction, so it has no such warning. What `render` cannot draw at all (a light type with no projection,
an axis of no length) is a :class:`ShadowProblem`, located at the light's scene line by :func:`light_where`.
"""
from __future__ import annotations

import numpy as np

from ..link.faces import CUBE_TYPES, FACE_MATRICES, FACE_NAMES, FACES

SHADOW_SIZE = 512  # the side of a light's map, in texels (render --shadow-size changes the renderer's)
DEPTH_FORMAT = "D32_SFLOAT"
DEPTH_CLEAR = 1.0  # the far plane: lit wherever no caster was drawn
MOMENTS_FORMAT = "R32G32B32A32_SFLOAT"  # (E[d], E[d²], 0, 1): 16-bit moments would lose E[d²] - E[d]²
MOMENTS_CLEAR = [1.0, 1.0, 0.0, 1.0]  # the moments of the depth clear
MOMENTS = "shadow_moments"  # the shadow brick texture that reads the (blurred) moments (vsm)
PCF_TEXEL = "pcf_texel"  # a shadow parameter the renderer writes as 1 / size when the scene leaves it unset
MOMENTS_BOX = 5  # the moments' prefilter: a box of this many texels a side
FIT_MARGIN = 0.02
FIT_MAX_HALF_ANGLE = 75.0  # the widest half-angle of a perspective map, in degrees: tan 75° = 3.7, so the map's
# texels at the edge are 14 times the centre's (1 / cos² 75°) — wider would waste the map on its rim
FIT_PADDING = 0.02  # the fraction a spot's or uberlight's cone tangents are widened by (5 texels of a 512 map)
PERSPECTIVE = ("point", "point_range", "spot", "uberlight")
IDENTITY = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
# (depth_range, ndc_y, framebuffer_origin) of the platform the renderer draws (assemble/platforms.py, Vulkan)
VULKAN_CONVENTIONS = ("0..1", "down", "top-left")


def shadow_textures(resolved) -> dict[str, dict[str, bool]]:
    """{shadow filter spec: {texture it samples: read through a comparison sampler}} of resolved permutations
    (spec.resolve values; {} for "none"): what the spec stage found, not the spec parsed again."""
    out = {}
    for r in resolved:
        for lk, lt in zip(r.perm.lights, r.lights):
            entry = lt.shadow.brick.entries[0]
            compare = {p.name: bool(p.ty.compare) for p in entry.params if p.ty.kind == "texture"}
            out[lk.shadow] = {t: compare.get(t, False) for t in lt.textures}
    return out


def shadowed_lights(scene, resolved) -> dict[str, dict[str, bool]]:
    """{light name: the textures its filter samples} of every light an object uses whose filter samples one, in
    the scene's order of lights; `resolved`: the scene's permutations resolved (every used filter is there)."""
    sampled = shadow_textures(resolved)
    used = {ln for o in scene.objects for ln in o["lights"]}
    return {ln: sampled[L.shadow] for ln, L in scene.lights.items() if ln in used and sampled.get(L.shadow)}


def depth_plan(shadowed: dict[str, dict[str, bool]], linked: dict):
    """The depth units (compose/depth.py DepthPlan) the shadowed lights ({name: textures}, shadowed_lights) need:
    depth-only casters for a light that samples depth, the moments stage and blur for one that samples
    moments, and every masked permutation of `linked` (hash -> LinkedPermutation) as a caster of its own."""
    from ..compose.depth import DepthPlan

    if not shadowed:
        return DepthPlan()
    return DepthPlan(depth=any(MOMENTS not in t for t in shadowed.values()),
                     moments=any(MOMENTS in t for t in shadowed.values()),
                     masked={h: lp for h, lp in sorted(linked.items()) if lp.perm.surface.alpha == "mask"})


def pass_units(plan, moments: bool) -> dict:
    """The units a light's pass draws with (depth_pass's `units`): the shared caster and blur units, and each masked
    permutation's mask unit (with the moments output for a VSM light)."""
    from ..link.depth import BLUR, DEPTH, mask_unit

    return {"depth": DEPTH, "blur": BLUR if moments else None,
            "masked": {h: mask_unit(h, moments) for h in plan.masked}}


def moments_map(depth: np.ndarray, box: int = MOMENTS_BOX) -> np.ndarray:
    """(H, W, 4) float32 (E[d], E[d²], 0, 1) of a depth map, box-filtered over box × box texels (box odd; edges
    clamped): what the depth pass's moments stage and blur (compose/depth.py) compute on the GPU, here in
    float64 and rounded once — their reference. Moments, unlike depths, may be filtered (bricks/shadow/vsm.py)."""
    if box < 1 or box % 2 == 0:
        raise ValueError(f"moments box {box}: use an odd number of texels")
    d = np.asarray(depth, np.float64)
    m = np.stack([d, d * d], -1)
    r = box // 2
    if r > 0:
        for axis in (0, 1):
            pad = [(0, 0)] * 3
            pad[axis] = (r, r)
            c = np.cumsum(np.pad(m, pad, mode="edge"), axis=axis)
            c = np.concatenate([np.zeros_like(np.take(c, [0], axis=axis)), c], axis=axis)
            n = m.shape[axis]
            m = (np.take(c, np.arange(2 * r + 1, 2 * r + 1 + n), axis=axis) - np.take(c, np.arange(n), axis=axis)) / box
    out = np.zeros(d.shape + (4,), np.float32)
    out[..., :2] = m
    out[..., 3] = 1.0
    return out


class ShadowProblem(Exception):
    """What `render` cannot draw of a shadowed light, before it is located: the parameter that asks for it (None:
    the light's type), what is wrong and what to do; the renderer raises it at the light's scene line
    (:func:`light_where`)."""

    def __init__(self, param: str | None, message: str, hint: str):
        self.param, self.message, self.hint = param, message, hint
        super().__init__(f"{message} — {hint}")


def light_where(scene, name: str, param: str | None = None):
    """The scene line that asks for light `name` (spec/where.Where): in a TOML scene its `params.<param>` key
    (or its `type`), elsewhere (glTF) where its first object's permutation records it (the light's definition)."""
    from ..spec.where import Where

    path = getattr(scene, "path", None)
    if path is not None and str(path).endswith(".toml") and scene.lights.get(name) is not None:
        from ..scene.locate import Locator
        try:
            loc = Locator(str(path), path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError):
            loc = None
        if loc is not None:
            keys = ("params", param) if param and param in scene.lights[name].params else ("type",)
            return Where(str(path), *loc.find(f"lights.{name}", *keys))
    for o in scene.objects:
        perm = scene.permutations.get(o["permutation"])
        if name in o["lights"] and perm is not None and perm.origin is not None:
            return perm.origin.at(f"light{o['lights'].index(name)}")
    return Where(str(path or scene.name))


def casters(scene, name: str) -> list[int]:
    """The indices (scene.objects' order, the manifest's and the export's) of the objects light `name` casts from and
    onto: those whose light set holds it."""
    return [i for i, o in enumerate(scene.objects) if name in o["lights"]]


def _axis(values: dict, name: str, example: str = "[0.3, -0.9, 0.3]") -> np.ndarray:
    d = np.asarray(values["direction"], np.float64).reshape(3)
    if not np.linalg.norm(d) > 0.0:
        raise ShadowProblem("direction", f"light '{name}': direction {list(values['direction'])} has no length, so "
                            "its shadow map has no view", f"give the light a direction, e.g. {example}")
    return d / np.linalg.norm(d)


def _uber_frame(values: dict, axis: np.ndarray) -> np.ndarray | None:
    """The uberlight brick's y axis (its `up` made orthogonal to the axis), or None where up is parallel to it."""
    c = np.cross(np.asarray(values["up"], np.float64).reshape(3), axis)
    if not np.dot(c, c) > 1e-30:
        return None
    x = c / np.linalg.norm(c)
    return np.cross(axis, x)


def _depth_range(view: np.ndarray, pts: np.ndarray) -> tuple[float, float]:
    """(near, far) of a perspective fit from the view-space depths of pts (the point fit's rule: module docstring)."""
    depth = -((view[:3, :3] @ pts.T).T + view[:3, 3])[:, 2]
    far = max(float(depth.max()), 1e-3) * 1.02 + 1e-3
    return max(float(depth.min()) * 0.98, far * 1e-3), far


def cone_tangents(light_type: str, values: dict) -> tuple[float, float]:
    """(tan x, tan y) of the half-angles a spot's or uberlight's map covers (before FIT_MAX_HALF_ANGLE's clamp):
    the cone or the outer superellipse's rectangle, widened by FIT_PADDING; inf for an unshaped uberlight."""
    pad = 1.0 + FIT_PADDING
    if light_type == "spot":
        t = np.tan(min(float(values["outer_angle"]), np.pi / 2 - 1e-9)) * pad
        return t, t
    axis = _axis(values, "")
    if _uber_frame(values, axis) is None:
        return np.inf, np.inf
    return ((float(values["width"]) + float(values["width_edge"])) * pad,
            (float(values["height"]) + float(values["height_edge"])) * pad)


def _cone_matrix(light_type: str, values: dict, pts: np.ndarray, name: str) -> np.ndarray:
    from .camera import _light_up, look_at, perspective

    axis = _axis(values, name)
    eye = np.asarray(values["position"], np.float64).reshape(3)
    up = _uber_frame(values, axis) if light_type == "uberlight" else None
    view = look_at(eye, eye + axis, _light_up(axis) if up is None else up)
    limit = np.tan(np.radians(FIT_MAX_HALF_ANGLE))
    tx, ty = (min(max(t, 1e-3), limit) for t in cone_tangents(light_type, values))
    near, far = _depth_range(view, pts)
    return perspective(2.0 * np.degrees(np.arctan(ty)), tx / ty, near, far) @ view


def _box_distance(eye: np.ndarray, pts: np.ndarray) -> float:
    """The distance from eye to the nearest of the world boxes of pts' groups of 8 corners (one per caster; 0
    inside one); pts not in groups of 8: the nearest point."""
    if len(pts) % 8:
        return float(np.linalg.norm(pts - eye, axis=1).min())
    boxes = pts.reshape(-1, 8, 3)
    gap = np.maximum(np.maximum(boxes.min(1) - eye, eye - boxes.max(1)), 0.0)
    return float(np.linalg.norm(gap, axis=1).min())


# Per cube face (Vulkan's order): its axis f and the view's x and y rows, so that the face's uv is Vulkan's
# (s, t) of a cube-map lookup along the same direction (sc = x·r, tc = -(y·r): perspective flips y).
_CUBE_AXES = (((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
              ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
              ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0)))


def cube_face_matrices(position, points) -> list[np.ndarray]:
    """World → light clip space (row-major, float64) of the six faces of a point light at `position` (Vulkan's
    cube-face order), fitted to world `points` ((n, 3): every caster's 8 corners) as the module docstring says."""
    from .camera import perspective

    eye = np.asarray(position, np.float64).reshape(3)
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    far = max(float(np.linalg.norm(pts - eye, axis=1).max()), 1e-3) * 1.02 + 1e-3
    near = max(_box_distance(eye, pts) * 0.98, far * 1e-3)
    proj = perspective(90.0, 1.0, near, far)
    out = []
    for f, x, y in _CUBE_AXES:
        view = np.eye(4)
        view[0, :3], view[1, :3], view[2, :3] = x, y, -np.asarray(f, np.float64)
        view[:3, 3] = -view[:3, :3] @ eye
        out.append(proj @ view)
    return out


def cube_face(direction) -> int:
    """The face (layer) of direction light → P, as the linker's glue picks it (link/faces.py): its major axis,
    ties to z, then y."""
    r = np.asarray(direction, np.float64).reshape(3)
    a = np.abs(r)
    if a[2] >= a[0] and a[2] >= a[1]:
        return 4 if r[2] >= 0 else 5
    if a[1] >= a[0]:
        return 2 if r[1] >= 0 else 3
    return 0 if r[0] >= 0 else 1


def fit_shadow_matrix(light_type: str, values: dict, points, name: str = "") -> np.ndarray:
    """World → light clip space (row-major, float64) of a light of `light_type` with parameters `values`, fitted
    to world `points` ((n, 3): the corners of every caster's bounds). The module docstring states the method; a
    light it has no projection for is a ShadowProblem. A point light's one map (±FIT_MAX_HALF_ANGLE toward its
    casters) is what an unshadowed light or a caller without arrays gets; a shadowed one has six faces
    (:func:`cube_face_matrices`)."""
    from .camera import directional_shadow_matrix, point_shadow_matrix

    pts = np.asarray(points, np.float64).reshape(-1, 3)
    if light_type == "directional":
        return directional_shadow_matrix(_axis(values, name, "[0.3, 0.9, 0.3]"), pts, margin=FIT_MARGIN)
    if light_type in ("point", "point_range"):
        return point_shadow_matrix(values["position"], pts, max_half_angle_deg=FIT_MAX_HALF_ANGLE)
    if light_type in ("spot", "uberlight"):
        return _cone_matrix(light_type, values, pts, name)
    raise ShadowProblem(None, f"light '{name}': the renderer has no shadow projection for light type "
                        f"'{light_type}' (it projects {', '.join(('directional',) + PERSPECTIVE)})",
                        'use shadow = "none" for it')


def uncovered(light_type: str, values: dict, matrix, points) -> np.ndarray:
    """Which of `points` ((n, 3)) the light may shine on but its map (`matrix`, row-major) does not reach: outside
    the clip volume's x, y or in front of the light's plane, and — for a spot or an uberlight — inside its cone
    (outside it the light gives nothing, so no shadow is missed). A directional fit covers every point."""
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    clip = np.c_[pts, np.ones(len(pts))] @ np.asarray(matrix, np.float64).reshape(4, 4).T
    w = clip[:, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        out = ~((w > 0) & (np.abs(clip[:, 0]) <= w * (1 + 1e-9)) & (np.abs(clip[:, 1]) <= w * (1 + 1e-9)))
    if light_type not in ("spot", "uberlight"):
        return out if light_type in PERSPECTIVE else np.zeros(len(pts), bool)
    axis = _axis(values, "")
    rel = pts - np.asarray(values["position"], np.float64).reshape(3)
    z = rel @ axis
    tx, ty = cone_tangents(light_type, values)
    if light_type == "spot":
        side = np.linalg.norm(rel - z[:, None] * axis, axis=1)
        lit = (z > 0) & (side <= tx * z)
    else:
        y = _uber_frame(values, axis)
        lit = z > 0
        if y is not None:
            x = np.cross(y, axis)
            lit &= (np.abs(rel @ x) <= tx * z) & (np.abs(rel @ y) <= ty * z)
    return out & lit


def face_values(matrix) -> dict:
    """{parameter: column-major matrix} a fitted light writes: {"shadow_matrix": m}, or a point light's six faces
    ({FACE_MATRICES[k]: face k's}) where `matrix` is fit_lights' list of six."""
    if isinstance(matrix[0], (list, tuple, np.ndarray)):
        return dict(zip(FACE_MATRICES, matrix))
    return {"shadow_matrix": matrix}


def caster_points(placed, indices: list[int]) -> np.ndarray:
    """The corners of the bounds of placed objects `indices` (runtime/placement.Placement), (8 n, 3): a light's
    casters' bounds, what its fit covers."""
    return np.concatenate([placed.objects[i].corners() for i in indices]) if indices else np.zeros((1, 3))


def fit_lights(scene, placed, values: dict, cast_by: dict[str, list[int]]) -> tuple[dict, list[str]]:
    """({light: its shadow_matrix, column-major; a point light's: its six faces' (a list of 6)}, located warnings) of
    the shadowed lights `cast_by` ({light: its casters' indices}) of `scene` placed as `placed`, their parameters
    `values`. A light the renderer cannot project is a SourceError at its scene line; one whose map misses
    casters it may light is a warning there."""
    from .camera import column_major

    matrices, warnings = {}, []
    for ln, idx in cast_by.items():
        L = scene.lights[ln]
        pts = caster_points(placed, idx)
        if L.type in CUBE_TYPES:
            matrices[ln] = [column_major(m) for m in cube_face_matrices(values[ln]["position"], pts)]
            continue
        try:
            m = fit_shadow_matrix(L.type, values[ln], pts, ln)
        except ShadowProblem as e:
            raise light_where(scene, ln, e.param).error(e.message, e.hint) from None
        matrices[ln] = column_major(m)
        missed = [placed.objects[i].name for i in idx
                  if uncovered(L.type, values[ln], m, placed.objects[i].corners()).any()]
        if missed:
            w = light_where(scene, ln, "direction")
            warnings.append(f"{w.path}:{w.line}:{w.col}: warning: light '{ln}': its one shadow map covers "
                            f"±{FIT_MAX_HALF_ANGLE:g}° about its axis, and the bounds of {', '.join(map(repr, missed))} "
                            "reach beyond inside its cone: shadows there are not drawn correctly — narrow its cone "
                            "(outer_angle) or its light sets, or make it a point light (six faces)")
    return matrices, warnings


# The fit's parameters as the manifest states them (depth_pass.matrix.fit; the method: the module docstring).
FIT = {"directional": {"projection": "orthographic", "margin": FIT_MARGIN},
       **{t: {"projection": "cube_faces", "fov_deg": 90.0, "near": "nearest caster box", "far": "farthest corner"}
          for t in ("point", "point_range")},
       **{t: {"projection": "perspective", "max_half_angle_deg": FIT_MAX_HALF_ANGLE, "padding": FIT_PADDING}
          for t in ("spot", "uberlight")}}
# What the fit covers: the world-space corners of each caster's axis-aligned bounding box in its own space,
# transformed by its model matrix (the renderer's: runtime/placement.py, Placement.points) ...
BOUNDS = "object_box_corners"
# ... of the casters: the objects whose light set holds the light (casters), not every object of the scene
CASTERS = "light_sets"


def _pair_layers(scene, dyn, light_name: str, pair: int, reads: str, size: int) -> dict:
    """Where a dynamic set's light lies in its pair's shadow array (link/values.py writes its first layer so)."""
    from ..link.faces import shadow_layers

    names = [ln for ln in scene.light_sets[dyn.name] if dyn.pair_of(scene.lights[ln]) == pair]
    per = shadow_layers(scene.lights[light_name].type)
    capacity = dyn.max * per
    return {"first_layer": names.index(light_name) * per, "layers": per, "capacity_layers": capacity,
            "capacity_bytes": capacity * size * size * (16 if reads == "moments" else 4)}


def platform_premultiply(depth_range: str, ndc_y: str, framebuffer_origin: str) -> list[list[float]]:
    """The matrix (row-major) a platform's depth pass puts before shadow_matrix in its Frame.view_proj, from its
    conventions (the module docstring): so that the pass writes the texel and depth the brick reads."""
    m = np.array(IDENTITY)
    if (ndc_y == "up") != (framebuffer_origin == "bottom-left"):  # row 0 of the map is NDC +y: flip
        m[1, 1] = -1.0
    if depth_range == "-1..1":  # window depth (z/w + 1) / 2: write 2z - w so that it is z/w
        m[2] = [0.0, 0.0, 2.0, -1.0]
    return m.tolist()


def depth_pass(light, textures: dict[str, bool], values: dict, units: dict, binds: list[dict],
               size: int = SHADOW_SIZE, platforms: dict | None = None) -> dict:
    """The depth pass of one shadowed light (scene Light `light`, the textures its filter samples, its parameter
    `values`): the manifest's ``lights.<name>.depth_pass`` (its fields are described once, in the manifest's
    schema) and what the renderer draws by.

    units: {"depth": unit, "blur": unit, "masked": {permutation hash: unit}} (pass_units); binds: where the
    result is read (:func:`bindings`); platforms: {platform: its Conventions' (depth_range, ndc_y,
    framebuffer_origin)}."""
    moments = MOMENTS in textures
    d = {"kind": "moments" if moments else "depth", "size": [size, size],
         "depth": {"format": DEPTH_FORMAT, "clear": DEPTH_CLEAR, "compare_op": "less", "write": True, "cull": "none",
                   "bias": {"constant": 0.0, "slope": 0.0, "clamp": 0.0}},
         "casters": {"opaque": {"unit": units["depth"], "stages": ["vert", "frag"] if moments else ["vert"]},
                     "masked": {h: {"unit": u, "stages": ["vert", "frag"]} for h, u in sorted(units["masked"].items())}}}
    if moments:
        d["moments"] = {"format": MOMENTS_FORMAT, "clear": list(MOMENTS_CLEAR),
                        "blur": {"unit": units["blur"], "filter": "box", "size": MOMENTS_BOX, "radius": MOMENTS_BOX // 2,
                                 "edges": "clamp", "passes": [{"axis": [0, 1]}, {"axis": [1, 0]}]}}
    bias = {"parameter": "shadow_bias", "value": values.get("shadow_bias")}
    if moments:
        bias["min_variance"] = {"parameter": "vsm_min_variance", "value": values.get("vsm_min_variance")}
    d["shader_bias"] = bias
    d["matrix"] = {"parameter": "shadow_matrix", "clip": "vulkan",
                   "to_map": {"uv": "clip.xy / clip.w * 0.5 + 0.5", "depth": "clip.z / clip.w"},
                   "premultiply": {p: platform_premultiply(*c) for p, c in sorted((platforms or {}).items())},
                   "fit": {"light_type": light.type, **FIT.get(light.type, {}), "bounds": BOUNDS,
                           "casters": CASTERS,
                           "function": "generator.runtime.shadow_pass.fit_shadow_matrix"}}
    if PCF_TEXEL in values:
        d["texel"] = {"parameter": PCF_TEXEL, "value": values[PCF_TEXEL]}
    if light.type in CUBE_TYPES:  # six faces in the layers of one 2D array (link/faces.py)
        d["matrix"]["parameters"] = list(FACE_MATRICES)
        d["faces"] = {"layers": FACES, "order": list(FACE_NAMES), "select": "major_axis", "passes": "per_layer"}
    d["binds"] = binds
    return d


def bindings(light_name: str, textures: dict[str, bool], objects, interfaces: dict, scene=None,
             size: int = SHADOW_SIZE) -> list[dict]:
    """Where a shadowed light's result binds: per permutation that reads it (an object's light set holds the light
    at index i), the texture of light i its filter samples, with its set, binding and sampler binding (the build
    adds ``sampler_state``, the row of the manifest's samplers it is read with: assemble/texture_outputs.py).
    interfaces: {permutation hash: its textures as the manifest's Interface lists them (Texture.as_dict)}.
    A light of a dynamic set (`scene` says which) binds in its pair's one array (light_index: the pair's): its rows
    add `array` ({first_layer, layers: its own; capacity: the set's max × its layers, and the bytes that array
    takes at `size`})."""
    rows, seen = [], set()
    for o in objects:
        if light_name not in o["lights"] or (o["permutation"], light_name) in seen:
            continue
        seen.add((o["permutation"], light_name))
        dyn = getattr(scene, "dynamic_sets", {}).get(o.get("light_set"))
        i = dyn.pair_of(scene.lights[light_name]) if dyn is not None else o["lights"].index(light_name)
        for t in interfaces.get(o["permutation"], []):
            if t.get("light") == i and t["name"] in textures:
                reads = "moments" if t["name"] == MOMENTS else "depth"
                row = {"permutation": o["permutation"], "light_index": i, "texture": t["name"], "set": t["set"],
                       "binding": t["binding"], "sampler_binding": t["sampler_binding"], "image": reads}
                if dyn is not None:
                    row["array"] = _pair_layers(scene, dyn, light_name, i, reads, size)
                rows.append(row)
    return sorted(rows, key=lambda r: (r["permutation"], r["texture"]))
