"""A scene of many distinct permutations from the bricks present, for the build benchmarks and tests.

    .venv/bin/python benchmarks/scenegen.py N OUT.toml [--objects-per-permutation K] [--fixed] [--seed S]

Materials are every BRDF the library builds (each diffuse and specular brick alone, every diffuse +
specular pair, a brick with slots with every filler combination) under every packing and normal
brick that suits it (albedo_texture only where the BRDF reads rho_d); light sets are combinations
of the light and shadow bricks. Objects pair materials with light sets until N distinct permutations
exist (each used by K objects), drawn from all pairs in a shuffled order fixed by --seed (default 0):
the same N and seed give the same bytes.

--fixed draws from the bricks of FIXED only (every brick there must exist), so that the scene, and what a
benchmark measures on it, does not grow when the library gains bricks: benchmarks/build.py builds such a scene.
"""
from __future__ import annotations

import argparse
import itertools
import random
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from generator.library.bricks import load_library  # noqa: E402
from generator.library.kinds import BRDF_KINDS  # noqa: E402

sys.path.insert(0, str(REPO / "benchmarks"))
from cliargs import positive  # noqa: E402


# The bricks of a --fixed scene: each kind's common forms (the one-brick benchmark edits ndf=beckmann).
FIXED = {
    "diffuse": ("lambert", "oren_nayar", "oren_nayar_improved", "gotanda_fitted"),
    "specular": ("phong", "blinn_phong_normalized", "ward_isotropic", "ashikhmin_shirley", "banks", "cook_torrance",
                 "microfacet"),
    "ndf": ("beckmann", "blinn_phong", "ggx"),
    "fresnel": ("none", "schlick", "dielectric_exact"),
    "visibility": ("implicit", "smith_ggx_height_correlated", "smith_schlick", "torrance_sparrow"),
    "normal": ("vertex", "vertex_tangent", "normal_map"),
    "light": ("directional", "point", "spot"),
    "shadow": ("none", "pcf", "vsm"),
}
ONLY: dict | None = None  # FIXED under --fixed: the kinds' bricks drawn from


def of_kind(lib, kind) -> list:
    """The library's bricks of `kind` by id (those of ONLY[kind] when ONLY is set)."""
    bricks = sorted(lib.of_kind(kind), key=lambda b: b.id)
    if ONLY is None:
        return bricks
    have = {b.id for b in bricks}
    missing = [i for i in ONLY[kind] if i not in have]
    if missing:
        raise SystemExit(f"benchmarks/scenegen.py: FIXED names {kind} brick(s) {', '.join(missing)} the library does "
                         "not have — update FIXED")
    return [b for b in bricks if b.id in ONLY[kind]]


def _terms(lib, kind) -> list[str]:
    out = []
    for b in of_kind(lib, kind):
        if not b.slots:
            out.append(b.id)
            continue
        options = [[f"{slot}={f.id}" for f in of_kind(lib, v["kind"])] for slot, v in b.slots.items()]
        out += [f"{b.id}({','.join(c)})" for c in itertools.product(*options)]
    return out


def brdfs(lib) -> list[str]:
    diffuse, specular = _terms(lib, BRDF_KINDS[0]), _terms(lib, BRDF_KINDS[1])
    return diffuse + specular + [f"{d}+{s}" for d in diffuse for s in specular]


def packings(lib, brdf: str) -> list[str]:
    """The packings a material of this BRDF may have: constants and albedo_texture with every normal filler, kept
    where scene loading accepts them (spec/constraints.py): albedo_texture only for a BRDF that reads rho_d,
    and only normals that carry the tangent for a BRDF that reads the tangent frame. Each term is parsed once."""
    from generator.spec.resolve import resolve_brdf
    normals = [b.id for b in of_kind(lib, "normal")]
    tangent, params = False, set()
    for term in brdf.split("+"):  # a BRDF is diffuse + specular terms; fillers have no '+'
        if term not in _TERMS:
            r = resolve_brdf(term, lib)
            _TERMS[term] = (bool(r.tangent), set(r.params))
        tangent, params = tangent or _TERMS[term][0], params | _TERMS[term][1]
    if tangent:
        normals = [n for n in normals if any(p.name in ("T", "B") for f in lib.get("normal", n).entries
                                                 for p in f.params)]
    return [f"{p}(normal={n})" for p in ("constants", "albedo_texture") for n in normals
            if p == "constants" or "rho_d" in params]


_TERMS: dict[str, tuple[bool, set]] = {}


def light_sets(lib) -> list[list[tuple[str, str]]]:
    lights = [b.id for b in of_kind(lib, "light")]
    shadows = [b.id for b in of_kind(lib, "shadow")]
    one = [(lt, sh) for lt in lights for sh in shadows]
    return [[x] for x in one] + [list(p) for p in itertools.combinations(one, 2)]


def scene_text(n: int, per: int = 1, seed: int = 0, ubershader: bool = True) -> str:
    lib = load_library()
    sets = light_sets(lib)
    materials = [(b, p) for b in brdfs(lib) for p in packings(lib, b)]
    if len(materials) * len(sets) < n:
        raise SystemExit(f"the bricks give {len(materials) * len(sets)} permutations, fewer than {n}")
    how = f"--objects-per-permutation {per}" + (" --fixed" if ONLY is not None else "") + (f" --seed {seed}" if seed else "") \
        + ("" if ubershader else " --no-ubershader")
    out = [f"# Generated by benchmarks/scenegen.py {n} ({how}): {n} distinct permutations.",
           "", "[scene]", f'name = "generated_{n}"', *([] if ubershader else ["ubershader = false"]), ""]
    light_names = {}
    for s in sets:
        for lt, sh in s:
            if (lt, sh) not in light_names:
                name = f"{lt}_{sh}"
                light_names[(lt, sh)] = name
                out += [f"[lights.{name}]", f'type = "{lt}"', f'shadow = "{sh}"', ""]
    out.append("[light_sets]")
    for k, s in enumerate(sets):
        out.append(f"set{k} = [{', '.join(repr(light_names[x]).replace(chr(39), chr(34)) for x in s)}]")
    out.append("")
    # a fixed mix of materials and light sets: n distinct (material, set) pairs drawn without building them all
    pairs = [divmod(k, len(sets)) for k in random.Random(seed).sample(range(len(materials) * len(sets)), n)]
    used = {m for m, _ in pairs}
    for m in sorted(used):
        b, p = materials[m]
        out += [f"[materials.m{m}]", f'brdf = "{b}"', f'packing = "{p}"', ""]
    for k, (m, s) in enumerate(pairs):
        for j in range(per):
            out += ["[[objects]]", f'name = "o{k}_{j}"', f'material = "m{m}"', f'lights = "set{s}"', ""]
    return "\n".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", type=positive, help="distinct permutations")
    ap.add_argument("out", help="the scene file to write (TOML)")
    ap.add_argument("--objects-per-permutation", type=positive, default=1, help="objects using each (default 1)")
    ap.add_argument("--fixed", action="store_true",
                    help="draw from the fixed brick list FIXED only (a scene that does not grow with the library)")
    ap.add_argument("--seed", type=int, default=0, help="the shuffle's seed (default 0)")
    ap.add_argument("--no-ubershader", action="store_true",
                    help="write `ubershader = false` in [scene]: build ships no fallback ubershader")
    args = ap.parse_args()
    global ONLY
    ONLY = FIXED if args.fixed else None
    Path(args.out).write_text(scene_text(args.n, args.objects_per_permutation, args.seed,
                                            not args.no_ubershader))
    return 0


if __name__ == "__main__":
    sys.exit(main())
