"""What each build's input keys were made of, and why a build rebuilt what it did (`build --explain`).

An input key (keys.py) is a digest: unequal keys say that an input changed, not which. So every build that is
not a no-op leaves INPUTS beside its state record: the parts its keys were made of, item by item — the build's
own (generator version, the sha256 of each of its source and template files, the tools' versions, languages,
platforms and their tools), every permutation's bricks with their sources' sha256, and the scene values its key
reads (its objects, their materials and lights). The next build diffs its own parts against that record for
each permutation (and the ubershader) it rebuilds, and counts how far each changed input reaches: its fan-out.

Deterministic, like the state record: no times, no absolute paths, sorted keys. A brick set shared by many
permutations is written once (``brick_sets``, each a list of indices into the sorted ``bricks``). Reading the
last record costs a build one file read; it is parsed only when an explanation is asked for. Measured on the
benchmark's generated scene of 1,000 permutations (1,000 materials, 1,000 distinct brick sets): a 0.8 MB
record (most of it the materials' values), made and written in about 60 ms.
"""
from __future__ import annotations

import dataclasses
import json
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..io import atomic_write

INPUTS = ".shadermatrix-inputs.json"
FORMAT = 1
_HEX64 = re.compile(r"^[0-9a-f]{64}$")
NO_EARLIER_BUILD = "no earlier build"


@dataclass(frozen=True)
class Change:
    """One input that differs from the last build's (a file, a tool, a scene value), or, with neither old nor new,
    a cause that is no input ("not in the last build")."""

    what: str
    old: str | None = None
    new: str | None = None

    @property
    def verb(self) -> str:
        return "" if self.old is None and self.new is None else \
            "added" if self.old is None else "removed" if self.new is None else "changed"

    def __str__(self) -> str:
        if not self.verb:
            return self.what
        if self.verb == "added":
            return f"{self.what} added ({self.new})"
        if self.verb == "removed":
            return f"{self.what} removed (was {self.old})"
        return f"{self.what} changed ({self.old} → {self.new})"

    @property
    def label(self) -> str:
        """The change without its values: what a fan-out line counts."""
        return f"{self.what} {self.verb}" if self.verb else self.what

    def order(self) -> tuple:
        return self.what, self.old or "", self.new or ""


def snapshot(b) -> dict:
    """The record of build `b` (assemble._Build): what its keys were made of."""
    from .. import __version__
    from .keys import build_inputs
    ctx, scene = b.ctx, b.scene
    bricks: dict[str, str] = {}
    for h in scene.permutations:
        read = b.keys.bricks.get(h, {})
        if "error" not in read:
            bricks.update(read)
    index = {p: i for i, p in enumerate(sorted(bricks))}
    sets: dict[tuple, int] = {}
    perms = {}
    for h in sorted(scene.permutations):
        read = b.keys.bricks.get(h, {})
        entry: dict = {"objects": [[o["name"], o["material"], o["light_set"], list(o["lights"])]
                                   for o in b.users.get(h, [])]}
        if "error" in read:  # it does not resolve: keyed by the error (keys._perm_key)
            entry["error"] = read["error"]
        else:
            entry["bricks"] = sets.setdefault(tuple(sorted(index[p] for p in read)), len(sets))
        perms[h] = entry
    return {"format": FORMAT, "build": build_inputs(__version__, b.tools, ctx.languages, ctx.platforms),
            "bricks": dict(sorted(bricks.items())), "brick_sets": [list(s) for s in sets],
            "permutations": perms,
            "materials": {n: _plain(m) for n, m in sorted(scene.materials.items())},
            "lights": {n: _plain(x) for n, x in sorted(scene.lights.items())}}


def record(b) -> Rebuild:
    """Write build `b`'s record over the last one; returns what explains this build (computed when asked for)."""
    out: Path = b.out
    try:
        old = (out / INPUTS).read_bytes()
    except OSError:
        old = None
    new = snapshot(b)
    atomic_write(out / INPUTS, (json.dumps(new, sort_keys=True, separators=(",", ":")) + "\n").encode())
    last = {h: (e.get("input_key"), e.get("status")) for h, e in b.old.items()}
    old_uber = b.previous.get("ubershader") or {}
    return Rebuild(old, new, b.scene, set(b.kept), last, bool(b.previous), b.uber_kept,
                   (old_uber.get("input_key"), old_uber.get("status")) if old_uber else None, b.keys)


