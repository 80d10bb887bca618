"""Generate docs/reference/ from the code: the CLI, the brick catalogue, the brick language, the manifest.

    .venv/bin/python scripts/gen_reference.py [DIR]     (`make reference`; DIR defaults to docs/reference)

Every page is a pure function of the code it documents (the argparse parser of generator/cli/, what
`shadermatrix bricks --json` prints, the tables of generator/lang/ and generator/library/, the manifest's
JSON Schema generator/assemble/manifest.schema.json, rendered by scripts/reference_manifest.py and copied
beside the page), so the output is deterministic: no times, no
absolute paths, no terminal width. tests/project/test_docs_reference.py regenerates into a temporary directory and
fails on any difference. Before the manifest page is written, scenes/example.toml is built (with --pack)
into a temporary directory and its manifest.json must validate against the schema (--no-build skips that
check, which needs the pinned tools).
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import reference_manifest  # noqa: E402  (this script's sibling: the manifest's schema as a page)
import reference_frame  # noqa: E402  (likewise: the frame export's schema)

COMMAND = "make reference"
PAGES = ("README.md", "cli.md", "bricks.md", "language.md", "manifest.md", "manifest.schema.json", "frame.md")
HANDWRITTEN = ("pack-h.md",)  # pages beside them written by hand (tests elsewhere check them), listed in the index
WIDTH = 100  # the usage lines' width: fixed, so the page does not depend on the terminal


def header(title: str, source: str) -> str:
    return (f"# {title}\n\n<!-- Generated from {source} by `{COMMAND}` (scripts/gen_reference.py); "
            "do not edit: tests/project/test_docs_reference.py fails when it is stale. -->\n\n")


def cell(text) -> str:
    """Text in a Markdown table cell: newlines joined, pipes escaped, and `<` outside code spans kept literal
    (not read as an HTML tag)."""
    s = " ".join(("" if text is None else str(text)).split())
    parts = s.split("`")
    return "`".join(p if i % 2 else p.replace("<", "&lt;") for i, p in enumerate(parts)).replace("|", "\\|")


def code(text) -> str:
    """Inline code in a table cell (a pipe inside it still needs escaping in GitHub's tables)."""
    s = " ".join(str(text).split())
    return f"`{s}`".replace("|", "\\|") if s else ""


def table(head: list[str], rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out) + "\n"


def anchor(title: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


# ------------------------------------------------------------------------------------------------ CLI

def _subcommands(p: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _usage(p: argparse.ArgumentParser) -> str:
    f = p.formatter_class(prog=p.prog, width=WIDTH)
    f.add_usage(p.usage, p._actions, p._mutually_exclusive_groups)
    return f.format_help().strip()


def _expanded_help(p: argparse.ArgumentParser, action: argparse.Action) -> str:
    if not action.help:
        return ""
    return p.formatter_class(prog=p.prog, width=WIDTH)._expand_help(action)


def _argument(action: argparse.Action) -> str:
    if not action.option_strings:
        return code(action.metavar or action.dest) + (" (optional)" if action.nargs in ("?", "*") else "")
    takes = action.nargs != 0
    meta = action.metavar or (("{" + ",".join(map(str, action.choices)) + "}") if action.choices
                              else action.dest.upper())
    return ", ".join(code(f"{o} {meta}" if takes else o) for o in action.option_strings) + \
        (" (required)" if action.required else "")


def _default(action: argparse.Action) -> str:
    d = action.default
    if d is None or d is argparse.SUPPRESS or d is False or d == []:
        return ""
    return code(json.dumps(d) if not isinstance(d, str) else d)


def render_cli() -> str:
    from generator.cli import EXIT_CODES, parser
    p = parser()
    subs = _subcommands(p)
    out = [header("Command-line reference", "the argument parser of generator/cli/"),
           f"`shadermatrix` — {cell(p.description.split(': ', 1)[-1])}\n\n",
           "Every command takes `-h`/`--help`; `shadermatrix --version` prints the version. A brick directory "
           "given with `--bricks DIR` adds to the shipped bricks/.\n\n## Commands\n\n"]
    out.append(table(["command", "what it does"],
                     [[f"[`{n}`](#{anchor('shadermatrix ' + n)})", cell(sp.description)] for n, sp in subs.items()]))
    out.append("\n## Exit codes\n\nThe same for every command:\n\n```text\n"
               + EXIT_CODES.split("\n", 1)[1] + "\n```\n")
    for name, sp in subs.items():
        out.append(f"\n## shadermatrix {name}\n\n{cell(sp.description)}\n\n```text\n{_usage(sp)}\n```\n\n")
        rows = [[_argument(a), cell(_expanded_help(sp, a)), _default(a)]
                for a in sp._actions if not isinstance(a, argparse._HelpAction)]
        if rows:
            out.append(table(["argument", "meaning", "default"], rows))
        else:
            out.append("No arguments.\n")
    return "".join(out)


# --------------------------------------------------------------------------------------------- bricks

def _value(v) -> str:
    return code(json.dumps(v)) if v is not None else ""


def render_bricks() -> str:
    from generator.cli.commands.bricks import rows
    from generator.library.bricks import load_library
    from generator.library.kinds import KINDS
    catalogue = json.loads(json.dumps(rows(load_library(())), sort_keys=False))  # what `bricks --json` prints
    by_kind: dict[str, list[dict]] = {}
    for r in catalogue:
        by_kind.setdefault(r["kind"], []).append(r)
    kinds = [k for k in KINDS if k in by_kind] + sorted(set(by_kind) - set(KINDS))
    out = [header("Brick catalogue", "`shadermatrix bricks --json`"),
           f"{len(catalogue)} bricks of {len(kinds)} kinds ship in bricks/. `shadermatrix bricks` prints this "
           "catalogue (`--json`: machine-readable; `--bricks DIR` adds a directory of your own). What each kind "
           "of brick takes and returns: [language.md](language.md#kind-contracts).\n\n"]
    out.append(table(["kind", "bricks"], [[f"[{k}](#{anchor('kind ' + k)})",
                                           ", ".join(f"[`{r['id']}`](#{anchor(r['id'] + ' ' + k)})"
                                                     for r in by_kind[k])] for k in kinds]))
    for k in kinds:
        doc = KINDS[k].doc if k in KINDS else ""
        out.append(f"\n## kind {k}\n\n{cell(doc)}\n")
        for r in by_kind[k]:
            out.append(f"\n### {r['id']} ({k})\n\n{cell(r['summary'])}\n\n- source: `{r['path']}`\n")
            if r["cite"]:
                out.append(f"- cite: {cell(r['cite'])}\n")
            if r["textures"]:
                out.append(f"- textures: {', '.join(code(t) for t in r['textures'])}\n")
            if r["slots"]:
                out.append("\n" + table(["slot", "kind", "default", "fillers"],
                                        [[code(s), v["kind"], code(v["default"]) if v["default"] else "none (optional: empty unless filled)",
                                          ", ".join(code(f) for f in v["fillers"])]
                                         for s, v in r["slots"].items()]))
            if r["params"]:
                out.append("\n" + table(["parameter", "type", "range", "default", "meaning"],
                                        [[code(n), code(p["type"]), _value(p["range"]), _value(p["default"]),
                                          cell(p["doc"])] for n, p in r["params"].items()]))
    return "".join(out)


# ------------------------------------------------------------------------------------------- language

def intrinsic_rules() -> dict[str, tuple[str, str]]:
    """{typing rule: (signature, notes)} from the intrinsics table's module docstring (the one place they are
    written: `  name   f(T) -> T   notes`, notes continued on deeper-indented lines); a rule the table uses
    without a description there is an error."""
    from generator.lang import intrinsics
    doc = intrinsics.__doc__.split("Typing rules (`sig`):", 1)[1].split("\n\n", 1)[0]
    rules: dict[str, list[str]] = {}
    last = None
    for line in doc.splitlines():
        m = re.match(r"^  (\w+)\s+(.*)$", line)
        if m:
            last = m.group(1)
            rules[last] = [p.strip() for p in re.split(r"\s{2,}", m.group(2).strip(), maxsplit=1)]
        elif line.strip() and last:
            rules[last].append(line.strip())
    used = {row["sig"] for row in intrinsics.INTRINSICS.values()}
    missing = sorted(used - set(rules))
    if missing:
        raise SystemExit(f"generator/lang/intrinsics.py: typing rule(s) {', '.join(missing)} used by INTRINSICS "
                         "but not described in the module docstring — describe them there")
    return {k: (v[0], " ".join(v[1:])) for k, v in rules.items()}


def _types_section() -> str:
    from generator.lang import types
    groups: dict[str, list[str]] = {k: [] for k in ("scalar", "vector", "matrix", "texture")}
    for name, t in types.BUILTIN_TYPES.items():
        groups.setdefault(t.kind, []).append(name)
    rows = [[kind, ", ".join(code(n) for n in names)] for kind, names in groups.items()]
    rows += [["array", code("array[T, N]") + ": a fixed-capacity array of a scalar, vector, matrix or struct, N ≥ 1"],
             ["struct", "a struct a brick declares (a class with annotated fields)"],
             ["buffer", f"{code('storage_buffer[S]')} (runtime-sized, read-only) and {code('uniform_buffer[S, N]')}: "
                        "global resources only, S a struct"]]
    leaves = ", ".join(code(x) for x in types.BUFFER_LEAVES)
    return ("\n## Types\n\n" + table(["kind", "types"], rows)
            + f"\nA buffer's element struct has only {leaves} leaves (directly, in nested structs or in fixed arrays "
            "of those), so std140, std430, HLSL and WGSL layouts agree byte for byte. A `texture2d_shadow` is a "
            "depth texture read only through its comparison sampler, by `sample_compare`. `texture2d_array`, "
            "`texturecube_array` and `texture2d_array_shadow` are arrays of layers: each sampling intrinsic takes an "
            "`int` or `uint` layer after the coordinate, clamped to [0, layers - 1] in every target (GLSL ES 3.10, "
            "the gl platform's `essl` dialect, has no cube arrays).\n")


def _intrinsics_section() -> str:
    from generator.lang.intrinsics import CONSTANTS, INTRINSICS
    rules = intrinsic_rules()
    rows = [[code(n), code(rules[r["sig"]][0]), cell(rules[r["sig"]][1]), code(r["sig"]), r["cls"]]
            for n, r in INTRINSICS.items()]
    consts = [[code(n), code(repr(v))] for n, v in CONSTANTS.items()]
    return ("\n## Intrinsics\n\nThe functions every brick may call (generator/lang/intrinsics.py). `T` is a float "
            "scalar or vector unless the rule says otherwise; where a rule takes `T`, a float scalar given for a vector "
            "is splatted. The cost class is what `shadermatrix costs` counts it as.\n\n"
            + table(["intrinsic", "signature", "notes", "typing rule", "cost class"], rows)
            + "\n### Constants\n\nNamed constants usable in every brick (float64 values, emitted with 9 or more "
            "digits).\n\n" + table(["constant", "value"], consts))


def _kinds_section() -> str:
    from generator.library.kinds import KINDS
    rows = []
    for k in KINDS.values():
        entries = []
        for e in k.entries:
            args = ", ".join(f"{a.name}: {a.ty}" + (" (required)" if a.required else "") for a in e.args)
            entries.append(code(f"{e.name}({args}) -> {e.ret}") + (" (optional)" if e.optional else ""))
        if k.prefix_entries:
            entries.append(code(f"{k.prefix_entries}<input>() -> <the input's type>"))
        reads = "[shading inputs](#shading-inputs)" if k.reads == "shading" else "[surface inputs](#surface-inputs)"
        rows.append([code(k.name), cell(k.doc), "; ".join(entries), reads, "yes" if k.slot else ""])
    return ("\n## Kind contracts\n\nWhat each kind of brick's entry functions take and return "
            "(generator/library/kinds.py). An entry's parameters are bound by name: an argument of the contract "
            "(passed positionally, in the contract's order), an input the kind reads, or a parameter or texture the "
            "brick declares. An optional argument may be left out of an entry; a required one must be declared. A "
            "slot kind fills a slot of a host brick and is called from the host.\n\n"
            + table(["kind", "what it is", "entries", "reads", "slot"], rows))


def _inputs_section() -> str:
    from generator.library.inputs import INPUTS, NV_MIN, SURFACE_INPUTS
    rows = []
    for i in INPUTS:
        flags = ", ".join(f for f, on in (("tangent frame", i.tangent), ("internal", i.internal)) if on)
        rows.append([code(i.name), code(i.ty), code(i.expr) if i.expr else "given", cell(i.guard),
                     cell(i.why), flags])
    surf = [[code(s.name), code(s.ty), code(s.interpolant) if s.interpolant else "computed", cell(s.why)]
            for s in SURFACE_INPUTS]
    return ("\n## Shading inputs\n\nWhat a BRDF term or slot filler may name as a parameter "
            "(generator/library/inputs.py); the glue computes each from the rows before it. `given` rows come from "
            f"the caller (samples, interpolants, the light loop). n·v is clamped to [{NV_MIN:g}, 1]; f_r is 0 for "
            "n·l ≤ 0. Tangent-frame rows need a permutation with tangents; internal rows are intermediates of the "
            "glue, not readable by bricks.\n\n"
            + table(["input", "type", "expression", "guard", "why", "notes"], rows)
            + "\n## Surface inputs\n\nWhat light, shadow, packing and normal bricks read, and the interpolant that "
            "carries it.\n\n" + table(["input", "type", "interpolant", "what it is"], surf))


def _meta_section() -> str:
    from generator.library.schema import BRICK_SCHEMA

    def kind(s: dict) -> str:
        if "enum" in s:
            return " or ".join(code(json.dumps(x)) for x in s["enum"])
        if "anyOf" in s:
            return "a number or (nested) list of numbers"
        t = s.get("type", "")
        if t == "object" and "additionalProperties" in s and isinstance(s["additionalProperties"], dict):
            inner = s["additionalProperties"].get("properties", {})
            return "a dict of name → {" + ", ".join(inner) + "}" if inner else "a dict"
        if t == "array":
            return f"a list of {s.get('items', {}).get('type', 'value')}s"
        return t

    required = set(BRICK_SCHEMA.get("required", ()))
    rows = [[code(k), kind(s), "yes" if k in required else ""] for k, s in BRICK_SCHEMA["properties"].items()]
    return ("\n## BRICK metadata\n\nEvery brick file defines a `BRICK` dict literal (checked against "
            "generator/library/schema.py before its meaning). Names that reach generated code (parameters, slots, "
            "textures, slot defaults) are identifiers of at most 64 characters.\n\n"
            + table(["key", "value", "required"], rows))


def render_language() -> str:
    return (header("The brick language", "generator/lang/ and generator/library/")
            + "A brick is a Python-syntax file that is parsed, type-checked and translated, never imported. This "
              "page lists what the language offers and what each kind of brick must provide.\n"
            + _types_section() + _intrinsics_section() + _kinds_section() + _inputs_section() + _meta_section())


# -------------------------------------------------------------------------------------------- the index

def render_index() -> str:
    return (header("Reference", "the code")
            + "Pages generated from the code, so they cannot drift from it.\n\n"
            + table(["page", "what it lists"], [
                ["[cli.md](cli.md)", "every command, its options with their help text, the exit codes"],
                ["[bricks.md](bricks.md)", "the shipped bricks: kind, slots, parameters (type, range, default), "
                                           "citation"],
                ["[language.md](language.md)", "the brick language: types, intrinsics, constants, kind contracts, "
                                               "shading and surface inputs, BRICK metadata"],
                ["[manifest.md](manifest.md)", "every field of a build's manifest.json, from its JSON Schema "
                                               "[manifest.schema.json](manifest.schema.json)"],
                ["[frame.md](frame.md)", "every field of `render --export`'s frame.json (meshes, matrices, camera), "
                                         "from its JSON Schema"]])
            + f"\nRegenerate them with `{COMMAND}` after changing the code they describe.\n"
            + "\nWritten by hand (tests/native/ compiles its example and checks what it says):\n\n"
            + table(["page", "what it documents"], [
                ["[pack-h.md](pack-h.md)", "`include/shadermatrix/pack.h`, the C reader of the shader packs: how to "
                                           "include it, every function and status, what opening a pack checks"]]))


def render_all() -> dict[str, str]:
    return {"README.md": render_index(), "cli.md": render_cli(), "bricks.md": render_bricks(),
            "language.md": render_language(),
            "manifest.md": reference_manifest.render(header("manifest.json", reference_manifest.SCHEMA_PATH)),
            "manifest.schema.json": reference_manifest.schema_text(),
            "frame.md": reference_frame.render(header("Frame export", reference_frame.SCHEMA_PATH))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("dir", nargs="?", default=str(REPO / "docs" / "reference"), help="where to write the pages")
    ap.add_argument("--no-build", action="store_true",
                    help="skip building scenes/example.toml to validate its manifest against the schema")
    args = ap.parse_args(argv)
    from generator.io import atomic_write
    pages = render_all()
    if not args.no_build:
        problems = reference_manifest.check_example_build() + reference_frame.check_example_export()
        if problems:
            print("\n".join(problems), file=sys.stderr)
            return 1
    out = Path(args.dir)
    for name, text in pages.items():
        atomic_write(out / name, text.encode())
    print(f"{len(pages)} pages in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
