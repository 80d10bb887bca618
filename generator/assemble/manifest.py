"""manifest.json's format: its version, its JSON Schema (package data), and the pipeline state and platform
conventions it states (runtime/pipeline_state.py is their one statement, shared with the renderer).

The schema (manifest.schema.json beside this module, JSON Schema draft 2020-12) is the one description of
every field: docs/reference/manifest.md is generated from it, and an engine's loader can validate against
the same file. Every object in it is closed (``additionalProperties: false``): a loader that rejects what it
does not know can trust it, and a field the build writes without describing it fails validation.
Format 1 grows only by optional fields; removing, renaming or retyping one is format 2 (docs/design/manifest.md).

The build validates what it is about to write when ``SHADERMATRIX_CHECK_MANIFEST`` is set (the tests set it
for every build they run, in process and in the commands they start): a manifest that does not match is a
generator bug, reported before it replaces the last one. Outside the tests it is not checked, as the IR is
not without ``--validate-ir``: the schema describes what the code writes, and the tests hold them together.
"""
from __future__ import annotations

import functools
import json
import os
from importlib import resources

from ..lang.errors import UserError
from ..runtime.pipeline_state import frame_block, object_block, output_state, render_state  # noqa: F401 (the build's)

FORMAT_VERSION = 1
SCHEMA_FILE = "manifest.schema.json"
CHECK_ENV = "SHADERMATRIX_CHECK_MANIFEST"


class ManifestSchemaError(UserError):
    """The manifest a build was about to write does not match its schema (a generator bug, or a hand-edited
    manifest whose entries the build kept)."""


def material_states(scene, tables: dict) -> dict:
    """`tables` (assemble/reflection.py scene_tables) with each material's render state added."""
    materials = {name: {**entry, "render_state": render_state(scene.materials[name].surface,
                                                              entry["params"].get("alpha_cutoff"))}
                 for name, entry in tables["materials"].items()}
    return {**tables, "materials": materials}


def conventions(platforms) -> dict:
    """The manifest's ``conventions``: what the Object block holds (runtime/pipeline_state.py), and per platform
    written its clip space, front face, cull modes, attachment formats and the Object block's binding, in its
    API's words (each platform class's declarations: assemble/platform_base.py conventions_section)."""
    from .platforms import PLATFORM_TABLE
    return {"frame_block": frame_block(), "object_block": object_block(), "platforms": {p: PLATFORM_TABLE[p].conventions_section() for p in platforms}}


@functools.lru_cache(maxsize=1)
def schema() -> dict:
    """The JSON Schema of manifest.json (package data: found beside this module wherever it is installed)."""
    return json.loads(resources.files(__package__).joinpath(SCHEMA_FILE).read_text(encoding="utf-8"))


@functools.lru_cache(maxsize=1)
def _validator():
    from jsonschema import Draft202012Validator
    Draft202012Validator.check_schema(schema())
    return Draft202012Validator(schema())


def problems(manifest: dict) -> list[str]:
    """Every place `manifest` does not match the schema, as `/json/pointer: what`, in document order."""
    found = [_deepest(e) for e in _validator().iter_errors(manifest)]
    found.sort(key=lambda e: [str(p) for p in e.absolute_path])
    return [f"/{'/'.join(str(p) for p in e.absolute_path)}: {e.message}" for e in found]


def _deepest(e):
    """For a value that matches none of its alternatives (oneOf, anyOf): the error of the alternative that went
    deepest into it, which names the field at fault rather than the whole value."""
    while e.context:
        e = max(e.context, key=lambda c: len(c.absolute_path))
    return e


def check(manifest: dict) -> None:
    """Validate `manifest` against the schema when CHECK_ENV asks for it; raise ManifestSchemaError if it fails."""
    if not os.environ.get(CHECK_ENV):
        return
    found = problems(manifest)
    if found:
        shown = found[:20] + ([f"… and {len(found) - 20} more"] if len(found) > 20 else [])
        raise ManifestSchemaError(
            f"manifest.json does not match format {FORMAT_VERSION}'s schema (generator/assemble/{SCHEMA_FILE}) — "
            "describe a new field in the schema (docs/design/manifest.md says how), or write what it describes; "
            "the last manifest is left as it was:\n  " + "\n  ".join(shown))
