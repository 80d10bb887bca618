"""docs/reference/manifest.md from the manifest's JSON Schema (generator/assemble/manifest.schema.json).

The schema is the one place each field of manifest.json is described: this module only renders it, one
section per object (`$defs` entry, in the order a reader meets them from the top level), one row per field
with its type and its description. `check_example_build()` builds scenes/example.toml with --pack and
validates its manifest against the schema, so `make reference` cannot publish a page the build contradicts.
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SCHEMA_PATH = "generator/assemble/manifest.schema.json"


def schema() -> dict:
    from generator.assemble.manifest import schema as shipped
    return shipped()


def schema_text() -> str:
    """The schema's bytes as shipped (docs/reference/manifest.schema.json is a copy)."""
    return (REPO / SCHEMA_PATH).read_text(encoding="utf-8")


def example_manifest(out: Path) -> dict:
    """Build scenes/example.toml with --pack into `out` (the pinned tools needed) and read its manifest."""
    cmd = [sys.executable, "-m", "generator.cli", "build", str(REPO / "scenes" / "example.toml"), "--out", str(out),
           "--pack", "-q"]
    r = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"building scenes/example.toml failed (exit {r.returncode}):\n{r.stderr[-3000:]}")
    return json.loads((out / "manifest.json").read_text())


def check_example_build() -> list[str]:
    """Where the example build's manifest does not match the schema (nothing, when they agree)."""
    from generator.assemble.manifest import problems
    with tempfile.TemporaryDirectory(prefix="shadermatrix-reference-") as tmp:
        return [f"manifest.json {p} — describe it in {SCHEMA_PATH}, then run `make reference`"
                for p in problems(example_manifest(Path(tmp)))]


# ------------------------------------------------------------------------------------------- rendering

def _anchor(title: str) -> str:
    return re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


def _cell(text: str) -> str:
    """Text in a table cell: newlines joined, pipes escaped, `<` outside code spans kept literal."""
    parts = " ".join(text.split()).split("`")
    return "`".join(p if i % 2 else p.replace("<", "&lt;") for i, p in enumerate(parts)).replace("|", "\\|")


def _ref(node: dict) -> str | None:
    ref = node.get("$ref", "")
    return ref.rsplit("/", 1)[1] if ref.startswith("#/$defs/") else None


def _refs(node) -> list[str]:
    """The $defs a schema node names, in document order (items, alternatives, map values included)."""
    if isinstance(node, list):
        return [r for x in node for r in _refs(x)]
    if not isinstance(node, dict):
        return []
    own = [_ref(node)] if _ref(node) else []
    return own + [r for k, v in node.items() if k not in ("$defs", "if", "then") for r in _refs(v)]


def _reachable(s: dict) -> list[str]:
    order: list[str] = []

    def visit(name: str) -> None:
        if name in order:
            return
        order.append(name)
        for r in _refs(s["$defs"][name] if name else {k: v for k, v in s.items() if k != "$defs"}):
            visit(r)

    visit("")
    return order[1:]


def _type(node: dict, defs: dict) -> str:
    """A field's type in words: a link to the object's section, a list of …, the values it may take."""
    if (r := _ref(node)) is not None:
        return f"[{defs[r]['title']}](#{_anchor(defs[r]['title'])})"
    for key in ("oneOf", "anyOf"):
        if key in node:
            return " or ".join(_type(x, defs) for x in node[key])
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    if "enum" in node:
        return " \\| ".join(f"`{json.dumps(v)}`" for v in node["enum"])
    t = node.get("type")
    if t == "array":
        return "list of " + (_type(node["items"], defs) if "items" in node else "nothing") + \
            (" (empty)" if node.get("maxItems") == 0 else "")
    if t == "object" and node.get("maxProperties") == 0:
        return "`{}`"
    if t == "string" and "pattern" in node:
        return f"string `{node['pattern']}`"
    return t or "any"


def _rows(d: dict, defs: dict) -> list[str]:
    rows = []
    required = set(d.get("required", ()))
    for k, p in d.get("properties", {}).items():
        mark = "" if k in required else " *(optional)*"
        rows.append(f"| `{k}`{mark} | {_type(p, defs)} | {_cell(p['description'])} |\n")
    extra = d.get("additionalProperties")
    if isinstance(extra, dict):
        names = d.get("propertyNames", {})
        key = f"`<{names.get('title', 'name')}>`"
        if "enum" in names:
            key += " (" + ", ".join(f"`{v}`" for v in names["enum"]) + ")"
        rows.append(f"| {key} | {_type(extra, defs)} | {_cell(extra['description'])} |\n")
    return rows


def render(head: str) -> str:
    s = schema()
    defs = s["$defs"]
    out = [head, f"What a build writes to DIR/manifest.json, field by field: the JSON Schema (draft 2020-12) "
           f"[manifest.schema.json](manifest.schema.json) (shipped in the package as `{SCHEMA_PATH}`) rendered "
           "as tables. Every object is closed: a field not listed here is an error to a loader that validates. "
           "A field marked *(optional)* is written only when its description says; `<name>` stands for a key "
           "that is a name (a material's, a stage, a tool). The format's rules: "
           "[design/manifest.md](../design/manifest.md).\n",
           f"\n## {s['title']}\n\n{_cell(s['description'])}\n\n| field | type | meaning |\n|---|---|---|\n",
           *_rows(s, defs)]
    reached = _reachable(s)
    for name in reached:
        d = defs[name]
        out.append(f"\n## {d['title']}\n\n" + (f"{_cell(d['description'])}\n\n" if d.get("description") else ""))
        out.append("| field | type | meaning |\n|---|---|---|\n")
        out += _rows(d, defs)
    unreached = sorted(set(defs) - set(reached))
    if unreached:
        raise SystemExit(f"{SCHEMA_PATH}: $defs {', '.join(unreached)} are not reachable from the top level — "
                         "name them from a field or remove them")
    return "".join(out)
