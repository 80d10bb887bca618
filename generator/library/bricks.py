"""Brick discovery, the metadata schema, kinds and their entry contracts, and slots.

A brick is one file under a brick directory; its id is the file stem, its kind
comes from its BRICK metadata. Bricks are parsed (generator.lang), never imported.
"""
from __future__ import annotations

import difflib
import re
import itertools
from dataclasses import dataclass, field
from pathlib import Path

from ..lang import Signature, SourceError, parse_module
from ..lang.parse import MAX_BRICK_BYTES, read_meta_node
from ..lang.errors import read_text
from ..lang import ir
from ..lang.exprs import F32_MAX
from ..lang.types import BUILTIN_TYPES, INT, Type, array
from .inputs import BY_NAME, SHADING, SURFACE
from .kinds import KINDS
from .sampling import slot_sampling_externals, split_sampling

BRDF_ARRAY_KINDS = ("diffuse", "specular", "ndf", "fresnel", "visibility")

REPO = Path(__file__).resolve().parents[2]  # a clone's root (installed: the folder that holds generator/)
# The built-in bricks: package data beside this module when installed from a wheel (setup.py maps the
# repository's bricks/ there), else the clone's bricks/ (an editable install runs from the clone).
_INSTALLED_BRICKS = Path(__file__).resolve().parent / "bricks_data"
BUILTIN_BRICKS = _INSTALLED_BRICKS if _INSTALLED_BRICKS.is_dir() else REPO / "bricks"


PARAM_TYPES = ("float", "vec2", "vec3", "vec4", "mat4")
META_KEYS = {"kind", "params", "slots", "needs", "cite", "textures", "doc", "fp16", "tolerance", "encodes",
             "reciprocal"}


@dataclass
class Param:
    name: str
    ty: Type
    default: object
    range: tuple | None
    doc: str = ""


@dataclass
class Brick:
    """One parsed brick file."""

    id: str
    kind: str
    path: Path
    display_path: str
    module: ir.Module
    params: dict[str, Param]
    slots: dict[str, dict]  # slot name -> {"kind": k, "default": filler id} or {"kind": k, "optional": True}
    textures: dict[str, dict]
    cite: str
    doc: str
    # "fp16": "unsafe: why" where the brick cannot be made safe in half (build warns for an fp16
    # permutation using it); "" or any other note ("guarded: ...") otherwise
    fp16: str = ""
    # the float32 hemisphere max relative error the brick's approximation (a baked table, a fit) is chosen
    # for: `accuracy` passes it up to max(tolerance, --fail-above); 0: exact up to rounding
    tolerance: float = 0.0
    # an output brick's: what its colour is, "linear" radiance or display-encoded ("srgb", "sqrt"), which decides
    # the colour attachment that stores it (runtime/pipeline_state.py); "linear" unless the brick says otherwise
    encodes: str = "linear"
    # the sampling entries (sample, pdf; an NDF's sample_h, pdf_h) and the helpers only they call, in file order:
    # kept out of `module` so that shading programs never link them (library/sampling.py)
    sampling: dict[str, ir.Function] = field(default_factory=dict)
    # "no: why" where the model is not reciprocal (plausibility skips that check, saying why); "" otherwise
    reciprocal: str = ""

    @property
    def fp16_unsafe(self) -> str:
        """Why the brick is unsafe in fp16 ("" when it is not marked unsafe)."""
        note = self.fp16.strip()
        if not note.lower().startswith("unsafe"):
            return ""
        return note.partition(":")[2].strip() or "marked unsafe"

    @property
    def entries(self) -> list[ir.Function]:
        k = KINDS[self.kind]
        if k.prefix_entries:
            return [f for n, f in self.module.functions.items() if n.startswith(k.prefix_entries)]
        return [self.module.functions[e.name] for e in k.entries if e.name in self.module.functions]


_SERIALS = itertools.count(1)


