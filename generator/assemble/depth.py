"""The depth passes in the build: the depth units written, compiled, validated and reflected like every other
shader, and each shadowed light's depth pass described, both in the manifest.

- ``depth_shaders`` (top level): {unit name: entry} of the units the scene's shadowed lights draw with
  (compose/depth.py: `depth`, `blur`, `<hash>.mask`, `<hash>.mask_moments`), each entry shaped like a
  permutation's: ``languages`` (sources and SPIR-V, vulkan/<language>/), ``platforms`` (every platform's tree,
  its reflection), ``interface``, ``input_key`` and ``status``. A unit whose input key (the build's key and its
  composed sources) is the last manifest's, with its files intact, is kept: not compiled again.
- ``lights.<name>.depth_pass``: runtime/shadow_pass.py depth_pass — the map, the casters' units, the shader
  bias, the matrix's convention per platform and the fit, where the result binds — for every light an object
  uses whose shadow filter samples a texture, at the contract's size (shadow_pass.SHADOW_SIZE).

The build cannot know an engine's meshes: the matrix is not computed here, its method and bounds are stated
(depth_pass.matrix.fit), and the ready-to-upload Lights blocks keep the brick's identity default.
"""
from __future__ import annotations

from ..io import content_key
from ..lang import SourceError
from ..lang.errors import UserError
from ..spec.where import KeyProblem
from .platforms import PLATFORM_TABLE
from .write import validate_dialects


def write_depth_passes(build) -> None:
    """Add ``depth_shaders`` and every shadowed light's ``depth_pass`` to the manifest of `build` (assemble._Build:
    its scene, context, writer, result and previous manifest), writing the units' files through its writer."""
    from ..compose.depth import compose_depth_units
    from ..link import link_permutation
    from ..runtime.shadow_pass import (MOMENTS, SHADOW_SIZE, bindings, depth_pass, depth_plan, pass_units,
                                       shadowed_lights)
    from ..spec.resolve import resolve

    scene, ctx, manifest = build.scene, build.ctx, build.res.manifest
    lib = ctx.library
    ok = {e["hash"]: e for e in manifest["permutations"] if e.get("status") in ("ok", "stale") and e.get("interface")}
    resolved, linked = {}, {}
    for h in sorted(ok):
        try:
            resolved[h] = resolve(scene.permutations[h], lib)
            if resolved[h].surface.alpha == "mask":
                linked[h] = link_permutation(resolved[h], lib)
        except (SourceError, KeyProblem, UserError):  # reported with the permutation; it casts no depth here
            resolved.pop(h, None)
    shadowed = {ln: t for ln, t in shadowed_lights(_Objects(scene, resolved), resolved.values()).items()
                if ln in manifest.get("lights", {})}
    # a light entry carried over from the last build (its objects' permutations failed) keeps no depth pass
    # of that build: the units it named are written only for the lights shadowed now
    for ln, light in list(manifest.get("lights", {}).items()):
        if ln not in shadowed and "depth_pass" in light:
            manifest["lights"][ln] = {k: v for k, v in light.items() if k != "depth_pass"}
    if not shadowed:
        return
    plan = depth_plan(shadowed, linked)
    units = compose_depth_units(plan, lib, ctx.languages, ctx.dialects)
    manifest["depth_shaders"] = _write_units(build, units)
    conventions = {p: (c.depth_range, c.ndc_y, c.framebuffer_origin)
                   for p, c in ((p, PLATFORM_TABLE[p].conventions) for p in ctx.platforms)}
    textures_of = {h: e["interface"]["frag"].get("textures", []) for h, e in ok.items()}
    for ln, textures in shadowed.items():
        light = manifest["lights"][ln]
        binds = bindings(ln, textures, _Objects(scene, resolved).objects, textures_of, scene)
        light["depth_pass"] = depth_pass(scene.lights[ln], textures, light["params"],
                                         pass_units(plan, MOMENTS in textures), binds, SHADOW_SIZE, conventions)


class _Objects:
    """The scene as shadowed_lights reads it, its objects narrowed to those whose permutation resolved."""

    def __init__(self, scene, resolved: dict):
        self.lights = scene.lights
        self.objects = [o for o in scene.objects if o["permutation"] in resolved]


def _write_units(build, units: dict) -> dict:
    """{unit name: manifest entry} of the composed depth units: kept from the last manifest where nothing they
    depend on changed, else compiled (SPIR-V checks of every language, the dialects validated) and written."""
    from ..toolchain import compile_many
    from ..toolchain.jobs import source_jobs

    ctx, res = build.ctx, build.res
    before = (build.previous.get("depth_shaders") or {})
    entries, todo = {}, {}
    for name, c in units.items():
        key = content_key(build.base, "depth unit", name, [s.text for s in [*c.sources, *c.dialects]])
        old = before.get(name)
        if old is not None and old.get("input_key") == key and old.get("status") == "ok" \
                and build.intact(old, old["hash"]):
            entries[name] = old
            res.unchanged += build.files(old)
        else:
            entries[name] = {"key": c.key, "hash": c.hash, "input_key": key, "languages": {},
                             "interface": c.interface.as_dict()}
            todo[name] = c
    if not todo:
        return entries
    jobs = [j for name, c in todo.items() for j in source_jobs(name, c.sources)]
    results = compile_many(jobs, optimize=True, validate=True, store=ctx.store, stats=res.compile, workers=ctx.jobs,
                           gate=ctx.gate)
    checked = validate_dialects(list(todo.items()), ctx.store, ctx.gate) if ctx.dialects else {}
    line, col = build.scene.head_at
    for name, c in todo.items():
        entry = entries[name]
        errs = build.writer.unit(name, c.sources, results, entry)
        if not errs:
            errs = build.writer.platforms(name, c, entry, checked, "fp32")
        if build.writer.spool is not None:  # build --pack-only: what its packs hold of the unit (spool.py)
            build.writer.spool.settle(entry, entry["hash"], ctx.platforms)
        entry["status"] = "failed" if errs else "ok"
        if errs:
            entry["errors"] = errs
            res.failures.append("\n  ".join([f"{build.scene.path}:{line}:{col}: the depth pass shader {name} "
                                             f"({c.key}) does not build — fix the errors below", *errs]))
    return entries
