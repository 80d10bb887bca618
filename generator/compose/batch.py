"""Compose a batch of permutations: each resolved, linked and composed once, in that order.

The build's loop (a chunk at a time, in this process or a worker), `shadermatrix check` and the cost
report all compose many permutations and then compile what they composed; this is the one loop they
share. It only composes: what to compile, and how, stays with the caller (the toolchain comes after
this stage). A permutation that cannot be composed is an error under its hash, and the others still
compose.
"""
from __future__ import annotations

from ..lang import SourceError
from ..library.bricks import Library
from ..link import link_permutation
from ..spec.permutation import Permutation, SpecError
from ..spec.resolve import resolve
from ..spec.where import spec_where
from . import Composed, compose_permutation


def compose_permutations(items, lib: Library, languages, dialects=()) -> tuple[dict[str, Composed],
                                                                              dict[str, list[str]]]:
    """(Composed by hash, errors by hash) of (hash, Permutation) pairs, in their order: the sources of
    every language of `languages`, and of every platform dialect of `dialects` (compose_permutation).

    Every error is located: where the scene asked for the permutation or at the brick line at fault (a
    SourceError's own position), a bad spec string at its column."""
    composed: dict[str, Composed] = {}
    errors: dict[str, list[str]] = {}
    for h, perm in items:
        try:
            composed[h] = compose_one(perm, lib, languages, dialects)
        except SourceError as e:
            errors[h] = [str(e)]
    return composed, errors


def compose_one(perm: Permutation, lib: Library, languages, dialects=()) -> Composed:
    """One permutation, each stage once and forward: its resolved key, its linked program, then its sources.
    Raises a located SourceError (a bad spec string, which spec.permutation reports by column alone, too)."""
    try:
        linked = link_permutation(resolve(perm, lib), lib)
    except SpecError as e:
        raise spec_where(e.spec, e.col).error(e.message, e.hint) from None
    return compose_permutation(linked, lib, languages, dialects)