@dataclass
class Library:
    """Every brick found, by (kind, id)."""

    bricks: dict[tuple[str, str], Brick] = field(default_factory=dict)
    errors: list[SourceError] = field(default_factory=list)
    memo: dict = field(default_factory=dict)  # what later stages derive from these bricks (linked programs)
    serial: int = field(default_factory=lambda: next(_SERIALS))  # names this library in other caches; never reused
    dirs: tuple = ()  # the brick directories it was loaded from (a build's depfile lists them)

    def get(self, kind: str, brick_id: str) -> Brick | None:
        b = self.bricks.get((kind, brick_id))
        if b is None:
            self._refuse_broken(brick_id)
        return b

    def of_kind(self, kind: str) -> list[Brick]:
        return sorted((b for (k, _), b in self.bricks.items() if k == kind), key=lambda b: b.id)

    def _refuse_broken(self, brick_id: str) -> None:
        """A lookup of a brick that did not load (load_library(strict=False)) raises that brick's own located
        error: the brick is reached, so its error is the build's. Matched by id (the file stem) alone: a brick
        that does not load may not even say its kind."""
        for e in self.errors:
            if Path(e.path).stem == brick_id:
                raise e

    def tables(self) -> dict[str, dict]:
        """{texture name: its declaration, "brick" and the brick's "tolerance"} of every texture a brick declares as a baked table
        (one per name: load_library refuses two different tables under one name)."""
        return {name: {**d, "brick": b.id, "tolerance": b.tolerance}
                for b in sorted(self.bricks.values(), key=lambda b: (b.kind, b.id))
                for name, d in b.textures.items() if d.get("table")}

    def find(self, brick_id: str, kinds) -> list[Brick]:
        found = [self.bricks[(k, brick_id)] for k in kinds if (k, brick_id) in self.bricks]
        if not found:
            self._refuse_broken(brick_id)
        return found


def display(path: Path, root: Path | None = None) -> str:
    """A path as shown in messages, provenance, #line directives and the manifest: relative to the repo when
    inside it, else to the brick directory's parent (an engine's ``/src/engine/bricks/x.py`` is
    ``bricks/x.py``), so that no absolute path of this machine reaches an output and moving a brick
    directory changes nothing that is built. A built-in brick is ``bricks/…`` wherever the package is installed."""
    path = path.resolve()
    try:
        return str(Path("bricks", path.relative_to(BUILTIN_BRICKS)))
    except ValueError:
        pass
    try:
        return str(path.relative_to(REPO))
    except ValueError:
        pass
    if root is not None:
        try:
            return str(path.relative_to(Path(root).resolve().parent))
        except ValueError:
            pass
    return str(path)


def load_library(extra_dirs=(), strict: bool = True) -> Library:
    """Parse every brick in bricks/ and the extra directories (an engine's own bricks).

    strict: the first brick that does not load raises its located error. Otherwise (a build: a broken brick no
    permutation reaches must not fail it) the errors are kept in ``errors`` and the brick is left out; looking
    it up by id (Library.get, Library.find: what resolving a scene does) raises its error then."""
    dirs = [BUILTIN_BRICKS, *[Path(d) for d in extra_dirs]]
    lib = Library(dirs=tuple(dirs))
    for d in dirs:
        if not d.is_dir():
            raise SourceError(str(d), 1, 1, "brick directory not found", "check the path of the extra brick directory")
        for path in sorted(d.rglob("*.py")):
            try:
                b = load_brick(path, shown=display(path, d))
            except SourceError as e:
                if strict:
                    raise
                lib.errors.append(e)
                continue
            other = lib.bricks.get((b.kind, b.id))
            if other is not None:
                raise SourceError(b.display_path, 1, 1, f"{b.kind} brick '{b.id}' is also defined in {other.display_path}",
                                  "rename one of the files (the file stem is the brick id)")
            lib.bricks[(b.kind, b.id)] = b
    _check_table_names(lib)
    return lib


def _table_key(d: dict):
    return (d.get("table"), tuple(d.get("size") or ()), d.get("format")) if d.get("table") else None


def _check_table_names(lib: Library) -> None:
    """Textures are bound by name (glue, ubershader, renderer, build): two bricks may share a texture name only
    when both mean the same thing — no table, or the same table at the same size and format."""
    seen: dict[str, Brick] = {}
    for b in sorted(lib.bricks.values(), key=lambda b: (b.kind, b.id)):
        for name, d in b.textures.items():
            other = seen.setdefault(name, b)
            if other is not b and _table_key(other.textures[name]) != _table_key(d):
                what = lambda t: f"table '{t['table']}' {t['size'][0]}x{t['size'][1]} {t['format']}" \
                    if t.get("table") else "a texture the scene supplies"  # noqa: E731
                raise SourceError(b.display_path, 1, 1, f"texture '{name}' of {b.kind} brick '{b.id}' is "
                                  f"{what(d)}, but {other.kind} brick '{other.id}' ({other.display_path}) declares "
                                  f"it as {what(other.textures[name])}",
                                  "rename one of the textures: textures are bound by name")


