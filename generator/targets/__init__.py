"""Target emitters: one per language, all behind generator.targets.base.Target.

GLSL, HLSL and WGSL share the tree walk in clike.py; the NumPy target
(numpy.py) is imported only when asked for, so the shader targets need
nothing beyond the standard library.
"""
from __future__ import annotations

from .base import Emitted, Target
from .glsl import GlslTarget
from .hlsl import HlslTarget
from .wgsl import WgslTarget

TARGETS: dict[str, Target] = {"glsl": GlslTarget(), "hlsl": HlslTarget(), "wgsl": WgslTarget()}
LANGUAGES: tuple[str, ...] = ("glsl", "hlsl", "wgsl")  # the shading languages, in output order


def get_target(name: str) -> Target:
    """The emitter for `name`: "glsl", "hlsl", "wgsl" or "numpy"."""
    if name not in TARGETS and name == "numpy":
        # Registered lazily: numpy.py imports NumPy, which the shader targets do not need.
        from .numpy import NumpyTarget
        TARGETS["numpy"] = NumpyTarget()
    try:
        return TARGETS[name]
    except KeyError:
        raise ValueError(f"unknown target '{name}' (known: glsl, hlsl, numpy, wgsl)") from None


__all__ = ["Emitted", "Target", "TARGETS", "LANGUAGES", "get_target", "GlslTarget", "HlslTarget", "WgslTarget"]
