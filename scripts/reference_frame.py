"""docs/reference/frame.md from the frame export's JSON Schema (generator/runtime/frame.schema.json).

The schema is the one place each field of `render --export`'s frame.json is described; this module renders it:
one section per object of the document (the top level, then each nested object by its path), one row per field
with its type and its description. `check_example_export()` renders scenes/example.toml with --export and
validates the frame.json it writes, so `make reference` cannot publish a page the renderer contradicts.
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from reference_manifest import _cell

REPO = Path(__file__).resolve().parent.parent
SCHEMA_PATH = "generator/runtime/frame.schema.json"


def schema() -> dict:
    return json.loads((REPO / SCHEMA_PATH).read_text(encoding="utf-8"))


def check_example_export() -> list[str]:
    """Where the example's frame export does not match the schema (nothing, when they agree)."""
    from generator.runtime.frame_export import check_document
    with tempfile.TemporaryDirectory(prefix="shadermatrix-reference-") as tmp:
        cmd = [sys.executable, "-m", "generator.cli", "render", str(REPO / "scenes" / "example.toml"), "--mode",
               "specialized", "--frames", "1", "--size", "32x20", "--out", f"{tmp}/out", "--export", f"{tmp}/frame"]
        r = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
        if r.returncode != 0:
            return [f"rendering scenes/example.toml with --export failed (exit {r.returncode}): {r.stderr[-2000:]}"]
        try:
            check_document(json.loads(Path(tmp, "frame", "frame.json").read_text()))
        except ValueError as e:
            return [f"{e} — describe it in {SCHEMA_PATH}, then run `make reference`"]
    return []


def _object(node: dict) -> dict | None:
    """The object a field holds: itself, a list's items, or a map's values (None for a plain value)."""
    if node.get("type") == "object" and ("properties" in node or isinstance(node.get("additionalProperties"), dict)):
        return node
    items = node.get("items")
    return items if isinstance(items, dict) and _object(items) is not None else None


def _anchor(path: str) -> str:
    """GitHub's anchor of the section titled by `path` (its heading drops the leading dot; punctuation goes)."""
    return "".join(c for c in path.lower() if c.isalnum() or c in "-_")


def _type(node: dict, path: str) -> str:
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    if "enum" in node:
        return " \\| ".join(f"`{json.dumps(v)}`" for v in node["enum"])
    t = node.get("type")
    if isinstance(t, list):
        return " or ".join(t)
    if _object(node) is not None:
        what = f"[object](#{_anchor(path)})"
        return f"list of {what}" if t == "array" else what
    if t == "array":
        n = node.get("minItems")
        return f"list of {node['items'].get('type', 'any')}" + (f" ({n})" if n and n == node.get("maxItems") else "")
    return t or "any"


def _sections(node: dict, path: str, out: list[str]) -> None:
    obj = _object(node)
    if obj is None:
        return
    rows, nested = [], []
    required = set(obj.get("required", ()))
    for k, p in obj.get("properties", {}).items():
        mark = "" if k in required else " *(optional)*"
        rows.append(f"| `{k}`{mark} | {_type(p, f'{path}.{k}')} | {_cell(p['description'])} |\n")
        nested.append((p, f"{path}.{k}" + ("[]" if p.get("type") == "array" else "")))
    extra = obj.get("additionalProperties")
    if isinstance(extra, dict):
        rows.append(f"| `<name>` | {_type(extra, f'{path}.(name)')} | {_cell(extra['description'])} |\n")
        nested.append((extra, f"{path}.(name)"))
    title = path.lstrip(".") or "frame.json"
    out.append(f"\n## {title}\n\n" + (f"{_cell(obj['description'])}\n\n" if obj.get("description") else "")
               + "| field | type | meaning |\n|---|---|---|\n" + "".join(rows))
    for p, sub in nested:
        _sections(p, sub, out)


def render(head: str) -> str:
    s = schema()
    out = [head, "What `shadermatrix render --export DIR` writes to DIR/frame.json, field by field: the JSON Schema "
           f"(draft 2020-12) shipped in the package as `{SCHEMA_PATH}`, rendered as tables. Every object is closed. "
           "Matrices are a mat4's 16 numbers in column-major order. The guide: "
           "[guide/render.md](../guide/render.md#the-frame-export).\n"]
    _sections(s, "", out)
    return "".join(out)
