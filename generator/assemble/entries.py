"""A compiled chunk's manifest entries and files, made wherever the chunk was compiled, written by the build.

Making a permutation's entry (its head, bricks, interface, uploads, the languages' and platforms' items, the
platform dialects validated, the d3d12 binary step) is most of what writing a chunk costs; writing its files is
the rest. So the two are apart: `make` runs where the chunk was composed and compiled — in this process for an
in-process build, in the worker for `-j N` and on a Dask worker for `--executor dask://` — through a Recorder,
which records the files a Writer would write instead of writing them; the building process then `replay`s them
through its own Writer, in chunk order, and settles each entry (ok, or its last good entry kept, stale). One
code path makes every entry, so the bytes are the same wherever it ran.

What the workers need for it beside the build's context is an Entries value: the scene (its objects and their
values, for the uploads) and every permutation's input key, sent once per build.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field

from ..lang import SourceError
from ..link.uber import coverage
from ..link.values import uploads
from ..scene.load import Scene
from .manifest import CHECK_ENV, output_state, render_state
from .write import Writer, validate_dialects


@dataclass
class Made:
    """One permutation's entry as made (not yet settled), the errors that fail it, and the files to write:
    (path in the output, bytes or None, whether it is a SPIR-V module that identical ones share: None for one the
    chunk made already, written once)."""

    entry: dict
    errors: list[str]
    files: list[tuple[str, bytes | None, bool]]
    # a permutation that built: its entry as the manifest's text holds it, cut where its sampler descriptors are
    # (split_text), and those descriptors, in order, each with its text (_hole)
    text: list[str] | None = None
    holes: list[tuple] | None = None


@dataclass
class Entries:
    """What a permutation's entry is made of besides its compiled unit (sent to the workers once per build)."""

    scene: Scene
    keys: dict[str, str]  # permutation hash -> input key
    uber_key: str = ""  # the ubershader's input key
    users: dict[str, list[dict]] = field(default_factory=dict)  # hash -> the objects drawn with it

    def __post_init__(self):
        if not self.users:
            for o in self.scene.objects:
                self.users.setdefault(o["permutation"], []).append(o)

    def _environments(self) -> dict | None:
        """The SH9 values of the scene's environments (assemble/environments.py), computed once per process."""
        if not self.scene.environment_of:
            return None
        if "_env" not in self.__dict__:
            from .environments import values
            self.__dict__["_env"] = values(self.scene)
        return self.__dict__["_env"]

    def __getstate__(self):  # the users are the scene's objects again: not sent twice
        return {"scene": self.scene, "keys": self.keys, "uber_key": self.uber_key}

    def __setstate__(self, state):
        self.__init__(state["scene"], state["keys"], state["uber_key"])

    def head(self, library, h: str) -> dict:
        """What the entry of permutation h says before anything is composed (a failed one keeps this much)."""
        perm = self.scene.permutations[h]
        head = {"id": perm.canonical(), "hash": h, "input_key": self.keys[h],
                "objects": self.scene.users.get(h, []), "languages": {}, "render_state": render_state(perm.surface)}
        out = library.get("output", perm.output)  # None: an unknown brick, which fails the permutation
        if out is not None:
            head["output"] = output_state(out)
        return head

    def make(self, ctx, pairs, part: dict, costs: dict) -> dict[str, Made]:
        """{hash: Made} of a compiled chunk: pairs, its (hash, Composed) in chunk order; part, its compile results by
        job key; costs, the SPIR-V costs by sha256 (filled in with any not analysed yet)."""
        checked = validate_dialects(pairs, ctx.store, ctx.gate) if ctx.dialects else {}
        out, rec = {}, Recorder(ctx, costs)
        for h, c in pairs:
            rec.files = []
            entry = {**self.head(ctx.library, h), "bricks": dict(sorted(c.bricks.items())),
                     "interface": c.interface.as_dict(), "uploads": uploads(self.scene, h, c, self.users.get(h, []),
                                                                       self._environments())}
            errs = rec.unit(h, c.sources, part, entry)
            if not errs:
                errs = rec.platforms(h, c, entry, checked, self.scene.permutations[h].precision)
                if errs:  # failed_sources stays: a failing GL core source is written beside (write_platforms)
                    entry.pop("platforms", None)
                    entry["languages"] = {}
            text = holes = None
            if not errs:  # as the build settles it (status ok), encoded here: most of writing the manifest
                entry["status"] = "ok"
                entry.pop("failed_sources", None)
                text, holes = split_text(entry)
            out[h] = Made(entry, errs, rec.files, text, holes)
        return out


    def ubershader(self, ctx, unit, results: dict, costs: dict) -> Made | None:
        """The ubershader's entry as made from `unit` (compose_ubershader's) and its compile results; None without
        permutations. The build fails, naming the value, when an axis value of the matrix is not reachable in it."""
        if unit is None:
            return None
        if isinstance(unit, str):
            return Made({"input_key": self.uber_key, "languages": {}}, [unit], [])
        c, u = unit
        perms = [p for _, p in sorted(self.scene.permutations.items())]
        entry = {"input_key": self.uber_key, "hash": c.hash, "languages": {}, "tables": u.tables(),
                 "interface": c.interface.as_dict()}
        rec = Recorder(ctx, costs)
        errs = [f"coverage: {p}" for p in coverage(u, perms, ctx.library)]
        errs += rec.unit("ubershader", c.sources, results, entry)
        return Made(entry, errs, rec.files)


