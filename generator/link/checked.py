"""Link a scene's permutations and its ubershader and check their IR (`build --validate-ir`, a debug aid)."""
from __future__ import annotations

from ..lang import SourceError
from ..lang.validate import validate_program
from . import link_permutation
from .uber import link_ubershader


def ir_violations(perms, lib) -> list[str]:
    """Every IR invariant the linked programs of `perms` (each permutation, then their ubershader) break,
    as '<permutation>: <violation>' lines; [] when the link stage built valid IR."""
    out, programs = [], []
    for p in perms:  # a permutation that does not link is the build's to report, located; its IR is not checked
        try:
            programs.append((p.canonical(), link_permutation(p, lib).program))
        except SourceError:
            continue
    try:
        if perms:
            programs.append(("ubershader", link_ubershader(list(perms), lib).program))
    except SourceError:
        pass
    for name, prog in programs:
        out += [f"{name}: {v}" for v in validate_program(prog.functions, prog.globals)]
    return out
