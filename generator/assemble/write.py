"""Writing a build's units: their sources and SPIR-V under content names, their platform artifacts, their costs.

Artifacts are named by their content (``<hash>.<stage>.<sha12>.<ext>``) and written atomically, so nothing a
previous manifest names is ever overwritten; a unit is entered into the manifest only when every one of its
shaders compiled, and otherwise its failing sources are written beside (``<name>.<stage>.failed.<lang>``).
"""
from __future__ import annotations

from pathlib import Path

from ..analysis import cost_dict
from ..io import atomic_write, sha256
from ..toolchain import CompileJob
from ..toolchain.jobs import job_key
from .context import BuildContext
from .platforms import LANGUAGE_TREE, PLATFORM_TABLE, write_platforms


class Writer:
    """Writes into `out` for one build, counting into its BuildResult `res` (written, unchanged, aliased, costs)."""

    spool = None  # build --pack-only: the spool.Spool that takes the artifacts instead of the output tree

    def __init__(self, out: Path, ctx: BuildContext, res):
        self.out, self.ctx, self.res = out, ctx, res
        self._done: set[str] = set()  # SPIR-V files this build has written or found in place
        self._dirs: dict[str, set[str]] = {}  # the directories it has made or found, their names (io.atomic_write)
        # the platforms' binary steps (d3d12's DXC, where a dxc is on PATH), asked for only when a platform is built
        self._steps = {p: step for p in ctx.platforms if (step := PLATFORM_TABLE[p].binary_step()) is not None}

    def count(self, changed: bool) -> None:
        if changed:
            self.res.written += 1
        else:
            self.res.unchanged += 1

    def put(self, rel: str, data: bytes) -> None:
        if self.spool is not None and artifact(rel):
            self.spool.stash(rel, data)
            return
        self.count(atomic_write(f"{self.out}/{rel}", data, self._dirs))

    def put_shared(self, rel: str, data: bytes) -> None:
        """Write a SPIR-V module that identical ones share: once per build, the others counted as aliased."""
        if rel in self._done:
            self.res.aliased += 1
        else:
            self._done.add(rel)
            if self.spool is not None:
                self.spool.stash(rel, data, shared=True)
            else:
                self.put(rel, data)

    def unit(self, name: str, sources, results, entry: dict) -> list[str]:
        """Write a unit's sources and SPIR-V into `entry` only when every one compiled; else write the failing
        sources beside and return the errors."""
        errs, failed = [], {}
        for src in sources:
            r = results[job_key(name, src.stage, src.language)]
            if not (r.ok and r.spirv):
                rel = f"{LANGUAGE_TREE}/{src.language}/{name}.{src.stage}.failed.{src.language}"
                self.put(rel, src.text.encode())
                failed[f"{src.language}.{src.stage}"] = rel
                errs += r.errors()
        if errs:
            entry["failed_sources"] = failed
            return errs
        for src in sources:
            r = results[job_key(name, src.stage, src.language)]
            entry["languages"].setdefault(src.language, {})[src.stage] = self._shader(name, src, r)
        return []

    def platforms(self, h: str, composed, entry: dict, checked: dict, precision: str) -> list[str]:
        """A permutation's platform artifacts (platforms.write_platforms); checked: its dialects' errors."""
        return write_platforms(self.put, h, composed, entry, self.ctx.platforms, checked, precision, self._steps)

    def _shader(self, name: str, src, r) -> dict:
        """Write one compiled source and its SPIR-V under content names; returns its manifest item."""
        data = src.text.encode()
        src_sha, spv_sha = sha256(data), sha256(r.spirv)
        if LANGUAGE_TREE not in self.ctx.platforms:  # the SPIR-V checks ran (their costs are recorded): nothing to ship
            return {"source_sha256": src_sha, "spirv_sha256": spv_sha, "cost": self.cost(spv_sha, r.spirv)}
        rel_src = f"{LANGUAGE_TREE}/{src.language}/{name}.{src.stage}.{src_sha[:12]}.{src.language}"
        # SPIR-V is named by its content alone: identical modules (the vertex shaders of most permutations) are
        # one file, and every manifest item that has them names it (aliased); sources keep their own header
        rel_spv = f"{LANGUAGE_TREE}/{src.language}/{spv_sha[:16]}.{src.stage}.spv"
        self.put(rel_src, data)
        self.put_shared(rel_spv, r.spirv)
        return {"source": rel_src, "source_sha256": src_sha, "spirv": rel_spv, "spirv_sha256": spv_sha,
                "cost": self.cost(spv_sha, r.spirv)}

    def cost(self, sha: str, spirv: bytes) -> dict:
        """A module's cost, analysed once per build (a worker's, or here) whatever the store holds."""
        cost = self.res.costs.get(sha)
        if cost is None:
            cost = self.res.costs[sha] = cost_dict(spirv, self.ctx.store)
        return cost


def artifact(rel: str) -> bool:
    """Whether `rel` is an artifact of a unit (a source, a SPIR-V module, a platform's file), which build
    --pack-only leaves to the packs: not the manifest, the tables and textures, or a failing unit's sources."""
    return rel.split("/", 1)[0] in _TREES and ".failed." not in rel


_TREES = {LANGUAGE_TREE, *(p.name for p in PLATFORM_TABLE.values() if p.own_files)}


def validate_dialects(pairs, store, gate=None) -> dict[str, list[str]]:
    """glslangValidator's errors (job key -> errors) for the platform dialect sources of a compiled chunk."""
    from ..toolchain.platforms import validate_dialects as validate
    jobs = [CompileJob(job_key(h, s.stage, s.language), s.language, s.stage, s.text, line_map=tuple(s.line_map))
            for h, c in pairs for s in c.dialects]
    return validate(jobs, store, gate=gate) if jobs else {}