_HOLE = "\0shadermatrix: a sampler descriptor\0"
_PLACE = "\0shadermatrix: the permutations\0"
_STATE = "sampler_state"


def _indented(entry: dict) -> str:
    """A permutation entry as json.dumps(manifest, indent=2) writes it inside the manifest's list."""
    return json.dumps(entry, indent=2).replace("\n", "\n    ")


def split_text(entry: dict) -> tuple[list[str], list[tuple]]:
    """(The entry's text (_indented) cut where each sampler descriptor of its platforms' reflections stands, those
    descriptors in the text's order, each with its text as it is when made: _hole). The build sets a light or table sampler's ``sampler_state`` in them once the
    scene's samplers are numbered (texture_outputs.py), after the entry was made: they are encoded then, the rest
    of the entry here."""
    from .texture_outputs import _sampler_descriptors  # what texture_outputs may change: the same rows
    holes: list[dict] = []
    platforms = {}
    for name, p in (entry.get("platforms") or {}).items():
        refl = (p or {}).get("reflection")
        wanted = {id(d) for d in _sampler_descriptors(refl)}
        if not wanted:
            platforms[name] = p
            continue
        cut = {}
        for k, v in refl.items():
            if isinstance(v, list) and any(id(d) in wanted for d in v):
                holes += [d for d in v if id(d) in wanted]
                v = [_HOLE if id(d) in wanted else d for d in v]
            cut[k] = v
        platforms[name] = {**p, "reflection": cut}
    text = _indented({**entry, "platforms": platforms} if holes else entry)
    parts = text.split(json.dumps(_HOLE))
    assert len(parts) == len(holes) + 1
    return parts, [_hole(d, before) for d, before in zip(holes, parts)]


def _hole(d: dict, before: str) -> tuple[dict, str | None, int]:
    """(A sampler descriptor, its text where it stands as it is now, how many keys it has now). The build adds
    ``sampler_state`` to it later, after the others (texture_outputs.py): its text is then this one with that
    key spliced in (_descriptor), not encoded again by json's indented encoder, which is Python (~12 descriptors a
    permutation). None: one that has a state already, encoded whole at the end."""
    if not d or _STATE in d:
        return d, None, len(d)
    return d, _encode(d, before[before.rfind("\n") + 1:]), len(d)


def _encode(d, indent: str) -> str:
    return json.dumps(d, indent=2).replace("\n", "\n" + indent)


def _descriptor(hole: tuple[dict, str | None, int], indent: str) -> str:
    d, text, n = hole
    if text is not None:
        if len(d) == n:  # no state given
            return text
        if len(d) == n + 1 and next(reversed(d)) == _STATE:  # the one key the build adds, after the others
            close = text.rindex("\n")  # the descriptor's closing brace, on a line of its own
            return (f"{text[:close]},\n{indent}  {json.dumps(_STATE)}: {_encode(d[_STATE], indent + '  ')}"
                    f"{text[close:]}")
    return _encode(d, indent)


def _joined(parts: list[str], holes: list[tuple]) -> str:
    out = [parts[0]]
    for hole, after in zip(holes, parts[1:]):
        indent = out[-1][out[-1].rfind("\n") + 1:]  # where the descriptor stands: its line's indentation
        out += [_descriptor(hole, indent), after]
    return "".join(out)


