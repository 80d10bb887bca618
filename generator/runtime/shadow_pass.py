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

The fit (:func:`fit_shadow_matrix`, the method the renderer uses; an engine that fits to its own bounds
the same way gets the same matrix): a directional light's orthographic projection along its direction
around the centre of the bounds, x and y padded by FIT_MARGIN of their extent, depth spanning them; a
point light's perspective projection from its position toward the bounds' centre, its field of view
covering them up to ±FIT_MAX_HALF_ANGLE degrees, near and far fitted with 2 % slack. The bounds are the
world-space corners of every object's axis-aligned bounding box in its own space, transformed by its
model matrix (runtime/placement.py, Placement.points); `render` records the matrices it used in its report.
"""
from __future__ import annotations

import numpy as np

SHADOW_SIZE = 512  # the side of a light's map, in texels (render --shadow-size changes the renderer's)
DEPTH_FORMAT = "D32_SFLOAT"
DEPTH_CLEAR = 1.0  # the far plane: lit wherever no caster was drawn
MOMENTS_FORMAT = "R32G32B32A32_SFLOAT"  # (E[d], E[d²], 0, 1): 16-bit moments would lose E[d²] - E[d]²
MOMENTS_CLEAR = [1.0, 1.0, 0.0, 1.0]  # the moments of the depth clear
MOMENTS = "shadow_moments"  # the shadow brick texture that reads the (blurred) moments (vsm)
PCF_TEXEL = "pcf_texel"  # a shadow parameter the renderer writes as 1 / size when the scene leaves it unset
MOMENTS_BOX = 5  # the moments' prefilter: a box of this many texels a side
FIT_MARGIN = 0.02
FIT_MAX_HALF_ANGLE = 75.0
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


def fit_shadow_matrix(light_type: str, values: dict, points, name: str = "") -> np.ndarray:
    """World → light clip space (row-major, float64) of a light of `light_type` with parameters `values`, fitted
    to world `points` ((n, 3): the corners of every object's bounds). The module docstring states the method."""
    from ..lang.errors import UserError
    from .camera import directional_shadow_matrix, point_shadow_matrix

    if light_type == "directional":
        if not np.linalg.norm(np.asarray(values["direction"], np.float64)) > 0.0:
            raise UserError(f"light '{name}': direction {list(values['direction'])} has no length, so its "
                            "shadow map has no view — give the direction to the light, e.g. [0.3, 0.9, 0.3]")
        return directional_shadow_matrix(values["direction"], points, margin=FIT_MARGIN)
    if light_type == "point":
        return point_shadow_matrix(values["position"], points, max_half_angle_deg=FIT_MAX_HALF_ANGLE)
    raise UserError(f"light '{name}': the renderer has no shadow projection for light type '{light_type}' "
                    "— use shadow = \"none\" for it")


# The fit's parameters as the manifest states them (depth_pass.matrix.fit; the method: the module docstring).
FIT = {"directional": {"projection": "orthographic", "margin": FIT_MARGIN},
       "point": {"projection": "perspective", "max_half_angle_deg": FIT_MAX_HALF_ANGLE}}
# What the fit covers: the world-space corners of every object's axis-aligned bounding box in its own space,
# transformed by its model matrix (the renderer's: runtime/placement.py, Placement.points).
BOUNDS = "object_box_corners"


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
                           "function": "generator.runtime.shadow_pass.fit_shadow_matrix"}}
    if PCF_TEXEL in values:
        d["texel"] = {"parameter": PCF_TEXEL, "value": values[PCF_TEXEL]}
    d["binds"] = binds
    return d


def bindings(light_name: str, textures: dict[str, bool], objects, interfaces: dict) -> list[dict]:
    """Where a shadowed light's result binds: per permutation that reads it (an object's light set holds the light
    at index i), the texture of light i its filter samples, with its set, binding and sampler binding (the build
    adds ``sampler_state``, the row of the manifest's samplers it is read with: assemble/texture_outputs.py).
    interfaces: {permutation hash: its textures as the manifest's Interface lists them (Texture.as_dict)}."""
    rows, seen = [], set()
    for o in objects:
        if light_name not in o["lights"] or (o["permutation"], light_name) in seen:
            continue
        seen.add((o["permutation"], light_name))
        i = o["lights"].index(light_name)
        for t in interfaces.get(o["permutation"], []):
            if t.get("light") == i and t["name"] in textures:
                reads = "moments" if t["name"] == MOMENTS else "depth"
                rows.append({"permutation": o["permutation"], "light_index": i, "texture": t["name"], "set": t["set"],
                             "binding": t["binding"], "sampler_binding": t["sampler_binding"], "image": reads})
    return sorted(rows, key=lambda r: (r["permutation"], r["texture"]))
