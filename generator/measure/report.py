"""Cost tables as Markdown, CSV or JSON, and why the three languages differ.

Markdown is for people: one row per subject, a cell holds one number when
GLSL, HLSL and WGSL agree and ``GLSL / HLSL / WGSL`` when they do not, laid
out like Hoffman & Baker 2006's "BRDF Costs" tables (texture, ALU) with
transcendental, branch and register columns, and the course's figure beside
ours where the model is in its table. CSV and JSON are for machines: one row
per subject and language. Output is deterministic (no timestamps, no paths).
"""
from __future__ import annotations

import csv
import io
import json
from collections import Counter

from .. import __version__
from ..analysis import COUNT_FIELDS
from ..toolchain import tool_versions
from .plans import REPORT_LANGUAGES, CourseModel, Row

LANGS_SLASH = " / ".join(x.upper() for x in REPORT_LANGUAGES)  # the order of every report's cells
LANGS_AND = ", ".join(x.upper() for x in REPORT_LANGUAGES[:-1]) + " and " + REPORT_LANGUAGES[-1].upper()

# Markdown columns: (header, Cost field or derived name).
MD_COLUMNS = [("tex", "texture"), ("ALU", "alu"), ("transc.", "transcendental"), ("ALU+T", "alu_t"),
              ("branches", "branches"), ("regs", "registers"), ("instr.", "instructions"),
              ("loads", "loads"), ("ALU ops", "alu_scalar")]
DIFF_FIELDS = ("texture", "alu", "transcendental", "branches", "registers", "instructions", "loads", "stores",
               "alu_scalar", "transcendental_scalar")
CSV_FIELDS = ["table", "subject", "kind", "stage", "language", *COUNT_FIELDS, "course_model", "course_table",
              "course_texture", "course_alu", "lights", "materials", "objects", "key", "measured", "baseline", "error"]

# Why the languages differ: (key, applies(language, stage, opcode delta vs the reference language,
# {count: {language: value}} of the counts that differ), explanation).
# Found by reading the disassembly (spirv-dis) of the example scene and the eval kernels.
EXPLANATIONS = [
    ("hlsl-row-major-mul",
     lambda lang, stage, d, m: lang == "hlsl" and bool(d.get("OpVectorTimesMatrix")),
     "glslang's HLSL front end keeps HLSL's row-major view of matrices: `mul(M, v)` becomes "
     "OpVectorTimesMatrix(v, M) (with an OpTranspose where the emitter built the matrix from columns as "
     "`transpose(float4x4(...))`). The scalar multiplies and adds are the same; the transpose is a register "
     "renaming, counted with the moves."),
    ("naga-column-loads",
     lambda lang, stage, d, m: lang == "wgsl" and stage == "vert" and d.get("OpLoad", 0) > 0,
     "The WGSL vertex template builds the normal matrix from `frame.model[0].xyz`, `[1].xyz`, `[2].xyz`; naga "
     "reads each column with its own access chain and load, where glslang loads the mat4 once and extracts "
     "the columns. More loads, the same arithmetic."),
    ("glsl-input-component-load",
     lambda lang, stage, d, m: lang != "glsl" and d.get("OpLoad", 0) < 0 and d.get("OpAccessChain", 0) < 0,
     "glslang reads a component of a GLSL input (`v_tangent.w`) with its own access chain and load next to "
     "the load of the whole vector (`v_tangent.xyz`), and `spirv-opt -O` does not merge the two; HLSL and "
     "WGSL entry points receive the input as a value, load it once and extract the component. One load "
     "more in GLSL, the same arithmetic."),
    ("late-output-stores",
     lambda lang, stage, d, m: lang != "glsl" and stage == "vert" and "registers" in m,
     "HLSL and WGSL vertex entry points return an output struct; glslang's HLSL wrapper and naga store its "
     "members only at the end, so every output stays live until the last instruction, where GLSL stores "
     "each output as soon as it is computed. The register estimate differs, the arithmetic does not."),
    ("naga-vector-construct",
     lambda lang, stage, d, m: lang == "wgsl" and d.get("OpCompositeExtract", 0) < 0,
     "naga builds a vector from a smaller vector and scalars in one OpCompositeConstruct (`vec4(v, 1.0)`); "
     "glslang first extracts every component. Moves only: instr. and other differ, ALU does not."),
]
SAME_INSTRUCTIONS = (
    "same-instructions",
    "The instruction counts agree in every language; only their order differs (each front end schedules its "
    "own way), which moves the peak of the register estimate. In a per-brick row, the with/without shaders "
    "may also differ alike in every language, which cancels in the counts but not in the peak.")
