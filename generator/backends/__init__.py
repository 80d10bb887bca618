"""The back ends: one package per language (glsl/, hlsl/, wgsl/, gl/ for the GL dialects, numpy/), each with
its emitter (behind generator.backends.base.Target), its keyword table, its Jinja templates and its part of the
template context (context.py: a generator.backends.language.Language), and the registry of them here.

GLSL, HLSL and WGSL share the tree walk in clike/; the NumPy back end is imported only when asked
for, so the shader back ends need nothing beyond the standard library. A shading language is added
by adding its package and its line in _SHADING below.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

from .base import Emitted, Target
from .front_end import FrontEnd
from .gl.context import DIALECTS as _DIALECTS
from .glsl.context import LANGUAGE as _GLSL
from .hlsl.context import LANGUAGE as _HLSL
from .language import Language
from .wgsl.context import LANGUAGE as _WGSL

_SHADING: tuple[Language, ...] = (_GLSL, _HLSL, _WGSL)  # in output order
LANGUAGES: tuple[str, ...] = tuple(lang.name for lang in _SHADING)  # the shading languages
# the platform dialects composed beside them ("gl": GLSL 4.50 core for OpenGL, "essl": GLSL ES 3.10)
DIALECTS: dict[str, Language] = dict(_DIALECTS)
TARGETS: dict[str, Target] = {lang.name: lang.full for lang in _SHADING}
# fp16 variants: the brick language's float is the language's 16-bit float (half arithmetic, not only storage)
HALF_TARGETS: dict[str, Target] = {lang.name: lang.half for lang in _SHADING}
# How each shading language's text becomes SPIR-V: what the toolchain reads instead of the language's name.
FRONT_ENDS: dict[str, FrontEnd] = {lang.name: lang.front_end for lang in _SHADING}
# Template names start with a folder ("glsl/fragment.glsl.j2"): the back-end package whose templates/ holds the file.
TEMPLATE_PACKAGES: dict[str, str] = {lang.folder: lang.package for lang in (*_SHADING, *DIALECTS.values())}


def language(name: str) -> Language:
    """The templates and template context of shading language or platform dialect `name`."""
    found = next((lang for lang in _SHADING if lang.name == name), None) or DIALECTS.get(name)
    if found is None:
        raise ValueError(f"unknown language '{name}' (known: {', '.join([*LANGUAGES, *DIALECTS])})")
    return found


def template_root(folder: str) -> Path:
    """The templates/ directory of the back end owning template folder `folder`, wherever it is installed (the
    directory jinja2.PackageLoader reads)."""
    spec = importlib.util.find_spec(TEMPLATE_PACKAGES[folder])
    return Path(next(iter(spec.submodule_search_locations))) / "templates"


def template_file(name: str) -> Path:
    """The file of template `name` ("glsl/fragment.glsl.j2")."""
    folder, _, rest = name.partition("/")
    if folder not in TEMPLATE_PACKAGES or not rest:
        raise ValueError(f"no template '{name}': a template name is FOLDER/FILE, FOLDER one of "
                         f"{', '.join(TEMPLATE_PACKAGES)}")
    return template_root(folder) / rest


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
        raise ValueError(f"unknown target '{name}' (known: {', '.join(sorted({*TARGETS, 'numpy'}))})") from None


__all__ = ["DIALECTS", "Emitted", "FRONT_ENDS", "FrontEnd", "HALF_TARGETS", "LANGUAGES", "Language", "TARGETS",
           "TEMPLATE_PACKAGES", "Target", "get_target", "language", "parse_languages", "template_file"]
