"""Golden files: what the generator links and emits for tests/golden/cases.toml.

`python -m tests.regen_goldens` (or `make goldens`) rewrites tests/golden/; review the result with
`git diff tests/golden`. tests/compose/test_golden.py fails when the checked-in files drift.

Names (tests/golden/README.md has the table): a case is named for what it is, never by a hash —
  <lang>/eval/<spec slug>.comp.<lang>                  an eval kernel of cases.toml's `eval`
  <lang>/<scene>/<material>.<vert|frag>.<lang>         a scene permutation, by its first material in the
                                                       scene's [materials] order (__<light set>, then
                                                       __<hash>, appended only when two would share a name)
  <lang>/<scene>/ubershader.<vert|frag>.<lang>         the scene's ubershader
  <lang>/link/<case slug>[.shade].<stage>.<lang>       the link-stage cases over tests/bricks/link
  ir/<dir>/<name>[.shade].ir                           the linked program of each case above
                                                       (generator/lang/dump.py), one for all languages

Normalization: a golden is the emitted text with two kinds of line rewritten, so that a brick's comment
or docstring edit (which moves its lines and changes its file's hash) changes no golden:
  `// brick <path> sha256:<12 hex>`, `// template <path> sha256:<12 hex>`   → the hash becomes `<elided>`
  `#line <digits> "<file>"` (GLSL and HLSL; WGSL has none)                 → `#line N "<file>"`, and dropped
                                                                             when the directive before it
                                                                             names the same file
The emitters write a directive wherever the next line is not the line after the last one, so a comment
between two statements adds one; a change of file always has one. What is kept is therefore one directive
per change of file: each function still says which brick it came from, whatever the line numbers.
Both patterns match whole lines at column 0; every other line is kept byte for byte (a test checks that
for every golden), so no code can hide behind the normalization. spirv.json is measured on the emitted
text itself (a `#line N` does not compile); a template's edit shows in the code it emits.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import re
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
GOLDEN = REPO / "tests" / "golden"
LANGUAGE_DIRS = ("glsl", "hlsl", "wgsl")

HEADER_HASH = re.compile(r"^(// (?:brick|template) [^ \n]+ sha256:)[0-9a-f]{12}$", re.M)
LINE_DIRECTIVE = re.compile(r'^#line [0-9]+ ("[^"\n]*")$')


def normalize(text: str) -> str:
    """The emitted text as checked in (see the module docstring): provenance hashes and #line numbers out."""
    out, last = [], None
    for line in HEADER_HASH.sub(r"\1<elided>", text).split("\n"):
        m = LINE_DIRECTIVE.match(line)
        if m and m.group(1) == last:
            continue
        if m:
            line, last = f"#line N {m.group(1)}", m.group(1)
        out.append(line)
    return "\n".join(out)


@dataclass(frozen=True)
class Golden:
    language: str  # glsl | hlsl | wgsl, or "ir" for a linked program's dump
    stage: str  # vert | frag | comp ("" for IR)
    emitted: str  # what the generator produced: compiled for spirv.json

    @property
    def text(self) -> str:
        """What is checked in."""
        return self.emitted if self.language == "ir" else normalize(self.emitted)


