"""The pipeline state a permutation is drawn with, stated once for the build and the renderer.

The build writes these into the manifest (``render_state`` and ``output`` per permutation, ``conventions``
scene-wide: assemble/manifest.py conventions), and the renderer draws by the very same values (runtime/renderer.py,
runtime/graphics.py ``GraphicsPipeline(render_state=...)``), as the depth passes share runtime/shadow_pass.py:

- :func:`render_state`: alpha mode (and a material's cutoff), blending, culling and depth from the surface
  state (spec/surface.py). Blending is source-over for a colour that is **not premultiplied** (link/glue.py
  ``surface_output`` returns the output brick's colour as is, its alpha the coverage); the attachment's alpha
  accumulates coverage, a + d(1 − a). A single-sided surface culls back faces (its shader does not flip the
  normal for them), a double-sided one culls nothing (its shader flips N, T and B on back faces, glTF 2.0
  §3.9.5). Depth is tested with LESS against a clear of 1 and written, except under blending: a transparent
  surface does not hide what is drawn after it.
- :func:`output_state`: which output brick the permutation ends in, what it encodes (its declaration's
  ``encodes``: ``linear`` radiance, or ``srgb`` / ``sqrt`` display-encoded values), and so which colour
  attachment stores it without encoding twice or not at all: an ``_SRGB`` attachment for ``linear`` (the
  hardware encodes on write, and blends in linear), ``UNORM`` for an encoding brick (it stores what is
  written). An engine keeping HDR for a later pass may as well give ``linear`` a float attachment.
- :data:`OBJECT_BLOCK`: what the per-draw Object block holds (runtime/camera.py ``object_bytes`` writes it).
"""
from __future__ import annotations

# Source-over for a colour that is not premultiplied (the module docstring).
SOURCE_OVER = {"color": {"src": "src_alpha", "dst": "one_minus_src_alpha", "op": "add"},
               "alpha": {"src": "one", "dst": "one_minus_src_alpha", "op": "add"},
               "premultiplied": False}
ENCODINGS = ("linear", "srgb", "sqrt")  # an output brick's `encodes` (library/schema.py)
# the colour attachment that stores an output without a second (or a missing) encoding, API-neutral (Vulkan's
# names without VK_FORMAT_); each platform spells it (assemble/platform_base.py Platform.formats)
COLOR_FORMATS = {"srgb": "R8G8B8A8_SRGB", "unorm": "R8G8B8A8_UNORM"}
DEPTH_FORMAT = "D32_SFLOAT"
DEPTH_CLEAR = 1.0  # the far plane; the depth test is LESS
# The per-draw Object block (link/interface.OBJECT_BLOCK, the vertex stage's): std140, matrices column-major
# (16 floats, column by column: every language reads the same bytes), at Vulkan's (set, binding) below, where
# link/__init__.py, link/depth.py and link/uber.py place it.
OBJECT_SET_BINDING = (2, 0)
OBJECT_HOLDS = {"model": "object to world space: the vertex stage's world position is model × (position, 1)",
                "normal_matrix": "the inverse transpose of model's upper 3 × 3 in the upper 3 × 3 of a mat4 whose "
                                 "fourth row and column are (0, 0, 0, 1): normals are normal_matrix × normal, so they "
                                 "stay perpendicular under non-uniform scale (tangents are transformed by model)"}


def render_state(surface, cutoff: float | None = None) -> dict:
    """The pipeline state of a surface (spec/surface.Surface): alpha mode, blending, culling, depth. `cutoff`: a
    material's alpha_cutoff, stated with alpha mode mask (a permutation has none: its materials share it)."""
    state: dict = {"alpha_mode": surface.alpha}
    if surface.alpha == "mask" and cutoff is not None:
        state["alpha_cutoff"] = cutoff
    blend = surface.alpha == "blend"
    state["blend"] = {k: (dict(v) if isinstance(v, dict) else v) for k, v in SOURCE_OVER.items()} if blend else None
    state["cull"] = "none" if surface.double_sided else "back"
    state["depth"] = {"test": True, "write": not blend, "compare": "less"}
    return state


def attachment(encodes: str) -> str:
    """The colour attachment (a key of COLOR_FORMATS) for an output brick that writes `encodes`."""
    if encodes not in ENCODINGS:
        raise ValueError(f"an output brick encodes one of {', '.join(ENCODINGS)}, not {encodes!r}")
    return "srgb" if encodes == "linear" else "unorm"


# The renderer's background, display-encoded: on an sRGB attachment it clears with the linear values, which the
# attachment encodes back, so a frame has the same background bytes whatever the scene's output.
CLEAR = (0.06, 0.07, 0.09, 1.0)


def color_attachment(lib, perms) -> str:
    """The colour attachment (a key of COLOR_FORMATS) the permutations' output brick asks for, as the build writes it
    into each one's ``output``; every permutation of a scene ends in the scene's output brick, so they agree."""
    from ..lang.errors import UserError

    kinds = {output_state(lib.get("output", p.output))["attachment"] for p in perms}
    if len(kinds) > 1:
        raise UserError(f"the permutations ask for colour attachments {', '.join(sorted(kinds))}: one target cannot "
                        "store both — give the scene one output brick")
    return kinds.pop() if kinds else "unorm"


def clear_color(attachment: str) -> tuple:
    """CLEAR as the floats given to the clear of an `attachment` target."""
    if attachment != "srgb":
        return CLEAR
    decode = lambda c: c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4  # noqa: E731 (IEC 61966-2-1)
    return (*(decode(c) for c in CLEAR[:3]), CLEAR[3])


def output_state(brick) -> dict:
    """{"brick", "encodes", "attachment"} of a permutation's output brick (library/bricks.Brick)."""
    return {"brick": brick.id, "encodes": brick.encodes, "attachment": attachment(brick.encodes)}


# The per-view Frame block (link/interface.FRAME_BLOCK), read by both stages: what the engine writes there.
FRAME_HOLDS = {"view_proj": "world to the platform's clip space (its `conventions.platforms.<p>.clip`); the vertex stage "
                            "writes view_proj × model × (position, 1). A depth pass writes its light's shadow_matrix "
                            "premultiplied as its depth_pass.matrix says",
               "camera_pos": "the camera's world position in xyz, w = 1: the view direction is camera_pos.xyz − the "
                             "surface's world position (a depth pass: the light's, or the centre of the casters)"}


def frame_block() -> dict:
    """The Frame block as the manifest states it: its name, stages, layout, size and members."""
    from ..link.interface import FRAME_BLOCK
    members = [{"name": m["name"], "type": m["type"], "offset": m["offset"], "size": m["size"],
                "holds": FRAME_HOLDS[m["name"]]} for m in FRAME_BLOCK]
    return {"name": "Frame", "stages": ["vert", "frag"], "layout": "std140", "matrices": "column_major",
            "size": max(m["offset"] + m["size"] for m in FRAME_BLOCK), "members": members}


def object_block() -> dict:
    """The Object block as the manifest states it: its name, stage, layout, size and members."""
    from ..link.interface import OBJECT_BLOCK
    members = [{"name": m["name"], "type": m["type"], "offset": m["offset"], "size": m["size"],
                "holds": OBJECT_HOLDS[m["name"]]} for m in OBJECT_BLOCK]
    return {"name": "Object", "stages": ["vert"], "layout": "std140", "matrices": "column_major",
            "size": max(m["offset"] + m["size"] for m in OBJECT_BLOCK), "members": members}
