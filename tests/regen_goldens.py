"""Golden files: what the generator emits for tests/golden/cases.toml.

`python -m tests.regen_goldens` (or `make goldens`) rewrites tests/golden/;
review the result with `git diff tests/golden`. tests/test_golden.py fails
when the emitted sources drift from the checked-in ones.
"""
from __future__ import annotations

import json
import re
import sys
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
GOLDEN = REPO / "tests" / "golden"


def slug(spec: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", spec).strip("_")


def golden_sources() -> dict[str, tuple[str, str, str]]:
    """{relative path under tests/golden: (language, stage, text)} for every case."""
    from generator.library.bricks import load_library
    from generator.compose import compose_eval, compose_permutation
    from generator.scene.load import load_scene

    cases = tomllib.loads((GOLDEN / "cases.toml").read_text())
    lib = load_library()
    out: dict[str, tuple[str, str, str]] = {}
    for spec in cases["eval"]:
        for src in compose_eval(spec, lib).sources:
            out[f"{src.language}/eval/{slug(spec)}.comp.{src.language}"] = (src.language, "comp", src.text)
    out.update(_link_sources(cases))
    for scene_path in cases["scenes"]:
        scene = load_scene(REPO / scene_path, lib)
        name = Path(scene_path).stem
        for h, perm in sorted(scene.permutations.items()):
            for src in compose_permutation(perm, lib).sources:
                out[f"{src.language}/{name}/{h}.{src.stage}.{src.language}"] = (src.language, src.stage, src.text)
        from generator.compose.uber import compose_ubershader
        uber, _ = compose_ubershader([p for _, p in sorted(scene.permutations.items())], lib)
        for src in uber.sources:
            out[f"{src.language}/{name}/ubershader.{src.stage}.{src.language}"] = (src.language, src.stage, src.text)
    return out


def _link_sources(cases: dict) -> dict[str, tuple[str, str, str]]:
    """The link-stage cases: eval kernels, switch kernels and permutations over the test bricks."""
    from generator.compose import compose_eval, compose_permutation, compose_shade_kernel
    from generator.library.bricks import load_library
    from generator.link import switch_program
    from generator.spec.permutation import LightKey, Permutation

    lib = load_library([REPO / cases["link_bricks"]])
    out = {}
    for spec in cases["link_eval"]:
        for src in compose_eval(spec, lib).sources:
            out[f"{src.language}/link/{slug(spec)}.comp.{src.language}"] = (src.language, "comp", src.text)
    for specs in cases["link_switch"]:
        ep = switch_program(specs, lib)
        for src in compose_eval(ep.spec, lib, ep=ep).sources:
            out[f"{src.language}/link/switch_{slug('_'.join(specs))}.comp.{src.language}"] = \
                (src.language, "comp", src.text)
    for case in cases["link_permutation"]:
        lights = tuple(LightKey(*k.lstrip("*").split("/"), dynamic=k.startswith("*")) for k in case["lights"])
        perm = Permutation(case["brdf"], lights, case["packing"], case["output"])
        for src in compose_permutation(perm, lib).sources:
            out[f"{src.language}/link/{perm.hash}.{src.stage}.{src.language}"] = (src.language, src.stage, src.text)
        for src in (compose_shade_kernel(perm, lib).sources if case.get("shade_kernel") else []):
            out[f"{src.language}/link/{perm.hash}.shade.comp.{src.language}"] = (src.language, "comp", src.text)
    return out


def spirv_summary(sources: dict[str, tuple[str, str, str]]) -> dict:
    """Optimized SPIR-V size (32-bit words) of every golden source, with the tool versions."""
    from generator.toolchain import CompileJob, compile_many, tool_versions

    jobs = [CompileJob(re.sub(r"[^A-Za-z0-9.]+", "_", rel), lang, stage, text)
            for rel, (lang, stage, text) in sources.items()]
    results = compile_many(jobs)
    words = {}
    for rel, job in zip(sources, jobs):
        r = results[job.key]
        if not r.ok:
            raise SystemExit(f"{rel} does not compile:\n" + "\n".join(map(str, r.diagnostics)))
        words[rel] = len(r.spirv) // 4
    return {"tools": tool_versions(), "spirv_words": dict(sorted(words.items()))}


def main() -> int:
    sources = golden_sources()
    for old in GOLDEN.glob("*/**/*.*"):
        rel = str(old.relative_to(GOLDEN))
        if old.is_file() and rel not in sources:
            old.unlink()
    for rel, (_, _, text) in sources.items():
        p = GOLDEN / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    summary = spirv_summary(sources)
    (GOLDEN / "spirv.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(f"wrote {len(sources)} golden sources and tests/golden/spirv.json; review with `git diff tests/golden`")
    return 0


if __name__ == "__main__":
    sys.exit(main())
