"""Evaluate a BRDF spec on samples: float64 reference, NumPy emission, or a GPU eval kernel on lavapipe.

``evaluate(spec, L, V, N, T=None, params=None, target=..., dtype=...)`` returns
f_r as float64 (N, 3): the bare BRDF in 1/sr, no cosine, no π. Directions are
used as given (nothing is normalized unless a brick does it).

- ``reference``: generator.reference.reference_brdf, float64 only.
- ``numpy``: the NumPy emission of the same linked IR the eval kernels run, at
  float64, float32 or float16 (inputs and parameters are rounded to that dtype).
- ``glsl`` / ``hlsl`` / ``wgsl``: that language's eval kernel (compose_eval),
  compiled with the project toolchain (validated, spirv-opt -O) and dispatched
  on lavapipe, float32 or float16. float16 is the fp16 kernel (compose_eval
  precision "fp16": the BRDF and glue compute in half; samples, parameters and
  the result stay 32-bit and are converted at the kernel's entry and exit) and
  needs a device reporting shaderFloat16 (EvalError otherwise; lavapipe has it).
  The GPU targets run on the device of `session` (runtime.eval_kernel.EvalSession),
  which keeps the kernels it compiled, so a sweep that passes one session pays for
  compilation once; without one, a call opens a device of its own and closes it
  when it returns. Loaded NumPy programs are kept in the library's memo.

Parameters default to the bricks' defaults; a scalar for a vector parameter
splats. Every bad input raises :class:`EvalError` ("what — what to do").
"""
from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from .. import DTYPES, GPU_TARGETS, EVAL_TARGETS  # defined in the package, where the CLI reads them without numpy
from ..library.bricks import library_or_builtin
from ..compose import compose_eval
from ..link import EvalProgram, eval_program
from ..lang.errors import UserError


class EvalError(UserError, ValueError):
    """A bad argument to evaluate(); the message says what is wrong and what to do."""

    def __init__(self, what: str, todo: str):
        self.what, self.todo = what, todo
        super().__init__(f"{what} — {todo}")


# ------------------------------------------------------------------ caches

def program(spec: str, lib=None) -> EvalProgram:
    """The linked eval program of a spec (kept in the library's memo, per spec string)."""
    lib = library_or_builtin(lib)
    key = ("eval_program", spec)
    if key not in lib.memo:
        lib.memo[key] = eval_program(spec, lib)
    return lib.memo[key]


# ------------------------------------------------------------------ inputs

def resolve_params(ep: EvalProgram, params: dict | None) -> dict[str, list[float]]:
    """Every parameter of the BRDF as a flat list of floats (defaults filled in, ranges checked)."""
    params = dict(params or {})
    unknown = sorted(set(params) - set(ep.params))
    if unknown:
        known = ", ".join(ep.params) or "none"
        raise EvalError(f"unknown parameter{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))} "
                        f"for BRDF '{ep.spec}'", f"use its parameters: {known} (see `shadermatrix bricks`)")
    defaults, ranges = ep.defaults(), ep.ranges()
    out = {}
    for name, ty in ep.params.items():
        raw = params.get(name, defaults[name])
        if ty.kind == "array":  # one value per element, each flattened under the element's shader name
            problem = ep.specs[name].check(raw)
            if problem:
                raise EvalError(f"parameter '{name}' of '{ep.spec}': {problem}",
                                f"give a list of {ty.size} values of {ty.elem}")
            for i, v in enumerate(raw):
                v = list(v) if isinstance(v, (list, tuple)) else [v]
                out[f"{name}_{i}"] = [float(x) for x in (v * ty.elem.components if len(v) == 1 else v)]
            continue
        try:
            vals = np.asarray(raw, dtype=np.float64).reshape(-1).tolist()
        except (TypeError, ValueError):
            raise EvalError(f"parameter '{name}' = {raw!r} is not numeric",
                            f"give {ty} as numbers, RGB as f0=0.9,0.6,0.3") from None
        problem = ep.specs[name].check(vals if ty.kind != "scalar" or len(vals) != 1 else vals[0])
        if problem:
            rng = ranges[name]
            if "outside the range" in problem:
                hint = f"give values in [{rng[0]}, {rng[1]}]"
            elif "finite float32" in problem:
                hint = "give finite numbers of at most 3.4e38 in magnitude"
            elif ty.kind == "vector":
                hint = f"give {ty.components} numbers for {ty}, or one number to splat"
            else:
                hint = f"give {ty.components} number{'s' if ty.components > 1 else ''} for {ty}"
            raise EvalError(f"parameter '{name}' of '{ep.spec}': {problem}", hint)
        if len(vals) == 1 and ty.components > 1:
            vals = vals * ty.components
        out[name] = vals
    return out