@dataclass
class Explained:
    """Why a build rebuilt what it did: per rebuilt permutation its changes, the ubershader's (None: kept), and
    each change's fan-out."""

    total: int
    first: bool  # no earlier build: everything was built
    ids: dict[str, str]
    rebuilt: dict[str, list[Change]]
    ubershader: list[Change] | None
    # (a change, how many rebuilt permutations a change of that input reached, whether the ubershader), widest first
    fan_out: list[tuple[Change, int, bool]] = field(default_factory=list)

    def lines(self) -> list[str]:
        """The explanation as text, in a fixed order: rebuilt permutations by hash, fan-outs widest first."""
        if self.first:
            return [f"explain: {NO_EARLIER_BUILD} — all {self.total:,} permutations and the ubershader built"]
        if not self.rebuilt and self.ubershader is None:
            return [f"explain: nothing rebuilt — all {self.total:,} permutations up to date"]
        out = [f"explain: {len(self.rebuilt):,} of {self.total:,} permutations rebuilt"
               + (", and the ubershader" if self.ubershader is not None else "")]
        out += [f"  {h}  {self.ids[h]}: {'; '.join(map(str, cs))}" for h, cs in self.rebuilt.items()]
        if self.ubershader is not None:
            out.append(f"  ubershader: {'; '.join(map(str, self.ubershader))}")
        out.append("fan-out:")
        out += [f"  {c.label} → {n:,} of {self.total:,} permutations" + (" and the ubershader" if uber else "")
                for c, n, uber in self.fan_out]
        return out

    def as_dict(self) -> dict:
        def one(c: Change) -> dict:
            return {"input": c.what, "change": c.verb or "cause", "old": c.old, "new": c.new, "text": str(c)}

        def fan(c: Change) -> dict:
            return {"input": c.what, "change": c.verb or "cause", "text": c.label}
        return {"first_build": self.first, "permutations": self.total,
                "rebuilt": [{"hash": h, "id": self.ids[h], "changes": [one(c) for c in cs]}
                            for h, cs in self.rebuilt.items()],
                "ubershader": None if self.ubershader is None else [one(c) for c in self.ubershader],
                "fan_out": [{**fan(c), "permutations": n, "ubershader": uber} for c, n, uber in self.fan_out]}


@dataclass
class Rebuild:
    """What a build knew of the last one and of itself, to explain itself (Rebuild.explained) when asked."""

    old_text: bytes | None
    new: dict
    scene: object
    kept: set
    last: dict  # hash -> (input key, status) of the last manifest's entries
    had_manifest: bool
    uber_kept: bool
    last_uber: tuple | None
    keys: object

    def explained(self) -> Explained:
        new, scene = self.new, self.scene
        try:
            old = json.loads(self.old_text) if self.old_text is not None else None
        except ValueError:
            old = None
        if not isinstance(old, dict) or old.get("format") != FORMAT:
            old = None
        ids = {h: scene.permutations[h].canonical() for h in new["permutations"]}
        total = len(ids)
        if old is None and not self.had_manifest:
            return Explained(total, True, ids, {}, None)
        where = _shown(scene.path)
        base = _build_changes(old["build"], new["build"]) if old else []
        rebuilt = {}
        for h in sorted(ids):
            if h not in self.kept:
                rebuilt[h] = self._why(h, old, base, where)
        uber = None if self.uber_kept or not ids else self._why_uber(old, base)
        fan: dict[str, list] = {}  # a change's label -> [a change of it, permutations, ubershader?]
        for cs in rebuilt.values():
            for c in cs:
                fan.setdefault(c.label, [c, 0, False])[1] += 1
        for c in uber or []:
            fan.setdefault(c.label, [c, 0, False])[2] = True
        order = sorted(fan.items(), key=lambda kv: (-kv[1][1], kv[0]))
        return Explained(total, False, ids, rebuilt, uber, [tuple(v) for _, v in order])

    def _why(self, h: str, old: dict | None, base: list[Change], where: str) -> list[Change]:
        if h not in self.last:
            return [Change("not in the last build")]
        key, status = self.last[h]
        causes = [] if status == "ok" else [Change(f"did not build last time ({status})")]
        if key == self.keys.permutations[h]:
            return causes or [Change("its files were missing or damaged")]
        was = (old or {}).get("permutations", {}).get(h)
        if was is None:
            return causes + [Change("the last build left no record of its inputs")]
        changes = base + _brick_changes(_bricks(old, was), _bricks(self.new, self.new["permutations"][h])) \
            + _value_changes(old, self.new, was, self.new["permutations"][h], where)
        return causes + (sorted(set(changes), key=Change.order)
                         or [Change("an input the record does not itemize changed")])

    def _why_uber(self, old: dict | None, base: list[Change]) -> list[Change]:
        """The ubershader's key covers the build's inputs and every permutation's key and bricks (no scene value)."""
        if self.last_uber is None:
            return [Change("not in the last build")]
        key, status = self.last_uber
        causes = [] if status == "ok" else [Change(f"did not build last time ({status})")]
        if key == self.keys.ubershader:
            return causes or [Change("its files were missing or damaged")]
        if old is None:
            return causes + [Change("the last build left no record of its inputs")]
        was, now = old["permutations"], self.new["permutations"]
        changes = set(base)
        for h in sorted(set(was) & set(now)):
            changes.update(_brick_changes(_bricks(old, was[h]), _bricks(self.new, now[h])))
        added, gone = len(set(now) - set(was)), len(set(was) - set(now))
        if added or gone:
            changes.add(Change(f"the permutations it covers changed ({added} added, {gone} removed)"))
        return causes + (sorted(changes, key=Change.order) or [Change("an input the record does not itemize changed")])


