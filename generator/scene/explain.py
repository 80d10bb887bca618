"""How a scene's matrix is pruned, stage by stage, and why each axis value is kept or dropped.

The axes of a scene's matrix are the values its declarations name: the BRDFs,
packings and surface states (alpha, sidedness, vertex colours, emission) of its materials, the light configurations of its light sets (light
brick and shadow filter per light, in order), its output transform and its
precision. Four counts:

1. full product — every combination of the axes' values;
2. valid — the combinations the bricks' constraints allow (CONSTRAINTS: a packing
   that provides a parameter the BRDF does not read, a BRDF that reads the
   tangent frame from a packing that supplies none, a packing that provides a
   parameter with another type);
3. used — the permutations the scene's objects draw (material × light set);
4. merged — used permutations whose optimized SPIR-V is identical in every
   language and stage are one shader (needs a build; its cache makes it cheap).

What each axis value costs: the permutations it adds (the used permutations that carry it: each carries one
value per axis, so the scene has these only because of it) and, from a build through the compile cache, the
compile time of the shaders only those permutations use (what dropping the value would save: a shader shared
with other permutations is compiled for them anyway), summed from the times the cache records per shader
(toolchain/cache.py). A record stored before times were kept has none: the report counts those shaders.

The constraints are data (spec/constraints.py): one Constraint per rule, each a
predicate over a permutation's resolved bricks with the message and the fix it
gives (Filament's variant filters, Unity's stripping log made readable);
tests/scene/test_explain.py holds their truth table.
"""
from __future__ import annotations

from itertools import product

from ..io.bulk import collector_paused
from ..lang import SourceError
from ..library.bricks import Library
from ..spec.constraints import CONSTRAINTS
from ..spec.permutation import Permutation
from ..spec.resolve import resolve
from .light_sets import set_keys
from .load import Scene


def violations(perm: Permutation, lib: Library) -> list[tuple[str, str]]:
    """(constraint name, why) for every constraint the permutation breaks; [] when it may exist."""
    try:
        r = resolve(perm, lib)
    except SourceError as e:  # bricks that cannot share one material (a parameter's type or range clashes)
        return [("parameter policy", str(e))]
    return [(c.name, why) for c in CONSTRAINTS if (why := c.problem(r)[0])]


def _first_seen(values) -> list:
    return list(dict.fromkeys(values))


def axes(scene: Scene) -> dict[str, list]:
    """The values each axis takes in the scene's declarations, in declaration order."""
    configs = _first_seen(set_keys(scene, n) for n in scene.light_sets)  # dynamic sets: their model
    return {"brdf": _first_seen(m.brdf for m in scene.materials.values()),
            "packing": _first_seen(m.packing for m in scene.materials.values()),
            "surface": _first_seen(m.surface for m in scene.materials.values()),
            "lights": configs, "output": [scene.output], "precision": [scene.precision]}


def _surface_text(surface) -> str:
    """A surface state as the key writes it, without the leading ';' ('default' at the defaults)."""
    return surface.canonical().lstrip(";") or "default"


def _lights_text(config) -> str:
    return ",".join(k.canonical() for k in config) or "-"


def report(scene: Scene, lib: Library, spirv: dict[str, tuple] | None = None,
           shaders: dict[str, dict[str, float | None]] | None = None) -> dict:
    """The pruning report as data. spirv: {permutation hash: identity of its optimized SPIR-V (every language
    and stage)} from a build, or None to leave the merged stage out. shaders: {permutation hash: {cache key:
    recorded compile seconds or None}} of every shader of it, from the same build, or None: no compile costs."""
    with collector_paused():  # every BRDF × packing pair resolved, and kept in the library's memo: io/bulk.py
        return _report(scene, lib, spirv, shaders)


