"""Several BRDFs in one program behind a switch on a per-sample id: the ubershader's BRDF core.

`evaluate_switch(specs, ids, L, V, N, ...)` runs `brdf_switch` (link.switch_program):
sample i is evaluated with BRDF `specs[ids[i]]`. On GPU targets the id travels in the
w component of the sample's L (backends/*/templates/eval.*.j2), so the switch is on a value read
from a storage buffer, divergent within a workgroup. Each BRDF keeps its own parameters
(`b<k>_<name>` in the kernel): `params={"alpha": 0.3}` sets alpha of every BRDF that has
one, `params={"b1_alpha": 0.5}` that of BRDF 1 only.
"""
from __future__ import annotations

import numpy as np

from .. import DTYPES, GPU_TARGETS
from ..library.bricks import library_or_builtin
from ..link import EvalProgram, switch_program
from .evaluate import (EvalError, _numpy_arg, _numpy_texels, _param_block, _vectors, own_session, resolve_params,
                       resolve_textures)


def switch_kernel_program(specs: list[str], lib=None) -> EvalProgram:
    """The linked switch program of `specs` (kept in the library's memo)."""
    lib = library_or_builtin(lib)
    key = ("switch_program", tuple(specs))
    if key not in lib.memo:
        lib.memo[key] = switch_program(list(specs), lib)
    return lib.memo[key]


def _switch_values(ep: EvalProgram, params: dict | None) -> dict:
    """Per-BRDF parameter values from names shared by every BRDF (`alpha`) or meant for one (`b1_alpha`)."""
    params = dict(params or {})
    shared = {n for names in ep.own for n in names}
    unknown = sorted(k for k in params if k not in shared and k not in ep.specs)
    if unknown:
        raise EvalError(f"unknown parameter{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))} for "
                        f"the switch over {', '.join(ep.specs_of)}", f"use {', '.join(sorted(shared))} or b<k>_<name>")
    out = {}
    for k, names in enumerate(ep.own):
        for n in names:
            if f"b{k}_{n}" in params:
                out[f"b{k}_{n}"] = params[f"b{k}_{n}"]
            elif n in params:
                out[f"b{k}_{n}"] = params[n]
    return out


def evaluate_switch(specs: list[str], ids, L, V, N, T=None, params: dict | None = None, target: str = "numpy",
                    dtype: str | None = None, lib=None, textures: dict | None = None, session=None) -> np.ndarray:
    """f_r (N, 3) float64: sample i evaluated with BRDF specs[ids[i]] through one switch program (a GPU target on
    the device of `session`, a runtime.eval_kernel.EvalSession; None: one for this call alone)."""
    lib = library_or_builtin(lib)
    ep = switch_kernel_program(specs, lib)
    values = resolve_params(ep, _switch_values(ep, params))
    texels = resolve_textures(ep, textures)
    vecs = _vectors(L, V, N, T, ep.tangent, ep.spec)
    ids = np.asarray(ids)
    if ids.shape != (len(vecs[0]),) or ids.dtype.kind not in "iu":
        raise EvalError(f"ids has shape {ids.shape} and dtype {ids.dtype}", f"pass one int per sample ({len(vecs[0])})")
    if target in GPU_TARGETS:
        if dtype not in (None, "float32"):
            raise EvalError(f"target {target} runs in float32 on lavapipe, not {dtype}", "pass dtype float32 or none")
        with own_session(session) as own:
            return _run_gpu(ep, lib, target, vecs, values, ids, texels, own)
    if target != "numpy":
        raise EvalError(f"target {target!r} has no switch program", "use numpy, glsl, hlsl or wgsl")
    if (dtype or "float64") not in DTYPES:
        raise EvalError(f"unknown dtype {dtype!r}", f"use one of {', '.join(DTYPES)}")
    f = np.dtype(dtype or "float64").type
    args = [ids.astype(np.int32)] + [v.astype(f) for v in vecs[:3]]
    if ep.tangent:
        args += [vecs[3].astype(f), np.cross(args[3], vecs[3].astype(f)).astype(f)]
    args += [_numpy_arg(ty, values[n], f) for n, _, _, ty, _ in ep.specs.flat]
    args += [_numpy_texels(x, bool(d.get("srgb"))).astype(f) for x, (_, _, d) in zip(texels, ep.textures)]
    key = ("numpy_switch", ep.spec, np.dtype(f).name)
    if key not in lib.memo:
        from ..backends.numpy.emit import NumpyTarget
        t = NumpyTarget()
        lib.memo[key] = t.load(t.emit(ep.program.structs, ep.program.functions), np.dtype(f))["brdf_switch"]
    out = lib.memo[key](*args)
    return np.broadcast_to(np.asarray(out, np.float64), (len(ids), 3)).copy()


def _run_gpu(ep: EvalProgram, lib, language: str, vecs, values, ids, texels, session) -> np.ndarray:
    from ..compose import compose_eval
    from ..runtime.eval_kernel import Texture, compile_kernel

    key = ("switch", lib.serial, ep.spec, language)
    if key not in session.kernels:
        src = compose_eval(ep.spec, lib, (language,), ep=ep).sources[0]
        session.kernels[key] = compile_kernel(src, session.device, ep.tangent, ep.param_vec4s,
                                              textures=len(ep.textures))
    f32 = [v.astype(np.float32) for v in vecs]
    tex = [Texture(np.asarray(x), bool(d.get("srgb"))) for x, (_, _, d) in zip(texels, ep.textures)]
    return session.kernels[key].run(f32, _param_block(ep, values), ids=ids, textures=tex or None).astype(np.float64)