NO_EXPLANATION = ("unexplained", "No explanation recorded yet: compare `spirv-dis` of the shaders.")


def _value(row: Row, name: str):
    if row.cost is None:
        return None
    if name == "alu_t":
        return row.cost.alu + row.cost.transcendental
    return getattr(row.cost, name)


def group(rows: list[Row]) -> dict[tuple, dict[str, Row]]:
    """Rows by (table, subject, stage, measured) -> {language: row}, in first-seen order."""
    out: dict[tuple, dict[str, Row]] = {}
    for r in rows:
        out.setdefault((r.table, r.subject, r.stage, r.measured), {})[r.language] = r
    return out


def _cell(by_lang: dict[str, Row], name: str) -> str:
    vals = [_value(by_lang[lang], name) if lang in by_lang else None for lang in REPORT_LANGUAGES
            if lang in by_lang]
    shown = ["–" if v is None else str(v) for v in vals]
    return shown[0] if len(set(shown)) == 1 else " / ".join(shown)


def differences(rows: list[Row]) -> list[dict]:
    """Subjects whose counts differ between languages: which counts, which opcodes, and why."""
    out = []
    for (table, subject, stage, _), by_lang in group(rows).items():
        have = {lang: r for lang, r in by_lang.items() if r.cost is not None}
        if len(have) < 2:
            continue
        metrics = {f: {lang: getattr(r.cost, f) for lang, r in have.items()} for f in DIFF_FIELDS}
        metrics = {f: v for f, v in metrics.items() if len(set(v.values())) > 1}
        if not metrics:
            continue
        ref = "glsl" if "glsl" in have else sorted(have)[0]
        opcodes, why = {}, []
        for lang in (x for x in REPORT_LANGUAGES if x in have and x != ref):
            delta = Counter(have[lang].cost.opcodes)
            delta.subtract(have[ref].cost.opcodes)
            d = {k: v for k, v in sorted(delta.items()) if v}
            if d:
                opcodes[lang] = d
            why += [key for key, applies, _ in EXPLANATIONS if applies(lang, stage, d, metrics) and key not in why]
        if not why and not opcodes:
            why = [SAME_INSTRUCTIONS[0]]
        out.append({"table": table, "subject": subject, "stage": stage, "reference": ref, "metrics": metrics,
                    "opcodes": opcodes, "why": why or [NO_EXPLANATION[0]]})
    return out


def _explanation_texts() -> dict[str, str]:
    return {key: text for key, _, text in EXPLANATIONS} | dict([SAME_INSTRUCTIONS, NO_EXPLANATION])


def _course_cell(r: Row, per_light: bool) -> str:
    if r.course is None:
        return ""
    text = f"{r.course.texture} / {r.course.alu}"
    if per_light:
        return f"{text} per light ×{r.lights} ({r.course.model}, {r.course.table})"
    return text