def _vectors(L, V, N, T, tangent: bool, spec: str) -> list[np.ndarray]:
    """[L, V, N] (+ T when the BRDF reads the tangent frame) as float64 (n, 3) arrays of one length."""
    named = [("L", L), ("V", V), ("N", N)] + ([("T", T)] if T is not None else [])
    out = []
    for name, a in named:
        arr = np.asarray(a)
        if arr.dtype.kind not in "fiu" or arr.ndim != 2 or arr.shape[1] != 3:
            raise EvalError(f"{name} has shape {arr.shape} and dtype {arr.dtype}",
                            f"pass {name} as a float array of shape (N, 3)")
        out.append(arr.astype(np.float64, copy=False))
    if len({len(a) for a in out}) != 1:
        raise EvalError(f"L, V, N{', T' if T is not None else ''} have different lengths "
                        f"{[len(a) for a in out]}", "pass the same number of samples for each")
    if tangent and T is None:
        raise EvalError(f"BRDF '{spec}' reads the tangent frame but no T was given",
                        "pass T (samples of shape (N, 12) = [L, V, N, T])")
    return out if tangent else out[:3]


def _param_block(ep: EvalProgram, values: dict[str, list[float]]) -> np.ndarray:
    """The kernel's vec4 parameter array, packed as link.interface.layout placed it (a mat4 column-major)."""
    from ..link.interface import put

    block = np.zeros((max(ep.param_vec4s, 1), 4), np.float32)
    for slot in ep.slots:
        put(block.reshape(-1), slot, values[slot.name])
    return block


def _numpy_arg(ty, vals: list[float], dtype) -> np.ndarray:
    a = np.asarray(vals, dtype)
    if ty.kind == "scalar":
        return a[0]
    if ty.kind == "matrix":
        return a.reshape(4, 4).T  # columns were listed first; numpy matrices are m[..., :, j]
    return a


# ------------------------------------------------------------------ targets

def _run_reference(ep: EvalProgram, vecs, values, n: int) -> np.ndarray:
    from ..reference import reference_brdf

    ref_params = {}
    for k, ty in ep.params.items():
        if ty.kind == "array":
            ref_params[k] = [values[f"{k}_{i}"] for i in range(ty.size)]
        else:
            ref_params[k] = values[k][0] if ty.kind == "scalar" else list(values[k])
    T = vecs[3] if len(vecs) > 3 else None
    out = reference_brdf(ep.spec, vecs[0], vecs[1], vecs[2], T=T, params=ref_params)
    return np.asarray(out, np.float64).reshape(n, 3)


def _numpy_brdf(ep: EvalProgram, lib, dtype: str):
    from ..backends.numpy.emit import NumpyTarget

    key = ("numpy_brdf", ep.spec, dtype)
    if key not in lib.memo:
        t = NumpyTarget()
        fns = t.load(t.emit(ep.program.structs, ep.program.functions), np.dtype(dtype))
        lib.memo[key] = fns["brdf"]
    return lib.memo[key]


