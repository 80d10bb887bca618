"""Helpers for the keyword tables of the C-like back ends (each language's table lives in its package)."""
from __future__ import annotations


def words(text: str) -> frozenset[str]:
    return frozenset(text.split())


def shapes(prefixes, sizes=(2, 3, 4), matrices=False) -> frozenset[str]:
    """Every vector (with `matrices`, every matrix) type name of `prefixes`: vec2 ... vec4, mat2x3, ..."""
    out = set()
    for p in prefixes:
        for n in sizes:
            out.add(f"{p}{n}")
            if matrices:
                out.update(f"{p}{n}x{m}" for m in sizes)
    return frozenset(out)