def _md_table(header: list[str], lines: list[list[str]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(cells) + " |" for cells in lines]
    return out


def _metric_cells(by_lang: dict[str, Row]) -> list[str]:
    first = next(iter(by_lang.values()))
    if first.error:
        return ["error"] + [""] * (len(MD_COLUMNS) - 1)
    return [_cell(by_lang, name) for _, name in MD_COLUMNS]


LEGEND = [
    "Static counts from the optimized SPIR-V (`spirv-opt -O`) of each entry point. A cell holds one number "
    f"when {LANGS_AND} agree, otherwise {LANGS_SLASH}. tex, ALU, transc. (transcendental) and "
    "instr. count instructions (a vec3 operation is one); ALU ops is the scalarized ALU count (a vec3 add is "
    "3, a dot of vec3 5); regs is an estimate of the peak number of live 32-bit scalars. Rules: "
    "`generator/analysis/classify.py`, `generator/analysis/liveness.py`.",
    "",
    "Course: Hoffman & Baker 2006, \"BRDF Costs\" tables, texture / ALU for one point light in hand-counted "
    "pixel-shader instructions, where every arithmetic instruction (transcendentals too) is ALU: compare it "
    "with our ALU+T.",
]


def markdown(rows: list[Row], title: str, models: list[CourseModel] | None = None, gpu=None,
             course: bool = False, languages: bool = False, model_errors: dict | None = None) -> str:
    """The report as Markdown (per-permutation rows, or per-brick rows); gpu: the
    measure.gpu.GpuRequest that added RADV's figures, or None.

    course: the comparison with Hoffman & Baker 2006's tables (a column per permutation, the models'
    section per brick); languages: the section that explains where the languages differ."""
    from . import gpu as radv

    out = [f"# {title}", "", *LEGEND, ""]
    groups = group(rows)
    head = [h for h, _ in MD_COLUMNS]
    perm = [(k, v) for k, v in groups.items() if k[0] == "permutation"]
    if perm:
        out += ["## Per permutation", ""]
        lines = []
        for (_, subject, stage, _), by_lang in perm:
            r = next(iter(by_lang.values()))
            lines.append([f"`{subject}`", ", ".join(r.materials), ", ".join(r.objects), stage, *_metric_cells(by_lang)]
                         + ([_course_cell(r, per_light=True) if stage == "frag" else ""] if course else []))
        out += _md_table(["permutation", "materials", "objects", "stage", *head]
                         + (["course tex / ALU"] if course else []), lines)
        out += ["", *_totals(perm)]
        uber = [(k, v) for k, v in groups.items() if k[0] == "ubershader"]
        if uber:
            out += ["", "The scene's ubershader (every permutation in one shader; docs/design/link.md, \"The ubershader's data\"):", ""]
            out += _md_table(["shader", "stage", *head], [[f"`{k[1]}`", k[2], *_metric_cells(v)] for k, v in uber])
        out += ["", "Permutation keys:", ""]
        seen = []
        for (_, subject, _, measured), _ in perm:
            if subject not in seen:
                seen.append(subject)
                out.append(f"- `{subject}` `{measured}`")
        out.append("")
    bricks = [(k, v) for k, v in groups.items() if k[0] == "brick"]
    if bricks:
        out += ["## Per brick", "",
                "What a brick adds: the shader with the brick minus the same shader with a trivial stand-in "
                "of its kind (`generator/measure/plans.py` says which shader for each kind: eval kernels for BRDF "
                "terms and slot fillers, a one-light fragment shader for the others). Negative values: the "
                "brick lets the optimizer remove more than it adds.", ""]
        lines = [[next(iter(v.values())).kind, f"`{k[1]}`", *_metric_cells(v)] for k, v in bricks]
        out += _md_table(["kind", "brick", *head], lines) + [""]
    model_rows = [(k, v) for k, v in groups.items() if k[0] == "model"]
    if models is not None and course:
        out += ["## The course's models", "",
                "Whole BRDFs (`course_costs.toml`): shift-invariant = eval kernel of the spec minus the stand-in "
                "BRDF; shift-variant = one-light fragment shader with the textured packing minus stand-ins.", ""]
        lines = []
        for m in models:
            for fig in (m.invariant, m.variant):
                match = [v for k, v in model_rows if k[1] == m.name and
                         next(iter(v.values())).course == fig]
                ours = _metric_cells(match[0]) if match else ["no brick yet"] + [""] * (len(MD_COLUMNS) - 1)
                err = (model_errors or {}).get(m.name, {}).get(m.form)
                lines.append([m.name, m.form, fig.table, f"`{m.spec}`" if m.spec and match else "",
                              str(fig.texture), fig.alu, *ours, f"{err:.1e}" if err is not None else ""])
        out += _md_table(["model", "form", "table", "measured", "course tex", "course ALU", *head,
                          "error vs direct"], lines) + [""]
        if model_errors:
            out += ["Error vs direct: the factored form's float32 hemisphere max relative error against the direct "
                    "model's float64 reference (NumPy, `shadermatrix accuracy`'s hemisphere), the error its tables add.",
                    ""]
    out += radv.markdown(rows, groups, gpu)
    diffs = differences(rows) if languages else []
    if diffs:
        out += ["## Where the languages differ", ""]
        texts = _explanation_texts()
        used: list[str] = []
        for d in diffs:
            metrics = "; ".join(f"{f} {' / '.join(str(v.get(lang, '–')) for lang in REPORT_LANGUAGES)}"
                                for f, v in d["metrics"].items())
            ops = "; ".join(f"{lang} vs {d['reference']}: " + ", ".join(f"{k} {v:+d}" for k, v in o.items())
                            for lang, o in d["opcodes"].items())
            ops = f" {ops}." if ops else ""
            out.append(f"- `{d['subject']}` {d['stage']} — {metrics} ({LANGS_SLASH}).{ops} "
                       f"Why: {', '.join(d['why'])}.")
            used += [w for w in d["why"] if w not in used]
        out += [""] + [f"- **{key}**: {texts[key]}" for key in used] + [""]
    errors = [r for r in rows if r.error]
    if errors:
        out += ["## Errors", ""] + [f"- `{r.subject}` {r.language}: {r.error}" for r in errors] + [""]
    return "\n".join(out)


def _totals(perm: list) -> list[str]:
    """Per stage, over the scene's permutations (in the first language that has each): the counts summed, and
    the shader with the most registers."""
    out = []
    for stage in ("frag", "vert"):
        firsts = []
        for (_, subject, st, _), by_lang in perm:
            r = next((by_lang[lang] for lang in REPORT_LANGUAGES if lang in by_lang and by_lang[lang].cost), None)
            if st == stage and r is not None:
                firsts.append(r)
        if not firsts:
            continue
        sums = ", ".join(f"{h} {sum(_value(r, name) for r in firsts)}" for h, name in MD_COLUMNS
                         if name in ("texture", "alu", "transcendental", "branches", "instructions"))
        top = max(firsts, key=lambda r: _value(r, "registers"))
        out.append(f"Totals of the {len(firsts)} {stage} shaders: {sums}; the most registers: "
                   f"{_value(top, 'registers')} (`{top.subject}`, {top.language}).")
    return out + [""] if out else []


def _flat(r: Row) -> dict:
    """One row as columns that each mean one thing: `kind` a brick's kind (none for a shader of the scene),
    `key` a permutation's key, `measured` what a per-brick or model row compiled."""
    shader = r.table in ("permutation", "ubershader")
    d = {"table": r.table, "subject": r.subject, "kind": None if shader else r.kind, "stage": r.stage,
         "language": r.language}
    d.update({f: getattr(r.cost, f) if r.cost else None for f in COUNT_FIELDS})
    c = r.course
    d.update({"course_model": c.model if c else None, "course_table": c.table if c else None,
              "course_texture": c.texture if c else None, "course_alu": c.alu if c else None,
              "lights": r.lights or None, "materials": list(r.materials) or None, "objects": list(r.objects) or None,
              "key": r.measured if shader else None, "measured": None if shader else r.measured,
              "baseline": r.baseline or None, "error": r.error or None})
    return d


def to_csv(rows: list[Row]) -> str:
    """One line per subject and language (and RADV's figures as gpu_<family>_<statistic> columns)."""
    from . import gpu as radv
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=CSV_FIELDS + radv.csv_fields(rows), lineterminator="\n")
    w.writeheader()
    for r in rows:
        d = _flat(r) | radv.csv_values(r)
        d["objects"] = " ".join(d["objects"] or [])
        d["materials"] = " ".join(d["materials"] or [])
        w.writerow({k: ("" if v is None else v) for k, v in d.items()})
    return buf.getvalue()