_BUILTIN: Library | None = None


def builtin_library() -> Library:
    """The built-in bricks, parsed once per process (for callers that were given no library)."""
    global _BUILTIN
    if _BUILTIN is None:
        _BUILTIN = load_library()
    return _BUILTIN


def library_or_builtin(lib: Library | None) -> Library:
    """`lib`, or the built-in bricks when it is None."""
    return lib if lib is not None else builtin_library()


def _meta_error(shown: str, loc: ir.Loc, message: str, hint: str) -> SourceError:
    return SourceError(shown, loc.line, loc.col, message, hint)


def load_brick(path: Path, text: str | None = None, shown: str | None = None) -> Brick:
    """Parse one brick file (or `text` standing for it) and check its metadata against its functions.

    The brick id is the file stem; `shown` names it in messages and #line directives.
    """
    shown = shown or display(path)
    bad = sorted({c for c in shown if c == '"' or not c.isprintable()})
    if bad:  # it is written into generated sources (#line, provenance comments): nothing there may end a line
        what = ", ".join("a quote" if c == '"' else f"U+{ord(c):04X}" for c in bad)
        safe = "".join(c if c.isprintable() and c != '"' else "?" for c in shown)
        raise SourceError(safe, 1, 1, f"the brick's path contains {what} (a quote, a line break or another "
                          "control character)", "rename the file or its directory: the path is written into #line "
                          "directives and provenance comments")
    if text is None:
        text = read_text(path, "brick", MAX_BRICK_BYTES)
    meta, loc, doc, node = read_meta_node(text, shown)
    from .schema import check, key_positions
    positions = key_positions(node)
    check(meta, shown, loc, positions)  # the shape first (library/schema.py), then the meaning
    unknown = set(meta) - META_KEYS
    if unknown:
        raise _meta_error(shown, loc, f"unknown BRICK key(s): {', '.join(sorted(unknown))}",
                          f"allowed keys: {', '.join(sorted(META_KEYS))}")
    kind = meta.get("kind")
    if kind not in KINDS:
        raise _meta_error(shown, loc, f"unknown brick kind {kind!r}", f"use one of {', '.join(KINDS)}")
    if not doc.strip():
        raise SourceError(shown, 1, 1, "a brick needs a docstring", "say what model it is and cite the paper and equation")
    cite = meta.get("cite", "")
    if not isinstance(cite, str) or not cite.strip():
        raise _meta_error(shown, loc, "BRICK has no 'cite'", 'add "cite": "Author Year, eq. N" (the source of the formula)')
    params = _params(shown, loc, meta.get("params", {}))
    arrays = [n for n, prm in params.items() if prm.ty.kind == "array"]
    if arrays and kind not in BRDF_ARRAY_KINDS:
        raise _meta_error(shown, loc, f"parameter '{arrays[0]}' of a {kind} brick has a count",
                          "array parameters are for BRDF terms and slot fillers (their count is part of the BRDF spec)")
    slots = _slots(shown, loc, meta.get("slots", {}))
    textures = meta.get("textures", {})
    if not isinstance(textures, dict):
        raise _meta_error(shown, loc, "'textures' must be a dict", 'write "textures": {"albedo_map": {"srgb": True}}')
    for tname, t in textures.items():
        baked = [k for k in ("size", "format") if k in t]
        if "table" in t and len(baked) < 2:
            missing = "size" if "size" not in t else "format"
            raise _meta_error(shown, loc, f"texture '{tname}' names table '{t['table']}' without its '{missing}'",
                              'add "size": [W, H] and "format": "unorm8" | "fp16" | "fp32" (chosen by measured error)')
        if baked and "table" not in t:
            raise _meta_error(shown, loc, f"texture '{tname}' has a '{baked[0]}' but no 'table'",
                              "size and format describe a baked table: add \"table\": NAME, or remove them")
        if "table" in t and t.get("srgb"):
            raise _meta_error(shown, loc, f"table texture '{tname}' is marked sRGB",
                              "baked tables hold linear values: remove \"srgb\": True")
        if (t.get("srgb") and t.get("holds", "color") != "color") or \
                (t.get("keep_length") and t.get("holds") not in ("normal", "normal_xy")):
            raise _meta_error(shown, loc, f"texture '{tname}' is marked {'sRGB' if t.get('srgb') else 'keep_length'} "
                              f"but holds {t.get('holds', 'data')!r}",
                              "only colour is sRGB-encoded, and only a normal map keeps its filtered length")
    _refuse_input_names(shown, loc, positions, params, textures)
    externals = {}
    for sname, s in slots.items():
        k = KINDS[s["kind"]]
        if k.slot:  # called from this brick's code, type-checked against the contract's arguments
            externals[sname] = Signature(k.signature(k.entries[0].name), k.entries[0].ret)
            externals.update(slot_sampling_externals(sname, k))  # `<slot>_sample_h(...)`: library/sampling.py
    module = parse_module(text, shown, externals)
    for g in module.globals.values():
        where = g.loc or loc
        raise SourceError(shown, where.line, where.col, f"buffer '{g.name}' is declared at the top level of a {kind} brick, "
                          "and the link stage binds no brick buffers yet",
                          "pass the values as parameters (an array parameter: \"count\": N) or a texture")
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,63}", path.stem):
        raise SourceError(shown, 1, 1, f"the brick id '{path.stem}' (its file name) is not a name of the brick language",
                          "rename the file: letters, digits and _, starting with a letter or _, at most 64 characters")
    for fname, f in module.functions.items():
        linked = f"{path.stem}_{fname}"  # link/program.py: the name of a brick without fillers
        if GLUE_FUNCTIONS.fullmatch(linked):
            raise SourceError(shown, f.loc.line, f.loc.col, f"function '{fname}' of brick '{path.stem}' would be "
                              f"linked as '{linked}', a function of the generated glue",
                              f"rename the function, or the brick file ('{path.stem}' is its id)")
    if kind == "packing" and "normal" not in slots:
        raise _meta_error(shown, loc, "a packing brick needs a 'normal' slot (the shading normal it provides)",
                          '"slots": {"normal": {"kind": "normal", "default": "vertex"}}')
    if "encodes" in meta and kind != "output":
        line, col = positions.get(("encodes",), (loc.line, loc.col))
        raise SourceError(shown, line, col, f"'encodes' is declared by a {kind} brick",
                          "only an output brick says what its colour encodes: remove it")
    brick = Brick(path.stem, kind, path, shown, module, params, slots, textures, cite.strip(), doc.strip(),
                  str(meta.get("fp16", "")).strip(), float(meta.get("tolerance", 0.0)),
                  meta.get("encodes", "linear"), reciprocal=str(meta.get("reciprocal", "")).strip())
    _check_entries(brick, loc)
    if kind == "environment":
        _check_environment(brick, loc, positions)
    brick.sampling = split_sampling(brick)
    return brick