def _report(scene: Scene, lib: Library, spirv: dict[str, tuple] | None, shaders: dict | None) -> dict:
    ax = axes(scene)
    full = 1
    for values in ax.values():
        full *= len(values)
    pairs = {}
    for brdf, packing in product(ax["brdf"], ax["packing"]):
        pairs[(brdf, packing)] = violations(Permutation(brdf, (), packing, scene.output, scene.precision), lib)
    valid_pairs = [k for k, v in pairs.items() if not v]
    valid = len(valid_pairs) * len(ax["surface"]) * len(ax["lights"]) * len(ax["output"]) * len(ax["precision"])

    materials_of: dict[str, list[str]] = {}
    for o in scene.objects:
        ms = materials_of.setdefault(o["permutation"], [])
        if o["material"] not in ms:
            ms.append(o["material"])
    used = len(scene.permutations)

    stages = [{"stage": "full product", "count": full,
               "of": " × ".join(f"{len(v)} {k}" for k, v in ax.items())},
              {"stage": "valid", "count": valid,
               "of": f"{len(valid_pairs)} of {len(pairs)} BRDF × packing pairs pass the constraints, "
                     f"× {len(ax['surface'])} surface states × {len(ax['lights'])} light configurations"},
              {"stage": "used", "count": used, "of": f"{len(scene.objects)} objects draw {used} distinct permutations; "
                                                     f"{valid - used:,} valid combinations are drawn by no object"}]
    merged_into: dict[str, str] = {}
    if spirv is not None:
        first: dict[tuple, str] = {}
        for h in scene.permutations:
            ident = spirv.get(h)
            if ident is None:
                continue
            merged_into[h] = first.setdefault(ident, h)
        stages.append({"stage": "merged", "count": len(set(merged_into.values())),
                       "of": "used permutations with identical optimized SPIR-V in every language and stage "
                             "are one shader"})

    values, users = [], _users(shaders)
    declared, drawn = _by_value(scene)
    for axis, vals in ax.items():
        for v in vals:
            if axis in declared:
                key = v
                mats, hs = declared[axis].get(v, []), drawn[axis].get(key, [])
            else:
                mats, hs = [], list(scene.permutations)
            objs = [o for h in hs for o in scene.users.get(h, [])]
            if objs:
                why = f"kept: drawn by {len(objs)} object(s) ({_names(objs)}) in {len(hs)} permutation(s)"
            elif not mats:
                why = "dropped: the scene has no object"
            elif axis == "lights":
                why = f"dropped: light set(s) {_names(mats)} are lit on no object"
            else:
                why = f"dropped: material(s) {_names(mats)} are drawn by no object"
            text = _lights_text(v) if axis == "lights" else _surface_text(v) if axis == "surface" else v
            values.append({"axis": axis, "value": text, "kept": bool(objs), "why": why, "declared_by": mats,
                           "permutations": hs, "adds": len(hs), **_cost(hs, shaders, users)})
    invalid = [{"brdf": b, "packing": p, "why": [f"{n}: {w}" for n, w in pairs[(b, p)]]}
               for (b, p) in pairs if pairs[(b, p)]]
    perms = [{"hash": h, "key": p.canonical(), "materials": materials_of.get(h, []), "objects": scene.users.get(h, []),
              **({"merged_into": merged_into[h]} if h in merged_into and merged_into[h] != h else {})}
             for h, p in scene.permutations.items()]
    return {"scene": scene.name, "stages": stages, "axes": values, "invalid": invalid, "permutations": perms,
            "constraints": [{"name": c.name, "doc": c.doc} for c in CONSTRAINTS], "notes": list(scene.notes),
            "compile_records": _records(shaders)}


def _by_value(scene: Scene) -> tuple[dict, dict]:
    """({axis: {value: the materials (light sets, for lights) declaring it}}, {axis: {value: the permutations
    carrying it}}), both in declaration order: one pass each, not one per value (a scene of 10,000 materials has
    6,000 BRDFs)."""
    declared: dict[str, dict] = {"brdf": {}, "packing": {}, "surface": {}, "lights": {}}
    drawn: dict[str, dict] = {axis: {} for axis in declared}
    for m in scene.materials.values():
        for axis, v in (("brdf", m.brdf), ("packing", m.packing), ("surface", m.surface)):
            declared[axis].setdefault(v, []).append(m.name)
    for n in scene.light_sets:
        declared["lights"].setdefault(set_keys(scene, n), []).append(n)
    for h, p in scene.permutations.items():
        for axis, v in (("brdf", p.brdf), ("packing", p.packing), ("surface", p.surface), ("lights", p.lights)):
            drawn[axis].setdefault(v, []).append(h)
    return declared, drawn


