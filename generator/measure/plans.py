"""Measured costs: per permutation of a scene, and per brick as "with it" minus "with a stand-in".

Every figure comes from the optimized SPIR-V of real shaders, in each
language (:mod:`generator.analysis` reads it). A brick's cost is the difference
between two shaders that differ only in that brick. The stand-ins do no
arithmetic and read no parameter; the BRDF stand-ins return the view vector
V, so that fetching V (an input, as in the course's accounting) is in every
shader measured and never in a difference.

- diffuse and specular bricks: the eval kernel of the brick beside the other
  kind's stand-in (``lambert+standin_specular``) minus the kernel of both
  stand-ins; a brick with slots is measured with its default fillers;
- slot fillers (ndf, fresnel, visibility): inside each BRDF brick that has
  such a slot (the microfacet host), with the host's default fillers in the
  other slots, minus the same host with the stand-in in that slot;
- lights, shadows, packings, normals, outputs: the fragment shader of a small
  synthetic permutation (BRDF ``standin_diffuse+standin_specular``, one
  ``standin_light`` with ``standin_shadow``, ``standin_packing``,
  ``standin_output``) with the brick put in its place, minus the permutation
  with stand-ins only. Slots of the brick get stand-ins too. A packing that
  provides material inputs is measured under a BRDF brick that reads them
  (the same BRDF in both shaders).

Models of the course's table (``course_costs.toml``) are measured the same
way, whole: shift-invariant as the eval kernel of the model's spec minus the
stand-in BRDF; shift-variant as the synthetic fragment shader with the
model's BRDF and the textured packing minus the all-stand-in one. The
stand-ins live in ``generator/measure/standins/`` (slot fillers are generated
from the slot signature) and are loaded only here.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

from ..library.bricks import Brick, Library, load_brick, load_library
from ..library.kinds import BRDF_KINDS, KINDS
from .. import GPU_TARGETS
from ..io import show_progress
from ..toolchain.jobs import job_key, source_jobs
from ..compose import Composed, compose_eval, compose_permutation
from ..compose.batch import compose_permutations
from ..analysis import Cost, entry_cost
from ..lang import SourceError
from ..spec.permutation import LightKey, Permutation, SpecError
from ..spec.resolve import resolve, resolve_brdf
from ..scene.load import Scene
from ..toolchain import CompileJob, compile_many

__all__ = ["Row", "CourseFigure", "CourseModel", "course_models", "course_figure", "brick_rows",
           "scene_rows", "load_cost_library", "standin", "is_standin", "COST_BRICKS", "REPORT_LANGUAGES"]

COST_BRICKS = Path(__file__).resolve().parent / "standins"
COURSE_FILE = Path(__file__).resolve().parent / "course_costs.toml"
REPORT_LANGUAGES = GPU_TARGETS  # column order of the reports: the order of build, accuracy and eval
STANDIN_CITE = "shadermatrix cost baseline (no model)"  # what marks a stand-in brick


@dataclass(frozen=True)
class CourseFigure:
    """One figure of the course's tables: texture and ALU cost of a model for one point light."""

    model: str
    form: str       # "direct" | "factored"
    table: str      # "shift-invariant" | "shift-variant"
    texture: int
    alu: str        # text: the course writes formulas for Lafortune


@dataclass(frozen=True)
class CourseModel:
    name: str
    form: str
    spec: str
    requires: tuple
    invariant: CourseFigure
    variant: CourseFigure


def course_models() -> tuple[list[CourseModel], str]:
    """The course's table as data, and the packing that makes a model shift-variant."""
    data = tomllib.loads(COURSE_FILE.read_text(encoding="utf-8"))
    models = []
    for m in data["model"]:
        fig = {t: CourseFigure(m["name"], m["form"], f"shift-{t}", int(m[t]["texture"]), str(m[t]["alu"]))
               for t in ("invariant", "variant")}
        models.append(CourseModel(m["name"], m["form"], m["spec"], tuple(m["requires"]),
                                  fig["invariant"], fig["variant"]))
    return models, data["variant"]["packing"]


def course_figure(perm: Permutation, lib: Library) -> CourseFigure | None:
    """The course's figure for a permutation's BRDF (direct form), shift-variant when its packing reads textures."""
    try:
        r = resolve(perm, lib)
        ids = {n.brick.id for top in r.brdf for n in top.tree}
        packing = r.packing.brick
    except (SpecError, SourceError):
        return None
    for m in course_models()[0]:
        if m.form == "direct" and m.requires and set(m.requires) <= ids:
            return m.variant if packing.entries else m.invariant
    return None