def _check_environment(b: Brick, loc, positions) -> None:
    """An environment brick declares the contract's textures (kinds.ENVIRONMENT_TEXTURES) and reads each with
    its dimension: the glue binds them by name, the radiance cube per light set, the AmbientBRDF table per BRDF."""
    from ..lang.types import texture_type
    from .kinds import ENVIRONMENT_TEXTURES
    names = set(b.textures)
    if names != set(ENVIRONMENT_TEXTURES):
        extra = sorted(names - set(ENVIRONMENT_TEXTURES))
        line, col = positions.get(("textures", extra[0]), positions.get(("textures",), (loc.line, loc.col))) \
            if extra else positions.get(("textures",), (loc.line, loc.col))
        want = ", ".join(f"'{n}' ({d})" for n, d in ENVIRONMENT_TEXTURES.items())
        raise SourceError(b.display_path, line, col, f"an environment brick declares the textures {want}, and this "
                          f"one declares {', '.join(repr(n) for n in sorted(names)) or 'none'}",
                          "declare exactly those (the glue binds them by name): \"textures\": {\"radiance\": {...}, "
                          "\"ambient_brdf\": {...}}")
    for f in b.entries:
        for p in f.params:
            if p.name in ENVIRONMENT_TEXTURES and p.ty != texture_type(ENVIRONMENT_TEXTURES[p.name]):
                raise SourceError(b.display_path, p.loc.line, p.loc.col, f"texture '{p.name}' is {p.ty} here, and the "
                                  f"environment contract reads it as a texture{ENVIRONMENT_TEXTURES[p.name]}",
                                  f"annotate it texture{ENVIRONMENT_TEXTURES[p.name]}")


# Functions the link stage and the templates generate (link/glue.py brdf_lit<suffix>, brdf<suffix>, brdf_switch,
# shade; link/uber.py shade; every template's main): a brick function linked as `<id>_<function>` must never be one.
GLUE_FUNCTIONS = re.compile(r"(brdf|brdf_lit|shade|main)(_[0-9]+)?|brdf_switch")