def _users(shaders: dict | None) -> dict[str, set]:
    """{cache key: the permutations whose shaders have it}."""
    users: dict[str, set] = {}
    for h, keys in (shaders or {}).items():
        for k in keys:
            users.setdefault(k, set()).add(h)
    return users


def _cost(hs: list[str], shaders: dict | None, users: dict[str, set]) -> dict:
    """The compile seconds of the shaders only permutations `hs` use (by cache key: one compile serves every job
    of a key), and how many of those have no recorded time; {} without a build's shaders."""
    if shaders is None:
        return {}
    mine = set(hs)
    own = {k: t for h in hs for k, t in shaders.get(h, {}).items() if users[k] <= mine}
    return {"compile_seconds": round(sum(t for t in own.values() if t is not None), 3), "shaders": len(own),
            "untimed": sum(1 for t in own.values() if t is None)}


def _records(shaders: dict | None) -> dict | None:
    """The compile-time records the costs come from: distinct shaders, those with a time, their sum."""
    if shaders is None:
        return None
    times = {k: t for keys in shaders.values() for k, t in keys.items()}
    known = [t for t in times.values() if t is not None]
    return {"shaders": len(times), "timed": len(known), "seconds": round(sum(known), 3)}

def _costs_note(records: dict | None) -> str:
    head = ("adds: the used permutations that carry the value (the scene has them only because of it); compile s: "
            "the recorded compile time of the shaders only those permutations use (what dropping the value saves)")
    if records is None:
        return head + " — not known without a build (--no-compile): the times come from the compile cache's records."
    missing = records["shaders"] - records["timed"]
    return (head + f" — from the compile cache's records of {records['timed']:,} of {records['shaders']:,} distinct "
            f"shaders ({records['seconds']:.2f} s in all)"
            + (f"; {missing:,} have no recorded time (cached before times were recorded: `shadermatrix cache clear` "
               "and build again to time them)" if missing else "") + ".")


def _seconds(v: dict) -> str:
    if "compile_seconds" not in v:
        return "—"
    if v["shaders"] and v["untimed"] == v["shaders"]:
        return "?"
    return f"{v['compile_seconds']:.2f}" + ("+?" if v["untimed"] else "")


def _names(xs, limit: int = 6) -> str:
    xs = list(xs)
    return ", ".join(xs[:limit]) + (f" and {len(xs) - limit} more" if len(xs) > limit else "")


def markdown(rep: dict, explain: bool) -> str:
    out = [f"# The matrix of scene {rep['scene']}", "", "| stage | permutations | how |", "|---|---:|---|"]
    out += [f"| {s['stage']} | {s['count']:,} | {s['of']} |" for s in rep["stages"]]
    if not explain:
        return "\n".join(out) + "\n"
    out += ["", "## Axis values", "", _costs_note(rep.get("compile_records")), "",
            "| axis | value | kept | adds | compile s | why |", "|---|---|---|---:|---:|---|"]
    out += [f"| {v['axis']} | `{v['value']}` | {'yes' if v['kept'] else 'no'} | {v['adds']:,} | {_seconds(v)} | "
            f"{v['why']} |" for v in rep["axes"]]
    out += ["", "## Combinations the constraints forbid", ""]
    out += ([f"- `{x['brdf']}` with `{x['packing']}`: {'; '.join(x['why'])}" for x in rep["invalid"]]
            or ["None: every BRDF × packing pair of the scene is valid."])
    out += ["", "Constraints (generator/spec/constraints.py): "
            + "; ".join(f"`{c['name']}` — {c['doc']}" for c in rep["constraints"]) + "."]
    if rep.get("notes"):  # what an importer (glTF) accepted without shading it, or left out
        out += ["", "## Importer notes: what was mapped, accepted or left out", ""] + [f"- {n}" for n in rep["notes"]]
    out += ["", "## Permutations and their objects", "", "| permutation | materials | objects | merged into | key |",
            "|---|---|---|---|---|"]
    out += [f"| `{p['hash']}` | {', '.join(p['materials'])} | {', '.join(p['objects'])} | "
            f"{('`' + p['merged_into'] + '`') if 'merged_into' in p else ''} | `{p['key']}` |"
            for p in rep["permutations"]]
    return "\n".join(out) + "\n"
