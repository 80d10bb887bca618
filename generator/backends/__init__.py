"""The back ends: one package per language (glsl/, hlsl/, wgsl/, gl/ for the GL dialects, numpy/), each an
emitter behind generator.backends.base.Target, and the registry of them (TARGETS, get_target, LANGUAGES).

GLSL, HLSL and WGSL share the tree walk in clike/; the NumPy back end is imported only when asked
for, so the shader back ends need nothing beyond the standard library.
"""
from __future__ import annotations

from .base import Emitted, Target
from .glsl.emit import GlslHalfTarget, GlslTarget
from .hlsl.emit import HlslHalfTarget, HlslTarget
from .wgsl.emit import WgslHalfTarget, WgslTarget

TARGETS: dict[str, Target] = {"glsl": GlslTarget(), "hlsl": HlslTarget(), "wgsl": WgslTarget()}
# fp16 variants: the brick language's float is the language's 16-bit float (half arithmetic, not only storage)
HALF_TARGETS: dict[str, Target] = {"glsl": GlslHalfTarget(), "hlsl": HlslHalfTarget(), "wgsl": WgslHalfTarget()}
LANGUAGES: tuple[str, ...] = ("glsl", "hlsl", "wgsl")  # the shading languages, in output order


def parse_languages(text: str) -> list[str]:
    """"glsl,wgsl" -> ["glsl", "wgsl"]; ValueError naming the problem for an unknown, repeated or missing name."""
    items = [x.strip() for x in text.split(",") if x.strip()]
    bad = [x for x in items if x not in LANGUAGES]
    if not items or bad or len(set(items)) != len(items):
        raise ValueError(f"{text!r} is not a comma-separated list of {', '.join(LANGUAGES)}, each at most once")
    return items


def get_target(name: str, precision: str = "fp32") -> Target:
    """The emitter for `name`: "glsl", "hlsl", "wgsl" or "numpy"; precision "fp16" gives a shading
    language's half variant (the NumPy target takes its dtype at load() instead)."""
    if precision == "fp16" and name in HALF_TARGETS:
        return HALF_TARGETS[name]
    if precision not in ("fp32", "fp16"):
        raise ValueError(f"unknown precision '{precision}' (known: fp32, fp16)")
    if name not in TARGETS and name == "numpy":
        # Registered lazily: numpy/emit.py imports NumPy, which the shader targets do not need.
        from .numpy.emit import NumpyTarget
        TARGETS["numpy"] = NumpyTarget()
    try:
        return TARGETS[name]
    except KeyError:
        raise ValueError(f"unknown target '{name}' (known: glsl, hlsl, numpy, wgsl)") from None


__all__ = ["Emitted", "Target", "TARGETS", "HALF_TARGETS", "LANGUAGES", "get_target", "GlslTarget", "HlslTarget",
           "WgslTarget", "GlslHalfTarget", "HlslHalfTarget", "WgslHalfTarget"]