def encode_manifest(manifest: dict, texts: dict) -> bytes:
    """json.dumps(manifest, indent=2) + "\n", as bytes, taking each permutation entry's text from `texts` (hash ->
    (the entry, its Made.text, its Made.holes)) where it is that very entry: json's indented encoder is Python, and
    encoding the entries is most of what writing the manifest costs, so the workers encode them (split_text). An
    entry is not changed once settled but for its sampler descriptors' states, which are encoded here. With
    SHADERMATRIX_CHECK_MANIFEST set (the tests), the text is compared with json.dumps's."""
    perms = manifest["permutations"]
    if not perms:
        return (json.dumps(manifest, indent=2) + "\n").encode()
    parts = []
    for e in perms:
        known = texts.get(e.get("hash"))
        parts.append(_joined(known[1], known[2]) if known is not None and known[0] is e else _indented(e))
    shell = json.dumps({**manifest, "permutations": _PLACE}, indent=2)
    placed = json.dumps(_PLACE)
    assert shell.count(placed) == 1
    text = shell.replace(placed, "[\n    " + ",\n    ".join(parts) + "\n  ]") + "\n"
    if os.environ.get(CHECK_ENV) and text != json.dumps(manifest, indent=2) + "\n":
        raise AssertionError("the manifest's text is not json.dumps(manifest, indent=2): an entry changed after its "
                             "text was made (entries.split_text)")
    return text.encode()


def compose_ubershader(scene: Scene, lib, languages):
    """(Composed, Uber) of the scene's ubershader, the compose error as text, or None without permutations."""
    from ..compose.uber import compose_ubershader as compose
    perms = [p for _, p in sorted(scene.permutations.items())]
    if not perms:
        return None
    try:
        return compose(perms, lib, languages)
    except SourceError as e:
        return str(e)


# Past this many material variants one ubershader is a shader no engine wants to wait for, and its compile grows
# faster than the variants do: measured on this machine, the 10,000-permutation generated scene's 9,526 variants
# made 12 MB of GLSL (38 MB of SPIR-V) whose glslc and spirv-opt were still running after 45 minutes each, where
# the 1,000-permutation benchmark scene's take up to a minute a shader (benchmarks/results/build.md).
UBER_VARIANTS_WARN = 1000


def ubershader_warning(scene: Scene) -> str | None:
    """A located warning when the scene's ubershader would stand in for more than UBER_VARIANTS_WARN material
    variants ((BRDF, packing, output) combinations: link/uber.py Variant.key); None otherwise or when it is off."""
    if not scene.ubershader:
        return None
    variants = len({(p.brdf, p.packing, p.output) for p in scene.permutations.values()})
    if variants <= UBER_VARIANTS_WARN:
        return None
    line, col = scene.head_at
    return (f"{scene.path}:{line}:{col}: the ubershader would hold {variants:,} material variants in one shader, "
            f"whose compile grows faster than their number (more than {UBER_VARIANTS_WARN:,} is slow to compile) — "
            "set `ubershader = false` in [scene] where no engine draws this scene's fallback, or split the scene")


class _Counts:
    """The part of a BuildResult a Recorder's Writer methods touch: the costs (the chunk's), nothing counted."""

    def __init__(self, costs: dict):
        self.costs, self.written, self.unchanged, self.aliased = costs, 0, 0, 0


class Recorder(Writer):
    """A Writer that records the files it would write (`files`) instead of writing them."""

    def __init__(self, ctx, costs: dict):
        super().__init__(None, ctx, _Counts(costs))
        self.files: list[tuple[str, bytes | None, bool]] = []
        self._sent: set[str] = set()  # the shared modules of this chunk recorded with their bytes

    def put(self, rel: str, data: bytes) -> None:
        self.files.append((rel, data, False))

    def put_shared(self, rel: str, data: bytes) -> None:
        self.files.append((rel, None if rel in self._sent else data, True))  # its bytes travel once per chunk
        self._sent.add(rel)


def replay(writer: Writer, files) -> None:
    """Write a Made's files through the build's writer, as the Writer would have written them."""
    for rel, data, shared in files:
        (writer.put_shared if shared else writer.put)(rel, data)  # a shared module without bytes: written already