def to_json(rows: list[Row], subject: str, models: list[CourseModel] | None = None, gpu=None,
            model_errors: dict | None = None) -> str:
    """Rows (with opcode histograms and RADV's figures), the language differences and their explanations."""
    from . import gpu as radv
    out_rows = []
    for r in rows:
        d = _flat(r)
        if r.gpu:
            d["gpu"] = r.gpu
        if r.cost is not None:
            d["opcodes"] = r.cost.as_dict()["opcodes"]
            d["loads_by_storage"] = r.cost.as_dict()["loads_by_storage"]
        out_rows.append(d)
    doc = {"generator": f"shadermatrix {__version__}", "tools": tool_versions(), "subject": subject,
           "languages": list(REPORT_LANGUAGES), "rows": out_rows, "differences": differences(rows),
           "explanations": _explanation_texts()}
    if gpu is not None:
        groups = group(rows)
        families = radv.families_of(rows)
        doc["gpu"] = {"families": list(gpu.families), "devices": gpu.devices or {}, "note": gpu.note or None,
                      "errors": gpu.errors or {}, "ubershader_load": radv.uber_load(groups, families),
                      "estimate_check": radv.estimate_check(rows, families)}
    if models is not None:
        doc["course"] = [{"model": m.name, "form": m.form, "spec": m.spec or None, "requires": list(m.requires),
                          "tables": {f.table: {"texture": f.texture, "alu": f.alu} for f in (m.invariant, m.variant)},
                          "error_vs_direct": (model_errors or {}).get(m.name, {}).get(m.form)}
                         for m in models]
    return json.dumps(doc, indent=2, allow_nan=False) + "\n"