def resolve_textures(ep: EvalProgram, textures: dict | None) -> list:
    """The texel arrays of the textures the BRDF samples, in kernel order (EvalError when one is missing)."""
    textures = dict(textures or {})
    names = [n for n, _, _ in ep.textures]
    unknown = sorted(set(textures) - set(names))
    if unknown:
        raise EvalError(f"unknown texture{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))} "
                        f"for BRDF '{ep.spec}'", f"its textures: {', '.join(names) or 'none'}")
    for n, _ty, d in ep.textures:  # a lookup table the generator bakes from its reference
        if n not in textures and d.get("table"):
            textures[n] = baked_table(d)
    missing = [n for n in names if n not in textures]
    if missing:
        raise EvalError(f"BRDF '{ep.spec}' samples texture{'s' if len(missing) > 1 else ''} {', '.join(missing)}",
                        "pass textures={name: array (H, W, 4)} (float32 texels, or uint8 for an 8-bit image)")
    return [textures[n] for n in names]


def baked_table(decl: dict) -> np.ndarray:
    """The stored texels of a texture declaration's baked table (EvalError for a table the generator lacks)."""
    from ..reference.tables import TableError, baked
    try:
        return baked(decl["table"], decl["size"], decl["format"])
    except TableError as e:
        raise EvalError(str(e), "name a table of generator/reference/tables_*.py in the brick's texture") from None
    except ValueError as e:  # a size or format the baker refuses (a non-square cube, fp16 overflow, …)
        raise EvalError(f"table '{decl['table']}' at {decl['size']} {decl['format']}: {e}",
                        "change the texture's size or format in the brick") from None


def _numpy_texels(data, srgb: bool):
    """What the GPU samples, as floats: uint8 texels are normalized (and sRGB-decoded for an sRGB texture)."""
    a = np.asarray(data)
    if a.dtype == np.uint8:
        a = a.astype(np.float64) / 255.0
        if srgb:
            a = np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4)
    elif a.dtype == np.float16:  # an fp16 table: the sampler returns its values exactly
        a = a.astype(np.float64)
    return a


def _run_numpy(ep: EvalProgram, lib, vecs, values, dtype: str, n: int, texels=()) -> np.ndarray:
    f = np.dtype(dtype).type
    args = [v.astype(f) for v in vecs[:3]]
    if ep.tangent:
        T = vecs[3].astype(f)
        with np.errstate(all="ignore"):
            args += [T, np.cross(args[2], T).astype(f)]  # B = cross(N, T), as in the eval kernels
    args += [_numpy_arg(ty, values[n], f) for n, _, _, ty, _ in ep.specs.flat]
    args += [_numpy_texels(x, bool(d.get("srgb"))).astype(f) for x, (_, _, d) in zip(texels, ep.textures)]
    out = _numpy_brdf(ep, lib, dtype)(*args)
    return np.broadcast_to(np.asarray(out, np.float64), (n, 3)).copy()


@contextmanager
def own_session(session):
    """`session`, or where it is None an EvalSession made for this call alone, closed when the call ends."""
    if session is not None:
        yield session
        return
    from ..runtime.eval_kernel import EvalSession
    with EvalSession() as own:
        yield own


def gpu_kernel(spec: str, language: str, lib, session, precision: str = "fp32"):
    """The EvalKernel of a spec in one language on the device of `session` (an EvalSession, which keeps it);
    precision "fp16" gives the half kernel (the device must report shaderFloat16)."""
    from ..runtime.eval_kernel import compile_kernel

    lib = library_or_builtin(lib)
    ep = program(spec, lib)
    key = ("eval", lib.serial, ep.spec, language) + ((precision,) if precision != "fp32" else ())
    if key not in session.kernels:
        src = compose_eval(ep.spec, lib, (language,), ep=ep, precision=precision).sources[0]
        session.kernels[key] = compile_kernel(src, session.device, ep.tangent, ep.param_vec4s,
                                              textures=len(ep.textures))
    return session.kernels[key]