PARAM_KEYS = {"type", "range", "default", "doc", "count"}
MAX_ARRAY = 16


def _refuse_input_names(shown, loc, positions, params, textures) -> None:
    """A parameter or texture may not be named like a row of the inputs tables (library/inputs.py: INPUTS, the
    shading inputs with the glue's intermediates, and SURFACE_INPUTS): an entry binds its parameters by name,
    so the glue would declare the name twice (`L` a material parameter and the light vector: a redefinition
    in every compiler) or pass the input where the texture goes (an assertion in the link stage)."""
    for group, names in (("params", params), ("textures", textures)):
        for name in names:
            table = ("shading", "INPUTS") if name in BY_NAME else ("surface", "SURFACE_INPUTS") \
                if name in SURFACE else None
            if table is None:
                continue
            line, col = positions.get((group, name), (loc.line, loc.col))
            what = "parameter" if group == "params" else "texture"
            raise SourceError(shown, line, col, f"{what} '{name}' is named like one of the {table[0]} inputs "
                              f"({table[1]} in generator/library/inputs.py), which entries read by the same name",
                              f"rename the {what}, e.g. to '{name}_{what}', here and where it is used")


def _params(shown, loc, raw) -> dict[str, Param]:
    if not isinstance(raw, dict):
        raise _meta_error(shown, loc, "'params' must be a dict", 'write "params": {"n": {"type": "float", ...}}')
    out = {}
    for name, spec in raw.items():
        if not isinstance(spec, dict) or spec.get("type") not in PARAM_TYPES:
            raise _meta_error(shown, loc, f"parameter '{name}' needs a type",
                              f"give \"type\" one of {', '.join(PARAM_TYPES)}")
        unknown = set(spec) - PARAM_KEYS
        if unknown:
            close = difflib.get_close_matches(sorted(unknown)[0], sorted(PARAM_KEYS), n=1)
            raise _meta_error(shown, loc, f"parameter '{name}' has unknown key(s) {', '.join(sorted(unknown))}",
                              (f"did you mean '{close[0]}'? " if close else "") + f"allowed: {', '.join(sorted(PARAM_KEYS))}")
        ty = BUILTIN_TYPES[spec["type"]]
        count = spec.get("count")
        if count is not None:
            if type(count) is not int or not 1 <= count <= MAX_ARRAY or ty.kind == "matrix":
                raise _meta_error(shown, loc, f"parameter '{name}' has a bad count {count!r}",
                                  f"an array parameter holds 1 to {MAX_ARRAY} scalars or vectors")
            ty = array(ty, count)
        rng = spec.get("range")
        if rng is not None and not (isinstance(rng, (list, tuple)) and len(rng) == 2 and rng[0] <= rng[1]):
            raise _meta_error(shown, loc, f"parameter '{name}' has a bad range {rng!r}", "write [low, high]")
        default = spec.get("default")
        if default is None:
            raise _meta_error(shown, loc, f"parameter '{name}' has no default", "add a \"default\" value")
        problem = check_value(ty, rng, default)
        if problem:
            raise _meta_error(shown, loc, f"default of '{name}': {problem}", "fix the default")
        out[name] = Param(name, ty, default, tuple(rng) if rng else None, spec.get("doc", ""))
    return out


def _slots(shown, loc, raw) -> dict[str, dict]:
    if not isinstance(raw, dict):
        raise _meta_error(shown, loc, "'slots' must be a dict", 'write "slots": {"ndf": {"kind": "ndf", "default": "ggx"}}')
    for name, s in raw.items():
        if not isinstance(s, dict) or s.get("kind") not in KINDS:
            raise _meta_error(shown, loc, f"slot '{name}' needs a kind and a default filler",
                              '"slots": {"ndf": {"kind": "ndf", "default": "ggx"}}')
        # an optional slot has no default: left empty it is not in the key and nothing fills it
        if s.get("optional") is True and "default" not in s:
            continue
        if not isinstance(s.get("default"), str) or "optional" in s:
            raise _meta_error(shown, loc, f"slot '{name}' needs a default filler, or \"optional\": True and none",
                              '"slots": {"ndf": {"kind": "ndf", "default": "ggx"}} or {"uv": {"kind": "uv", '
                              '"optional": True}}')
    return raw


