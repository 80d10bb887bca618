"""`costs --diff OLD.json`: what a change cost, shader by shader, and its helped/hurt summary.

A shader is one row of a report: (table, subject, stage, language). The rows of this run are compared
with the rows of an earlier `costs --format json` report of the same shaders: every SPIR-V count, and
the RADV statistics (budget.py's names) of every AMD family both reports measured. The summary is that
of Mesa's shader-db (`report.py`): per count, the total over the shaders both reports have, before and
after, and the same over the shaders it changed in ("affected"), with the relative change; helped: the
shaders whose count went down (waves per SIMD: up, more occupancy), hurt: the reverse.
"""
from __future__ import annotations

from .budget import AT_LEAST, RADV_NAMES, SPIRV_NAMES, radv_value
from .report import _flat, _md_table, _value


def _key(d: dict) -> tuple:
    return d["table"], d["subject"], d["stage"], d["language"]


def _who(d: dict) -> str:
    return f"`{d['subject']}`" + (f" ({', '.join(d['objects'])})" if d.get("objects") else "")


def _families(rows: list[dict]) -> list[str]:
    return list(dict.fromkeys(f for d in rows for f in (d.get("gpu") or {})))


def _num(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _pct(before, after) -> str:
    if before == after:
        return "0.00%"
    return f"{(after - before) / before * 100:+.2f}%" if before else "n/a"


def _metrics(families):
    """(label, lower is better, value of a flat row) per compared count: SPIR-V's, then each family's RADV ones."""
    out = [(name, True, lambda d, n=name: d.get(n)) for name in SPIRV_NAMES]
    for f in families:
        out += [(f"{f} {name}", name not in AT_LEAST,
                 lambda d, f=f, n=name: radv_value((d.get("gpu") or {}).get(f), n)) for name in RADV_NAMES]
    return out


def summary(pairs, metrics) -> tuple[list[list[str]], list[str]]:
    """shader-db's helped/hurt lines per metric that changed in some shader, and the metrics that changed in none.

    pairs: (before, after) flat rows of the same shader."""
    lines, same = [], []
    for label, lower_better, get in metrics:
        vals = [(a, b) for a, b in ((get(x), get(y)) for x, y in pairs) if a is not None and b is not None]
        changed = [(a, b) for a, b in vals if a != b]
        if not changed:
            same.append(label)
            continue
        better = sum(1 for a, b in changed if (b < a) == lower_better)
        tb, ta = sum(a for a, _ in vals), sum(b for _, b in vals)
        cb, ca = sum(a for a, _ in changed), sum(b for _, b in changed)
        lines.append([label, f"{_num(tb)} → {_num(ta)}", _pct(tb, ta), f"{_num(cb)} → {_num(ca)}", _pct(cb, ca),
                      str(better), str(len(changed) - better)])
    return lines, same


def diff(rows, old: list[dict], old_name: str) -> str:
    """The Markdown report: the changed counts shader by shader, the shaders only one side has, the summary."""
    new = {_key(d): d for d in (_flat(r) | {"alu_t": _value(r, "alu_t"), "gpu": r.gpu} for r in rows)}
    before = {_key(d): d | {"alu_t": (d["alu"] + d["transcendental"]) if d.get("alu") is not None
                            and d.get("transcendental") is not None else None} for d in old}
    fam_new, fam_old = _families(list(new.values())), _families(list(before.values()))
    families = [f for f in fam_new if f in fam_old]
    metrics = _metrics(families)
    shared = sorted(new.keys() & before.keys())
    lines = []
    for k in shared:
        a, b = before[k], new[k]
        for label, _, get in metrics:
            x, y = get(a), get(b)
            if x is not None and y is not None and x != y:
                lines.append([f"{k[0]} {_who(b)}", k[2], k[3], label, _num(x), _num(y), _num(y - x)
                              if y < x else f"+{_num(y - x)}"])
    only = [f"- new: {k[0]} {_who(new[k])} {k[2]} {k[3]}" for k in sorted(new.keys() - before.keys())]
    only += [f"- gone: {k[0]} {_who(before[k])} {k[2]} {k[3]}" for k in sorted(before.keys() - new.keys())]
    out = [f"# Costs against {old_name}", "",
           f"{len({tuple(x[:3]) for x in lines})} shaders changed, {len(only)} new or gone, "
           f"{len(shared)} compared.", ""]
    if lines:
        out += _md_table(["shader", "stage", "language", "count", "before", "now", "change"], lines) + [""]
    out += only + ([""] if only else [])
    helped, same = summary([(before[k], new[k]) for k in shared], metrics)
    out += ["## Helped and hurt", "",
            f"As Mesa's shader-db reports a change: per count, the total over the {len(shared)} shaders both "
            "reports have (a shader: one stage in one language), before → after, and over the shaders the count "
            "changed in (affected); helped: shaders whose count went down (waves per SIMD: up), hurt: the "
            "reverse.", ""]
    if helped:
        out += _md_table(["count", "total before → after", "change", "affected before → after", "change",
                          "helped", "hurt"], helped) + [""]
    if same:
        out += [f"Unchanged in every shader: {', '.join(same)}.", ""]
    notes = [f"RADV figures of {', '.join(missing)} are in {side} alone (both need `--gpu`); not compared."
             for missing, side in (([f for f in fam_old if f not in fam_new], old_name),
                                   ([f for f in fam_new if f not in fam_old], "this run")) if missing]
    return "\n".join(out + notes + ([""] if notes else []))