@dataclass
class Row:
    """One measured subject in one language."""

    table: str           # "brick" | "model" | "permutation"
    subject: str         # brick id, "ndf=beckmann", model name, permutation hash
    kind: str            # brick kind; "brdf" for models; the stage name for permutations
    language: str
    stage: str           # "comp" | "frag" | "vert"
    measured: str        # what was compiled (spec or permutation key)
    baseline: str = ""   # what was subtracted (per-brick and model rows)
    cost: Cost | None = None
    course: CourseFigure | None = None
    error: str = ""
    objects: tuple = ()  # permutation rows: the scene objects using it
    materials: tuple = ()  # permutation rows: the materials of those objects, in scene order
    lights: int = 0      # permutation rows: light count (the course's figures are per light)
    gpu: dict | None = None  # {AMD family: {RADV statistic: value}} with --gpu (measure/gpu.py)


# ------------------------------------------------------------------ compiling

class _Batch:
    """Shaders to compile once each (eval kernels and permutation fragment shaders), then their costs."""

    def __init__(self, lib: Library, languages, vert: bool = False, store=None):
        self.lib, self.languages, self.store = lib, tuple(languages), store
        self.vert = vert  # compile the vertex shaders of permutation units too (graphics pipelines for --gpu)
        self.units: dict[str, Composed | str] = {}  # unit key -> composed, or an error message
        self.results: dict = {}

    def eval(self, spec: str) -> str:
        key = "eval:" + spec
        if key not in self.units:
            self.units[key] = _compose(lambda: compose_eval(spec, self.lib, self.languages))
        return key

    def perm(self, perm: Permutation) -> str:
        key = "perm:" + perm.canonical()
        if key not in self.units:
            self.units[key] = _compose(lambda: compose_permutation(perm, self.lib, self.languages))
        return key

    def run(self) -> None:
        jobs, seen = [], set()
        for c in self.units.values():
            if isinstance(c, str):
                continue
            for src in c.sources:
                k = job_key(c.hash, src.stage, src.language)
                if (src.stage in ("comp", "frag") or (self.vert and src.stage == "vert")) and k not in seen:
                    seen.add(k)
                    jobs.append(CompileJob(k, src.language, src.stage, src.text, line_map=tuple(src.line_map)))
        self.results = compile_many(jobs, progress=show_progress(), store=self.store)

    def spirv(self, unit: str, language: str) -> tuple[str, dict[str, bytes]] | None:
        """(job key, {stage: SPIR-V}) of a unit in one language, None when it did not build."""
        c = self.units[unit]
        if isinstance(c, str):
            return None
        stages = ("comp",) if unit.startswith("eval:") else ("vert", "frag")
        got = {st: self.results.get(job_key(c.hash, st, language)) for st in stages}
        if not all(r is not None and r.ok for r in got.values()):
            return None
        return f"{c.hash}.{language}", {st: r.spirv for st, r in got.items()}

    def fail(self, name: str, message: str) -> str:
        """A unit that cannot be built: its rows carry `message`."""
        key = "fail:" + name
        self.units[key] = message
        return key

    def canonical(self, unit: str) -> str:
        """The canonical spec or permutation key of a unit (as given when it did not compose)."""
        c = self.units[unit]
        return unit.split(":", 1)[1] if isinstance(c, str) else c.key

    def cost(self, unit: str, language: str) -> Cost | str:
        c = self.units[unit]
        if isinstance(c, str):
            return c
        stage = "comp" if unit.startswith("eval:") else "frag"
        r = self.results[job_key(c.hash, stage, language)]
        if not r.ok:
            return "; ".join(r.errors())
        return entry_cost(r.spirv)


def _compose(fn) -> Composed | str:
    try:
        return fn()
    except (SourceError, SpecError) as e:
        return str(e)


# ------------------------------------------------------------------ per brick

# the specular term an environment brick's row is measured on (an environment lights microfacet terms only)
ENVIRONMENT_LIT = "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"


def standin(lib: Library, kind: str) -> Brick | None:
    """The stand-in brick of a kind (generator/measure/standins, or generated for slot kinds)."""
    return next((b for b in lib.of_kind(kind) if is_standin(b)), None)


def is_standin(b: Brick) -> bool:
    return b.id.startswith("standin_") and b.cite == STANDIN_CITE