def slug(spec: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", spec).strip("_")


class _Goldens(dict):
    """{path under tests/golden: Golden}; two cases that would write one file are an error, not an overwrite."""

    def add(self, rel: str, g: Golden) -> None:
        if rel in self:
            raise SystemExit(f"tests/golden/cases.toml: two golden cases are named {rel} — rename one of them")
        self[rel] = g

    def sources(self, where: str, name: str, composed, stage_suffix: str = "") -> None:
        for src in composed.sources:
            self.add(f"{src.language}/{where}/{name}{stage_suffix}.{src.stage}.{src.language}",
                     Golden(src.language, src.stage, src.text))

    def ir(self, where: str, name: str, program, about: list[str]) -> None:
        from generator.lang.dump import dump_program

        head = "".join(f"// {line}\n" for line in about)
        self.add(f"ir/{where}/{name}.ir",
                 Golden("ir", "", head + dump_program(program.functions, program.structs, program.globals)))


@contextlib.contextmanager
def _bricks_from(bricks: Path | None):
    """Load the library's own bricks from `bricks` (a copy of bricks/, as a test edits it) while inside."""
    from generator.library import bricks as library

    if bricks is None:
        yield
        return
    saved, library.BUILTIN_BRICKS = library.BUILTIN_BRICKS, Path(bricks)
    try:
        yield
    finally:
        library.BUILTIN_BRICKS = saved


def golden_files(bricks: Path | None = None) -> dict[str, Golden]:
    """{relative path under tests/golden: Golden} for every case of cases.toml; `bricks`: the library's
    bricks folder to link from instead of bricks/."""
    cases = tomllib.loads((GOLDEN / "cases.toml").read_text())
    out = _Goldens()
    with _bricks_from(bricks):
        _eval_goldens(cases, out)
        _link_goldens(cases, out)
        for scene_path in cases["scenes"]:
            _scene_goldens(REPO / scene_path, out)
    return dict(out)


def _eval_goldens(cases: dict, out: _Goldens) -> None:
    from generator.compose import compose_eval
    from generator.library.bricks import load_library
    from generator.link import eval_program

    lib = load_library()
    for spec in cases["eval"]:
        ep = eval_program(spec, lib)
        out.ir("eval", slug(spec), ep.program, [f"eval: {ep.spec}"])
        out.sources("eval", slug(spec), compose_eval(spec, lib, ep=ep))


def permutation_names(scene) -> dict[str, str]:
    """{permutation hash: golden name} of a scene: the first material (in the scene's [materials] order)
    of the objects drawn with it; where two permutations would share that name (one material under two
    light sets), each takes `__<light set>` too, and `__<hash>` if that is still not enough."""
    order = {m: i for i, m in enumerate(scene.materials)}
    materials: dict[str, list[str]] = {}
    light_sets: dict[str, list[str]] = {}
    for o in scene.objects:
        materials.setdefault(o["permutation"], []).append(o["material"])
        light_sets.setdefault(o["permutation"], []).append(str(o.get("light_set") or "no_lights"))
    names = {h: slug(min(materials[h], key=lambda m: order.get(m, len(order)))) if h in materials else h
             for h in scene.permutations}
    for more in (lambda h: slug(light_sets.get(h, ["no_lights"])[0]), lambda h: h):
        seen: dict[str, int] = {}
        for n in names.values():
            seen[n] = seen.get(n, 0) + 1
        names = {h: f"{n}__{more(h)}" if seen[n] > 1 else n for h, n in names.items()}
    return names


def _scene_goldens(path: Path, out: _Goldens) -> None:
    from generator.compose import compose_permutation
    from generator.compose.uber import compose_ubershader
    from generator.library.bricks import load_library
    from generator.link import link_permutation
    from generator.scene.load import load_scene

    lib = load_library()
    scene = load_scene(path, lib)
    where = path.stem
    names = permutation_names(scene)
    for h, perm in sorted(scene.permutations.items(), key=lambda kv: names[kv[0]]):
        users = sorted({o["material"] for o in scene.objects if o["permutation"] == h})
        out.ir(where, names[h], link_permutation(perm, lib).program,
               [f"permutation: {perm.canonical()}", f"materials: {', '.join(users)}"])
        out.sources(where, names[h], compose_permutation(perm, lib))
    composed, uber = compose_ubershader([p for _, p in sorted(scene.permutations.items())], lib)
    out.ir(where, "ubershader", uber.program, [f"ubershader of {len(scene.permutations)} permutations"])
    out.sources(where, "ubershader", composed)


def _link_goldens(cases: dict, out: _Goldens) -> None:
    """The link-stage cases: eval kernels, switch kernels and permutations over the test bricks."""
    from generator.compose import compose_eval, compose_permutation, compose_shade_kernel
    from generator.library.bricks import load_library
    from generator.link import eval_program, link_permutation, switch_program
    from generator.spec.permutation import LightKey, Permutation

    lib = load_library([REPO / cases["link_bricks"]])
    for spec in cases["link_eval"]:
        ep = eval_program(spec, lib)
        out.ir("link", slug(spec), ep.program, [f"eval: {ep.spec}"])
        out.sources("link", slug(spec), compose_eval(spec, lib, ep=ep))
    for specs in cases["link_switch"]:
        ep = switch_program(specs, lib)
        name = f"switch_{slug('_'.join(specs))}"
        out.ir("link", name, ep.program, [f"switch: {ep.spec}"])
        out.sources("link", name, compose_eval(ep.spec, lib, ep=ep))
    for case in cases["link_permutation"]:
        lights = tuple(LightKey(*k.lstrip("*").split("/"), dynamic=k.startswith("*")) for k in case["lights"])
        perm = Permutation(case["brdf"], lights, case["packing"], case["output"])
        name = link_case_name(case)
        out.ir("link", name, link_permutation(perm, lib).program, [f"permutation: {perm.canonical()}"])
        out.sources("link", name, compose_permutation(perm, lib))
        if case.get("shade_kernel"):
            out.ir("link", f"{name}.shade", link_permutation(perm, lib, kernel=True).program,
                   [f"shade kernel: {perm.canonical()}"])
            out.sources("link", name, compose_shade_kernel(perm, lib), stage_suffix=".shade")


def link_case_name(case: dict) -> str:
    """A [[link_permutation]] case's name: its brdf, lights (`dyn_` for a dynamic one), packing and output."""
    lights = "_".join(("dyn_" if k.startswith("*") else "") + k.lstrip("*") for k in case["lights"])
    return "__".join(slug(part) for part in (case["brdf"], lights, case["packing"], case["output"]))


def spirv_summary(goldens: dict[str, Golden]) -> dict:
    """Optimized SPIR-V size (32-bit words) of every golden shader (the emitted text), with the tool versions."""
    from generator.toolchain import CompileJob, compile_many, tool_versions

    shaders = {rel: g for rel, g in goldens.items() if g.language != "ir"}
    jobs = [CompileJob(re.sub(r"[^A-Za-z0-9.]+", "_", rel), g.language, g.stage, g.emitted)
            for rel, g in shaders.items()]
    results = compile_many(jobs)
    words = {}
    for rel, job in zip(shaders, jobs):
        r = results[job.key]
        if not r.ok:
            raise SystemExit(f"{rel} does not compile:\n" + "\n".join(map(str, r.diagnostics)))
        words[rel] = len(r.spirv) // 4
    return {"tools": tool_versions(), "spirv_words": dict(sorted(words.items()))}


def checked_in(root: Path = GOLDEN) -> set[str]:
    """The golden files under `root` (every file in a subfolder: cases.toml, README.md and spirv.json sit on top)."""
    return {str(p.relative_to(root)) for p in root.glob("*/**/*") if p.is_file()}


def write(goldens: dict[str, Golden], root: Path) -> None:
    """Write every golden under `root` (atomically, each file) and remove the ones no case makes any more."""
    from generator.io import atomic_write

    for rel in sorted(checked_in(root) - set(goldens)):
        (root / rel).unlink()
    for rel, g in goldens.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        atomic_write(root / rel, g.text.encode())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tests.regen_goldens", description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=GOLDEN, help="where to write (default tests/golden)")
    ap.add_argument("--bricks", type=Path, help="link the library from this copy of bricks/ instead")
    ap.add_argument("--no-spirv", action="store_true", help="skip compiling the goldens for spirv.json")
    args = ap.parse_args(argv)
    goldens = golden_files(args.bricks)
    summary = None if args.no_spirv else spirv_summary(goldens)  # before writing: a compile failure writes nothing
    write(goldens, args.out)
    if summary is not None:
        from generator.io import atomic_write
        atomic_write(args.out / "spirv.json", (json.dumps(summary, indent=2) + "\n").encode())
    ir = sum(g.language == "ir" for g in goldens.values())
    print(f"wrote {len(goldens) - ir} golden sources and {ir} IR dumps under {args.out}"
          + ("" if summary is None else " and spirv.json") + "; review with `git diff tests/golden`")
    return 0


if __name__ == "__main__":
    sys.exit(main())