def _build_changes(old: dict, new: dict) -> list[Change]:
    """What differs between two builds' own inputs (keys.build_inputs)."""
    out = []
    if old.get("generator") != new["generator"]:
        out.append(Change("generator version", old.get("generator"), new["generator"]))
    out += _dict_changes(old.get("sources", {}), new["sources"], lambda p: p)
    out += _dict_changes(old.get("tools", {}), new["tools"], lambda t: f"tool {t}")
    for what in ("languages", "platforms"):
        if old.get(what) != new[what]:
            out.append(Change(what, ", ".join(old.get(what) or []), ", ".join(new[what])))
    was = old.get("platform_tools", {})
    for p in sorted(set(was) & set(new["platform_tools"])):  # a platform added or dropped: said by "platforms"
        out += _dict_changes(was[p], new["platform_tools"][p], lambda t, p=p: f"tool {t} ({p})")
    return out


def _bricks(rec: dict, entry: dict) -> dict[str, str]:
    """{brick path: sha256} a record's permutation entry reads ({"its bricks' resolution": error} if none)."""
    if "error" in entry:
        return {"its bricks' resolution": entry["error"]}
    paths = rec.setdefault("paths", sorted(rec["bricks"]))  # the indices' order (kept: asked per permutation)
    return {paths[i]: rec["bricks"][paths[i]] for i in rec["brick_sets"][entry["bricks"]]}


def _brick_changes(old: dict, new: dict) -> list[Change]:
    return _dict_changes(old, new, lambda p: p)


def _dict_changes(old: dict, new: dict, name) -> list[Change]:
    return [Change(name(k), _show(old[k]) if k in old else None, _show(new[k]) if k in new else None)
            for k in sorted(set(old) | set(new)) if old.get(k) != new.get(k) or (k in old) != (k in new)]


def _value_changes(old: dict, new: dict, was: dict, now: dict, where: str) -> list[Change]:
    """The scene values a permutation's key reads that differ: its objects, their materials' and lights' fields."""
    out = []
    o_objs, n_objs = {o[0]: o for o in was["objects"]}, {o[0]: o for o in now["objects"]}
    if set(o_objs) != set(n_objs):
        out.append(Change(f"{where}: the objects drawn with it", ", ".join(sorted(o_objs)) or "none",
                          ", ".join(sorted(n_objs)) or "none"))
    for name in sorted(set(o_objs) & set(n_objs)):
        if o_objs[name] != n_objs[name]:
            out.append(Change(f"{where}: object '{name}'", _show(o_objs[name][1:]), _show(n_objs[name][1:])))
    for table, col in (("materials", 1), ("lights", 3)):
        names: set[str] = set()
        for o in [*was["objects"], *now["objects"]]:
            names.update([o[col]] if col == 1 else o[col])
        for name in sorted(names):
            if name in old.get(table, {}) and name in new[table]:
                out += _deep(old[table][name], new[table][name], f"{where}: {table}.{name}")
    return out


def _deep(old, new, path: str) -> list[Change]:
    """Each leaf of two plain values that differs, named by its dotted path (as the scene spells its tables)."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for k in sorted(set(old) | set(new)):
            if k not in old or k not in new:
                out.append(Change(f"{path}.{k}", _show(old[k]) if k in old else None,
                                  _show(new[k]) if k in new else None))
            else:
                out += _deep(old[k], new[k], f"{path}.{k}")
        return out
    return [] if old == new else [Change(path, _show(old), _show(new))]


def _show(v) -> str:
    """A value as a change shows it: a sha256 as its first 12 digits, anything else as JSON (at most 80 characters)."""
    if isinstance(v, str) and _HEX64.match(v):
        return f"sha256 {v[:12]}"
    text = v if isinstance(v, str) else json.dumps(v, sort_keys=True)
    return text if len(text) <= 80 else text[:77] + "..."


def _plain(x):
    """A scene value as JSON: a dataclass as its shown fields (those its repr, and so the key, holds)."""
    if x is None or isinstance(x, (str, int, float, bool)):  # most values: tested first
        return x
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return {f.name: _plain(getattr(x, f.name)) for f in dataclasses.fields(x) if f.repr and f.name != "name"}
    return repr(x)


def _shown(path) -> str:
    """The scene as the command line named it: relative to the working directory when inside it."""
    p = Path(path).resolve()
    try:
        return str(p.relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(p)