def _consumer(lib: Library, packing: Brick, pair) -> str | None:
    """A BRDF reading every material input a packing provides and no tangent frame (the packing's normal slot
    holds a stand-in), the same in both measured shaders."""
    wanted = {f.name[len("get_"):] for f in packing.entries}
    if not wanted:
        return pair("diffuse", standin(lib, "diffuse").id)
    for kind in BRDF_KINDS:
        for b in lib.of_kind(kind):
            if not is_standin(b) and wanted <= set(b.params) and not _reads_tangent(b.id, lib):
                return pair(kind, b.id)
    # what no one term reads, a diffuse + specular pair may (the course's specular map: rho_d, f0, n)
    for d in (x for x in lib.of_kind("diffuse") if not is_standin(x) and not x.slots):
        for s in (x for x in lib.of_kind("specular") if not is_standin(x) and not x.slots):
            if wanted <= set(d.params) | set(s.params) and not _reads_tangent(f"{d.id}+{s.id}", lib):
                return f"{d.id}+{s.id}"
    return None


def _with_standin_slots(b: Brick, lib: Library, normal: str | None = None) -> str:
    """A brick's spec with every slot filled by its kind's stand-in (a packing's normal slot by `normal` if given)."""
    if not b.slots:
        return b.id
    fillers = [f"{slot}={normal if normal and v['kind'] == 'normal' else standin(lib, v['kind']).id}"
               for slot, v in b.slots.items() if not v.get("optional")]  # an optional slot stays empty: no cost
    return f"{b.id}({','.join(fillers)})" if fillers else b.id


def _reads_tangent(spec: str, lib: Library) -> bool:
    """Whether a BRDF spec reads a tangent-frame row of the inputs table (an anisotropic model); a spec whose
    bricks break the parameter policy reads none (its plan fails when it is composed, with that error)."""
    try:
        return bool(resolve_brdf(spec, lib).tangent)
    except SourceError:
        return False


@dataclass
class _Plan:
    table: str
    subject: str
    kind: str
    with_unit: str
    without_unit: str
    course: CourseFigure | None = None


