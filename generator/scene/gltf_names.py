"""The names a glTF import gives what it maps: materials, light sets, lights and objects.

A glTF name is optional and need not be unique: it is kept printable, stripped and at most 200
characters (`unnamed` when nothing is left); an absent or empty one falls back to a related object's name
or to `<kind><index>` (materials, scenes: `material3`, `scene0`); and one already taken gets `~2`, `~3`,
… (the first free).
"""
from __future__ import annotations


def clean(name: str) -> str:
    name = "".join(c for c in name if c.isprintable()).strip() or "unnamed"
    return name[:200]


def free_name(base: str, taken) -> str:
    if base not in taken:
        return base
    k = 2
    while f"{base}~{k}" in taken:
        k += 1
    return f"{base}~{k}"


def unique_names(names: list[str], prefix: str) -> list[str]:
    out: list[str] = []
    for i, n in enumerate(names):
        out.append(free_name(clean(n) if n else f"{prefix}{i}", set(out)))
    return out
