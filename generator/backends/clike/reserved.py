"""The names every C-like back end renames brick identifiers against, and the prefixes of generated names.

Each language's words live in its package (glsl/keywords.py, hlsl/keywords.py, wgsl/keywords.py). Every
C-like target renames against their union `ALL`, so one brick name is spelled the same in GLSL, HLSL
and WGSL (and in the GL dialects, which are GLSL). A new C-like language adds its table to the union:
that renames a brick name using one of its words in every language, which is the point (one spelling
everywhere), and changes the other languages' output where a brick uses such a name.
"""
from __future__ import annotations

from ..glsl.keywords import WORDS as GLSL
from ..hlsl.keywords import WORDS as HLSL
from ..wgsl.keywords import WORDS as WGSL

ALL: frozenset[str] = GLSL | HLSL | WGSL

# GLSL reserves every identifier that starts with this prefix.
RESERVED_PREFIXES: tuple[str, ...] = ("gl_",)
# A reserved brick identifier is spelled with this prefix in every target. Brick
# identifiers never start with '_' (generator/lang/exprs.py), so a renamed name
# cannot meet a brick's own name; the same holds for SAMPLER_PREFIX.
PREFIX = "_r_"
SAMPLER_PREFIX = "_smp_"
# Generated names for buffers: the GLSL block / HLSL cbuffer of buffer NAME, and
# HLSL's length helper of a storage buffer (see clike/resources.py).
BLOCK_PREFIX = "_blk_"
LENGTH_PREFIX = "_len_"