def brick_rows(lib: Library, languages=REPORT_LANGUAGES, gpu=None, store=None) -> list[Row]:
    """Per-brick and per-model rows; `lib` must include the stand-ins (see load_cost_library).

    gpu: a measure.gpu.GpuRequest, to add RADV's statistics (with minus without) to every row."""
    batch = _Batch(lib, languages, vert=gpu is not None, store=store)
    sd, ss = standin(lib, "diffuse").id, standin(lib, "specular").id

    def pair(kind: str, spec: str) -> str:
        """A BRDF term with the other kind's stand-in beside it (which reads V, so V is always fetched)."""
        return f"{spec}+{ss}" if kind == "diffuse" else f"{sd}+{spec}"

    base = Permutation(f"{sd}+{ss}", (LightKey(standin(lib, "light").id, standin(lib, "shadow").id),),
                       _with_standin_slots(standin(lib, "packing"), lib), standin(lib, "output").id)
    plans: list[_Plan] = []

    def eval_plan(table, subject, kind, spec, baseline, course=None):
        plans.append(_Plan(table, subject, kind, batch.eval(spec), batch.eval(baseline), course))

    def perm_plan(table, subject, kind, perm, course=None, baseline=base):
        plans.append(_Plan(table, subject, kind, batch.perm(perm), batch.perm(baseline), course))

    hosts = [b for k in BRDF_KINDS for b in lib.of_kind(k) if b.slots and not is_standin(b)]
    # a slot filler is measured in one host (microfacet when there is one), so its row is named once
    hosts.sort(key=lambda h: h.id != "microfacet")
    for kind in KINDS:
        sub = standin(lib, kind)
        for b in (x for x in lib.of_kind(kind) if not is_standin(x)):
            if kind in BRDF_KINDS:  # a brick with slots is measured with its default fillers, named in full
                try:
                    subject = resolve_brdf(b.id, lib).nodes[0].key
                except (SpecError, SourceError) as e:  # e.g. a slot whose default filler does not exist
                    plans.append(_Plan("brick", b.id, kind, batch.fail(b.id, str(e)), batch.fail(b.id, str(e))))
                    continue
                eval_plan("brick", subject, kind, pair(kind, b.id), pair(kind, sub.id))
            elif any(v["kind"] == kind for h in hosts for v in h.slots.values()):
                h = next(h for h in hosts if any(v["kind"] == kind for v in h.slots.values()))
                for slot in (s for s, v in h.slots.items() if v["kind"] == kind):
                    eval_plan("brick", f"{slot}={b.id}", kind, pair(h.kind, f"{h.id}({slot}={b.id})"),
                              pair(h.kind, f"{h.id}({slot}={sub.id})"))
            elif kind == "light":
                perm_plan("brick", b.id, kind, replace(base, lights=(LightKey(b.id, base.lights[0].shadow),)))
            elif kind == "shadow":
                perm_plan("brick", b.id, kind, replace(base, lights=(LightKey(base.lights[0].light, b.id),)))
            elif kind == "packing":
                brdf = _consumer(lib, b, pair)
                if brdf is None:
                    wanted = ", ".join(f.name[len("get_"):] for f in b.entries)
                    plans.append(_Plan("brick", b.id, kind, batch.fail(b.id, f"no BRDF brick reads {wanted}"),
                                       batch.perm(base)))
                    continue
                perm_plan("brick", b.id, kind, replace(base, brdf=brdf, packing=_with_standin_slots(b, lib)),
                          baseline=replace(base, brdf=brdf))
            elif kind == "normal":
                perm_plan("brick", b.id, kind, replace(base, packing=f"{standin(lib, 'packing').id}(normal={b.id})"))
            elif kind == "output":
                perm_plan("brick", b.id, kind, replace(base, output=b.id))
            elif kind == "environment":  # a GGX/Schlick metal lit by it, minus the same metal without it
                metal = replace(base, brdf=ENVIRONMENT_LIT)
                perm_plan("brick", b.id, kind, replace(metal, environment=b.id), baseline=metal)
            elif kind == "uv":  # in the first packing with a uv slot: that packing with minus without it
                host = next((p for p in lib.of_kind("packing") if not is_standin(p)
                             and any(v["kind"] == "uv" for v in p.slots.values())), None)
                brdf = _consumer(lib, host, pair) if host is not None else None
                if brdf is None:
                    plans.append(_Plan("brick", b.id, kind, batch.fail(b.id, "no packing has a uv slot"),
                                       batch.perm(base)))
                    continue
                plain = _with_standin_slots(host, lib)
                with_uv = f"{plain[:-1]},uv={b.id})" if plain.endswith(")") else f"{plain}(uv={b.id})"
                perm_plan("brick", b.id, kind, replace(base, brdf=brdf, packing=with_uv),
                          baseline=replace(base, brdf=brdf, packing=plain))

    models, variant_packing = course_models()
    for m in models:
        if not m.spec or not all(lib.find(r, KINDS) for r in m.requires):
            continue  # no brick for this model yet: the report shows the course's figures alone
        try:
            kinds = [n.brick.kind for n in resolve_brdf(m.spec, lib).nodes]
        except (SpecError, SourceError):
            continue
        stand = "+".join(standin(lib, k).id for k in kinds)
        eval_plan("model", m.name, "brdf", m.spec, stand, m.invariant)
        packing = lib.find(variant_packing, ("packing",))
        if packing:
            # an anisotropic model needs the mesh's tangent: the packing's normal slot takes vertex_tangent
            normal = "vertex_tangent" if _reads_tangent(m.spec, lib) else None
            perm_plan("model", m.name, "brdf",
                      replace(base, brdf=m.spec, packing=_with_standin_slots(packing[0], lib, normal)), m.variant,
                      baseline=replace(base, brdf=stand))

    batch.run()
    rows, pairs = [], []
    for p in plans:
        for lang in languages:
            with_, without = batch.cost(p.with_unit, lang), batch.cost(p.without_unit, lang)
            stage = "comp" if p.with_unit.startswith("eval:") else "frag"
            row = Row(p.table, p.subject, p.kind, lang, stage, batch.canonical(p.with_unit),
                      batch.canonical(p.without_unit), course=p.course)
            if isinstance(with_, str) or isinstance(without, str):
                row.error = with_ if isinstance(with_, str) else f"baseline: {without}"
            else:
                row.cost = with_ - without
            rows.append(row)
            if gpu is not None and not row.error:
                measured, baseline = batch.spirv(p.with_unit, lang), batch.spirv(p.without_unit, lang)
                if measured is not None and baseline is not None:  # a difference needs both; never a raw value
                    pairs.append((row, measured, baseline))
    if gpu is not None:
        _attach_gpu(gpu, pairs)
    return rows


def _attach_gpu(gpu, pairs) -> None:
    """RADV's statistics for rows given as (row, (key, stages) of what was measured, of the baseline or None)."""
    from .gpu import attach

    units, triples = {}, []
    for row, with_, without in pairs:
        units[with_[0]] = with_[1]
        if without is not None:
            units[without[0]] = without[1]
        triples.append((row, with_[0], without[0] if without is not None else None))
    attach(gpu, triples, units)


# ------------------------------------------------------------------ per permutation