def gpu_fp16_status(session) -> tuple[bool, str]:
    """(whether fp16 eval kernels run on the device of `session`, why not): it must report shaderFloat16."""
    device = session.device
    if device.fp16:
        return True, ""
    return False, f"{device.name} does not report shaderFloat16 and 16-bit storage access"


def _run_gpu(ep: EvalProgram, lib, language: str, vecs, values, texels, dtype: str, session) -> np.ndarray:
    from ..runtime.eval_kernel import Texture

    if dtype == "float16":
        ok, why = gpu_fp16_status(session)
        if not ok:
            from ..runtime.device import Fp16Unsupported
            raise Fp16Unsupported(f"target {language} cannot run float16 here: {why} — evaluate float32 on the "
                                  "GPU, or float16 with --target numpy")
    kernel = gpu_kernel(ep.spec, language, lib, session, precision="fp16" if dtype == "float16" else "fp32")
    f32 = [v.astype(np.float32) for v in vecs]
    textures = [Texture(np.asarray(x), bool(d.get("srgb"))) for x, (_, _, d) in zip(texels, ep.textures)]
    return kernel.run(f32, _param_block(ep, values), textures=textures or None).astype(np.float64)


def evaluate(spec: str, L, V, N, T=None, params: dict | None = None, target: str = "reference",
             dtype: str | None = None, lib=None, textures: dict | None = None, session=None) -> np.ndarray:
    """f_r (N, 3) float64 of BRDF `spec` for unit vectors L, V, N (and T) of shape (N, 3).

    session: the runtime.eval_kernel.EvalSession a GPU target runs on (None: one for this call alone).

    textures: {name: texels (H, W, 4)} for a BRDF that samples lookup tables; the GPU samples
    them bilinearly with clamp-to-edge at level 0 (runtime.images.Sampler) and the NumPy target
    filters the same texels the same way.

    dtype: float64 (default) for reference and numpy; float32/float16 for numpy;
    GPU targets compute in float32 (their default) or float16 (the fp16 kernel, where the
    device reports shaderFloat16); float64 is an error for them. Inputs and parameters reach
    the fp16 kernel as float32 and are rounded to half inside it.
    """
    if target not in EVAL_TARGETS:
        raise EvalError(f"unknown target {target!r}", f"use one of {', '.join(EVAL_TARGETS)}")
    if dtype is not None:
        dtype = np.dtype(dtype).name if isinstance(dtype, type) or hasattr(dtype, "name") else str(dtype)
    if target in GPU_TARGETS:
        if dtype not in (None, "float32", "float16"):
            raise EvalError(f"target {target} runs in float32 or float16 on lavapipe, not {dtype}",
                            "pass --dtype float32 (or none) or float16 for GPU targets; numpy runs float64")
        dtype = dtype or "float32"
    elif target == "reference":
        if dtype not in (None, "float64"):
            raise EvalError(f"the reference is float64 only, not {dtype}",
                            "pass --dtype float64 (or none), or use --target numpy for other dtypes")
        dtype = "float64"
    else:
        dtype = dtype or "float64"
        if dtype not in DTYPES:
            raise EvalError(f"unknown dtype {dtype!r}", f"use one of {', '.join(DTYPES)}")
    lib = library_or_builtin(lib)
    ep = program(spec, lib)
    values = resolve_params(ep, params)
    vecs = _vectors(L, V, N, T, ep.tangent, ep.spec)
    n = len(vecs[0])
    if n == 0:
        return np.zeros((0, 3), np.float64)
    texels = resolve_textures(ep, textures)
    if target == "reference":
        return _run_reference(ep, vecs, values, n)
    if target == "numpy":
        return _run_numpy(ep, lib, vecs, values, dtype, n, texels)
    with own_session(session) as s:
        return _run_gpu(ep, lib, target, vecs, values, texels, dtype, s)