def check_value(ty: Type, rng, value) -> str:
    """'' when value fits type and range, else what is wrong (an array: one value per element)."""
    if ty.kind == "array":
        if not isinstance(value, (list, tuple)) or len(value) != ty.size:
            return f"expected a list of {ty.size} values for {ty}, got {value!r}"
        for i, v in enumerate(value):
            problem = check_value(ty.elem, rng, v)
            if problem:
                return f"element {i}: {problem}"
        return ""
    n = ty.components
    vals = value if isinstance(value, (list, tuple)) else [value]
    if ty.kind == "scalar" and isinstance(value, (list, tuple)):
        return f"expected one number, got a list of {len(value)}"
    if len(vals) != n and not (len(vals) == 1 and ty.kind == "vector"):
        return f"expected {n} numbers for {ty}, got {len(vals)}"
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
        return f"expected numbers for {ty}, got {value!r}"
    bad = [v for v in vals if not abs(v) <= F32_MAX]  # inf, nan, 1e39: what a float32 uniform cannot hold
    if bad:
        return f"{bad[0]!r} is not a finite float32 number (at most 3.4e38 in magnitude)"
    if rng is not None:
        bad = [v for v in vals if not rng[0] <= v <= rng[1]]
        if bad:
            return f"{bad[0]!r} is outside the range [{rng[0]}, {rng[1]}]"
    return ""


def _check_entries(b: Brick, loc) -> None:
    """Every entry the kind's contract names is defined, returns its type and reads only what it may."""
    k = KINDS[b.kind]
    fns = b.module.functions
    for e in k.entries:
        if e.name not in fns and not e.optional:
            args = ", ".join(f"{a.name}: {a.ty}" for a in e.args if a.required)
            raise _meta_error(b.display_path, loc, f"a {b.kind} brick must define '{e.name}'",
                              f"add def {e.name}({args}) -> {e.ret}")
    kind_inputs = SHADING if k.reads == "shading" else SURFACE
    for f in b.entries:
        contract = k.entry(f.name)
        inputs = {} if contract.sampling else kind_inputs  # a sampling entry reads its arguments and params only
        if contract.ret is not None and f.ret != contract.ret:
            raise SourceError(b.display_path, f.loc.line, f.loc.col, f"'{f.name}' must return {contract.ret}, not {f.ret}",
                              "fix the return annotation")
        args = {a.name: a.ty for a in contract.args}
        declared = {p.name for p in f.params}
        for a in contract.args:
            if a.required and a.name not in declared:
                raise SourceError(b.display_path, f.loc.line, f.loc.col,
                                  f"'{f.name}' must take '{a.name}: {a.ty}' (the {b.kind} contract)",
                                  f"add the parameter {a.name}: {a.ty}")
        for p in f.params:
            if p.ty.kind == "texture":
                if p.name not in b.textures:
                    raise SourceError(b.display_path, p.loc.line, p.loc.col, f"texture '{p.name}' is not declared",
                                      f'add "textures": {{"{p.name}": {{"srgb": False}}}} to BRICK')
                continue
            want = args.get(p.name) or inputs.get(p.name) or (b.params[p.name].ty if p.name in b.params else None)
            if want is None and p.name.endswith("_count") and p.name[:-6] in b.params \
                    and b.params[p.name[:-6]].ty.kind == "array":
                want = INT  # the element count of an array parameter: part of the permutation key
            if want is None and b.kind == "packing":
                continue  # a material parameter of the BRDF, bound when composed
            if want is None:
                allowed = sorted(set(args) | set(inputs))
                close = difflib.get_close_matches(p.name, allowed + sorted(b.params), n=1)
                hint = f"did you mean '{close[0]}'? " if close else ""
                raise SourceError(b.display_path, p.loc.line, p.loc.col,
                                  f"parameter '{p.name}' is neither an argument of the {b.kind} contract, "
                                  f"a {k.reads} input nor a declared param",
                                  f"{hint}use one of {', '.join(allowed)}, or declare '{p.name}' in BRICK['params']")
            if want != p.ty:
                raise SourceError(b.display_path, p.loc.line, p.loc.col,
                                  f"parameter '{p.name}' is {p.ty} here but {want} by convention or declaration",
                                  f"annotate it {want}")
    needs = b.module.meta.get("needs")
    if needs is not None:
        used = sorted({p.name for f in b.entries if not k.entry(f.name).sampling for p in f.params if p.name in SHADING})
        if sorted(needs) != used:
            raise _meta_error(b.display_path, loc, f"BRICK['needs'] {sorted(needs)} differs from the inputs the entry reads {used}",
                              "list exactly the shading inputs named as parameters (or drop 'needs')")