def _compile_scene(scene: Scene, lib: Library, languages, store) -> tuple[dict, dict, dict]:
    """Every permutation composed, and all their shaders compiled in one batch: (Composed by hash, compose errors
    by hash, results by job key). The build's loop (assemble/loop.py) also writes as it goes; a cost report
    reads the results once they are all in."""
    composed, errors = compose_permutations(sorted(scene.permutations.items()), lib, languages)
    jobs = [j for h, c in composed.items() for j in source_jobs(h, c.sources)]
    return composed, errors, compile_many(jobs, optimize=True, validate=True, progress=show_progress(), store=store)


def scene_rows(scene: Scene, lib: Library, languages=REPORT_LANGUAGES, gpu=None, store=None) -> list[Row]:
    """Fragment and vertex shader cost of every permutation of a scene and of its ubershader, per language.

    gpu: a measure.gpu.GpuRequest, to add RADV's statistics to every row."""
    from ..compose.uber import compose_ubershader

    composed, errors, results = _compile_scene(scene, lib, languages, store)
    rows, pairs = [], []

    materials: dict[str, list[str]] = {}
    for o in scene.objects:
        if o["material"] not in materials.setdefault(o["permutation"], []):
            materials[o["permutation"]].append(o["material"])

    def row_of(table, subject, perm_key, stage, lang, c_hash, course=None, objects=(), lights=0, error=None):
        row = Row(table, subject, table, lang, stage, perm_key, course=course, objects=objects, lights=lights,
                  materials=tuple(materials.get(subject, ())))
        r = results.get(job_key(c_hash, stage, lang)) if error is None else None
        if error is not None:
            row.error = error
        elif r.ok:
            row.cost = entry_cost(r.spirv)
        else:
            row.error = "; ".join(r.errors())
        rows.append(row)
        if gpu is not None and not row.error:
            both = {st: results.get(job_key(c_hash, st, lang)) for st in ("vert", "frag")}
            if all(x is not None and x.ok for x in both.values()):
                pairs.append((row, (f"{c_hash}.{lang}", {st: x.spirv for st, x in both.items()}), None))

    for h, perm in sorted(scene.permutations.items()):
        course = course_figure(perm, lib)
        for stage in ("frag", "vert"):
            for lang in languages:
                row_of("permutation", h, perm.canonical(), stage, lang, h, course, tuple(scene.users.get(h, [])),
                       len(perm.lights), "; ".join(errors[h]) if h in errors else None)
    perms = [scene.permutations[h] for h in sorted(scene.permutations) if h not in errors]
    # the scene's ubershader: one shader for every permutation (docs/design/link.md); it does not draw environments
    # yet (link/uber.py refuses them), so a scene with one has no ubershader row
    if perms and not any(p.environment for p in perms):
        try:
            uber, _ = compose_ubershader(perms, lib, languages)
            jobs = source_jobs("ubershader", uber.sources)
            results.update(compile_many(jobs, optimize=True, validate=True, progress=show_progress(), store=store))
            failed = None
        except (SourceError, SpecError) as e:
            failed = str(e)
        key = f"ubershader of {len(perms)} permutations"
        for stage in ("frag", "vert"):
            for lang in languages:
                row_of("ubershader", "ubershader", key, stage, lang, "ubershader", error=failed)
    if gpu is not None:
        _attach_gpu(gpu, pairs)
    return rows


def load_cost_library(extra_dirs=()) -> Library:
    """The bricks, an engine's extra brick directories, and the cost stand-ins.

    Stand-ins of slot kinds (ndf, fresnel, visibility) are generated from the
    kind's slot signature, so they follow it when it changes; the others are
    files in generator/measure/standins.
    """
    lib = load_library([*extra_dirs, COST_BRICKS])
    for kind, k in KINDS.items():
        if not k.slot or standin(lib, kind) is not None:
            continue
        b = load_brick(COST_BRICKS / f"standin_{kind}.py", text=_slot_standin(kind), shown=f"<stand-in {kind}>")
        lib.bricks[(kind, b.id)] = b
    return lib


def _slot_standin(kind: str) -> str:
    """Brick text of a slot kind's stand-in: it returns one of its inputs unchanged, so nothing folds."""
    e = KINDS[kind].entries[0]
    params = ", ".join(f"{a.name}: {a.ty}" for a in e.args)
    same = [a.name for a in e.args if a.ty == e.ret]
    value = same[-1] if same else f"{e.ret}({e.args[-1].name})"
    return (f'"""Cost stand-in {kind}: returns {value} (not a model; the baseline of `costs --per-brick`)."""\n'
            f'BRICK = {{"kind": "{kind}", "cite": "{STANDIN_CITE}"}}\n\n\n'
            f"def {e.name}({params}) -> {e.ret}:\n    return {value}\n")
