"""Run a permutation's fragment glue, shade(), on samples: NumPy, or a shade kernel on lavapipe.

`shade_samples(perm, P, Ng, V, ...)` returns shade()'s vec4 per sample: the packing, the
normal, the light loop (static lights and storage-buffer lights alike) and the output brick,
exactly as the fragment shader computes them, in a compute kernel
(compose.compose_shade_kernel) so no graphics pipeline is needed. Values are given by the
glue's names (`m_rho_d`, `l0_color`, `o_ev`; the bricks' defaults otherwise); the lights of
dynamic light i are `buffers={i: {"position": (n, 3), "color": (n, 3)}}`.
"""
from __future__ import annotations

import numpy as np

from .. import GPU_TARGETS
from ..library.bricks import library_or_builtin
from .evaluate import EvalError


def _values(c, values: dict | None) -> dict:
    values = dict(values or {})
    slots = c.material + [s for ls in c.lights for s in ls]
    names = {s.name for s in slots}
    unknown = sorted(set(values) - names)
    if unknown:
        raise EvalError(f"unknown shade() value {', '.join(map(repr, unknown))}", f"use {', '.join(sorted(names))}")
    out = {}
    for s in slots:
        v = values.get(s.name, None)
        if v is None:
            v = s.spec.default if s.element is None else s.spec.default[s.element]
        out[s.name] = v
    return out


def _buffer_fields(glob, given: dict, n: int) -> dict[str, np.ndarray]:
    """(n, 4) float arrays per field of a LightData struct from the lights' parameter values."""
    out = {}
    for f, _ in glob.ty.elem.fields:
        if "_c" in f and f[:f.rindex("_c")] in given:  # a mat4 column
            name, c = f[:f.rindex("_c")], int(f[f.rindex("_c") + 2:])
            out[f] = np.asarray(given[name], np.float64).reshape(n, 4, 4)[:, c, :]
            continue
        v = np.asarray(given[f], np.float64).reshape(n, -1)
        out[f] = np.concatenate([v, np.zeros((n, 4 - v.shape[1]))], 1)
    return out


def shade_samples(perm, P, Ng, V, T=None, uv=None, values: dict | None = None, buffers: dict | None = None,
                  target: str = "numpy", lib=None) -> np.ndarray:
    """shade()'s vec4 (N, 4) float64 for each sample; see the module docstring."""
    from ..compose import compose_shade_kernel

    lib = library_or_builtin(lib)
    c = compose_shade_kernel(perm, lib, () if target == "numpy" else (target,))
    vals = _values(c, values)
    buffers = dict(buffers or {})
    lp = _linked(perm, lib)
    globs = {int(g.name[len("light_buffer"):]): g for g in lp.program.globals}
    if set(buffers) != set(globs):
        raise EvalError(f"permutation has buffer lights {sorted(globs)}, got buffers for {sorted(buffers)}",
                        "give buffers={light index: {parameter: values per light}}")
    fields = {i: _buffer_fields(globs[i], b, len(next(iter(b.values())))) for i, b in buffers.items()}
    n = len(P)
    if target == "numpy":
        return _numpy(lp, P, Ng, V, T, uv, vals, fields, globs)
    if target not in GPU_TARGETS:
        raise EvalError(f"unknown target {target!r}", f"use numpy or one of {', '.join(GPU_TARGETS)}")
    return _gpu(c.sources[0], c, n, P, Ng, V, T, uv, vals, fields, globs)


def _linked(perm, lib):
    """The shade-kernel link of a permutation (kept in the library's memo)."""
    from ..link import link_permutation

    key = ("shade_program", perm.canonical())
    if key not in lib.memo:
        lib.memo[key] = link_permutation(perm, lib, kernel=True)
    return lib.memo[key]


def _numpy(lp, P, Ng, V, T, uv, vals, fields, globs) -> np.ndarray:
    from ..targets.numpy import NumpyTarget

    t = NumpyTarget()
    res = {globs[i].name: f for i, f in fields.items()}
    shade = t.load(t.emit(lp.program.structs, lp.program.functions, lp.program.globals), np.dtype("float64"),
                   resources=res)["shade"]
    norm = lambda a: np.asarray(a, np.float64) / np.linalg.norm(a, axis=1, keepdims=True)  # noqa: E731
    local = {"P": np.asarray(P, np.float64), "Ng": norm(Ng), "V": norm(V)}
    if T is not None:
        T4 = np.asarray(T, np.float64)
        local["T"] = norm(T4[:, :3])
        local["B"] = np.cross(local["Ng"], local["T"]) * T4[:, 3:4]
    if uv is not None:
        local["uv"] = np.asarray(uv, np.float64)
    args = [local[name] if name in local else vals[name] for name, _ in lp.glue.signature]
    return np.broadcast_to(np.asarray(shade(*args), np.float64), (len(P), 4)).copy()


def _gpu(source, c, n, P, Ng, V, T, uv, vals, fields, globs) -> np.ndarray:
    from ..link.interface import pack
    from ..runtime.compute import STORAGE, UNIFORM, ComputePipeline
    from ..runtime.eval_kernel import KernelError, shared_device
    from ..toolchain import CompileJob, compile_many

    job = CompileJob(f"shade-{c.hash}.comp.{source.language}", source.language, "comp", source.text,
                     line_map=tuple(map(tuple, source.line_map)))
    res = compile_many([job])[job.key]
    if not res.ok:
        raise KernelError(f"the {source.language} shade kernel does not compile: " + "; ".join(res.errors()))
    device = shared_device()
    vk = device.vk
    order = sorted(globs)
    pipe = ComputePipeline(device, res.spirv, (STORAGE, STORAGE, UNIFORM, UNIFORM, UNIFORM) + (STORAGE,) * len(order))
    rows = [np.asarray(P), np.asarray(Ng), np.asarray(V)] + ([np.asarray(T)[:, :4]] if T is not None else []) \
        + ([np.asarray(uv)] if uv is not None else [])
    k = len(rows)
    sample = np.zeros((n, k, 4), np.float32)
    for j, r in enumerate(rows):
        sample[:, j, :r.shape[1]] = r
    usage_s, usage_u = vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
    lights_bytes = pack([s for ls in c.lights for s in ls], vals, c.interface.block("Lights").members[-1]["size"] // 16)
    mat_bytes = pack(c.material, vals, c.interface.block("Material").members[-1]["size"] // 16)
    bufs = [device.buffer(sample.nbytes, usage_s), device.buffer(16 * n, usage_s), device.buffer(16, usage_u),
            device.buffer(len(lights_bytes), usage_u), device.buffer(len(mat_bytes), usage_u)]
    for i in order:
        arr = np.stack([fields[i][f] for f, _ in globs[i].ty.elem.fields], 1).astype(np.float32)  # (n, fields, 4)
        b = device.buffer(max(arr.nbytes, 16), usage_s)
        b.array(np.float32)[: arr.size] = arr.reshape(-1)
        bufs.append(b)
    try:
        bufs[0].array(np.float32)[: sample.size] = sample.reshape(-1)
        bufs[2].array(np.uint32)[:4] = (n, 0, 0, 0)
        bufs[3].write(lights_bytes)
        bufs[4].write(mat_bytes)
        pipe.bind(bufs)
        pipe.dispatch(-(-n // 64))
        return bufs[1].array(np.float32)[: 4 * n].reshape(n, 4).astype(np.float64)
    finally:
        pipe.destroy()
        for b in bufs:
            b.destroy()


# ------------------------------------------------------------------ the ubershader's shade()

def uber_entries(u, materials: list[tuple[int, dict]], lights: list[tuple[str, str, dict]]):
    """MaterialEntry and LightEntry contents (ids int32 (n, 4), data float (n, vec4s, 4)) as link/uber.py lays them out.

    materials: (variant, {glue name: value}) per material; lights: (light type, shadow, {param: value}).
    """
    from ..link.interface import pack

    mids = np.zeros((len(materials), 4), np.int32)
    mdata = np.zeros((len(materials), u.material_vec4s, 4), np.float64)
    for m, (k, values) in enumerate(materials):
        v = u.variants[k]
        full = _values_of(v.slots, values)
        mids[m] = (k, 0, 0, 0)
        mdata[m] = np.frombuffer(pack(v.slots, full, u.material_vec4s), np.float32).reshape(-1, 4)
    lids = np.zeros((max(len(lights), 1), 4), np.int32)
    ldata = np.zeros((max(len(lights), 1), u.light_vec4s, 4), np.float64)
    for i, (t, s, values) in enumerate(lights):
        lids[i] = (u.light_types.index(t), u.shadows.index(s), 0, 0)
        for name, (j, ty) in u.light_layouts[(t, s)].items():
            val = np.asarray(values[name], np.float64).reshape(-1)
            if ty.kind == "vector" and len(val) == 1:  # a scalar for a vector parameter splats, as pack() does
                val = np.repeat(val, ty.components)
            for c in range(0, len(val), 4):
                ldata[i, j + c // 4, :len(val[c:c + 4])] = val[c:c + 4]
    return {"ids": mids, "data": mdata}, {"ids": lids[:len(lights)], "data": ldata[:len(lights)]}


def _values_of(slots, values: dict) -> dict:
    out = {}
    for s in slots:
        v = values.get(s.name)
        out[s.name] = v if v is not None else (s.spec.default if s.element is None else s.spec.default[s.element])
    return out


def uber_samples(perms, P, Ng, V, material, materials, lights, target: str = "numpy", lib=None,
                 variant: int | None = None, T=None, uv=None) -> np.ndarray:
    """The ubershader kernel's shade() (N, 4): sample i shaded as material material[i] under `lights`.

    materials: (variant index, {glue name: value}); lights: (light type, shadow, {param: value}), looped over
    with a runtime count. variant: run the specialization-constant ubershader with its variant set to this
    (a pipeline of its own: SpecId 0 in GLSL/HLSL, naga's override in WGSL) instead of reading ids.x.
    T: (N, 4) tangents (w: the bitangent's sign) and uv: (N, 2), when the ubershader reads them.
    """
    from ..compose.uber import compose_uber_kernel
    from ..link.uber import SPEC_VARIANT

    lib = library_or_builtin(lib)
    c, u = compose_uber_kernel(perms, lib, () if target == "numpy" else (target,), specialized=variant is not None)
    mat, lts = uber_entries(u, materials, lights)
    n = len(P)
    material = np.asarray(material, np.int32)
    for name, given in (("T", T), ("uv", uv)):
        if name in u.surface and given is None:
            raise EvalError(f"the ubershader of these permutations reads {name}", f"pass {name}= per sample")
    if target == "numpy":
        from ..targets.numpy import NumpyTarget
        t = NumpyTarget()
        res = {"material_buffer": mat, "light_buffer": lts}
        if variant is not None:
            res["material_variant"] = np.int32(variant)
        shade = t.load(t.emit(u.program.structs, u.program.functions, u.program.globals), np.dtype("float64"),
                       resources=res)["shade"]
        norm = lambda a: np.asarray(a, np.float64) / np.linalg.norm(a, axis=1, keepdims=True)  # noqa: E731
        local = {"P": np.asarray(P, np.float64), "Ng": norm(Ng), "V": norm(V), "material": material}
        if T is not None:
            T4 = np.asarray(T, np.float64)
            local["T"] = norm(T4[:, :3])
            local["B"] = np.cross(local["Ng"], local["T"]) * T4[:, 3:4]
        if uv is not None:
            local["uv"] = np.asarray(uv, np.float64)
        return np.broadcast_to(np.asarray(shade(*[local[name] for name, _ in u.signature]), np.float64),
                               (n, 4)).copy()
    spec = None if variant is None else {SPEC_VARIANT: int(variant)}
    rows = [P, Ng, V] + ([T] if "T" in u.surface else []) + ([uv] if "uv" in u.surface else [])
    return _gpu_uber(c.sources[0], n, rows, material, mat, lts, spec)


def _gpu_uber(source, n, rows, material, mat, lts, spec=None) -> np.ndarray:
    from ..runtime.compute import STORAGE, UNIFORM, ComputePipeline
    from ..runtime.eval_kernel import KernelError, shared_device
    from ..toolchain import CompileJob, compile_many

    # WebGPU keys an override declared with @id(N) by N
    over = tuple((str(i), v) for i, v in spec.items()) if spec and source.language == "wgsl" else ()
    job = CompileJob(f"uber-{len(source.text)}.comp.{source.language}", source.language, "comp", source.text,
                     line_map=tuple(map(tuple, source.line_map)), overrides=over)
    res = compile_many([job])[job.key]
    if not res.ok:
        raise KernelError(f"the {source.language} ubershader kernel does not compile: " + "; ".join(res.errors()))
    device = shared_device()
    vk = device.vk
    pipe = ComputePipeline(device, res.spirv, (STORAGE, STORAGE, UNIFORM, STORAGE, STORAGE),
                           specialization=spec if source.language != "wgsl" else None)
    sample = np.zeros((n, len(rows), 4), np.float32)  # P (w: the material), Ng, V[, T][, uv]: templates/*/shade
    for j, r in enumerate(rows):
        r = np.asarray(r)
        sample[:, j, :r.shape[1]] = r
    sample[:, 0, 3] = material
    usage_s, usage_u = vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT

    def entries(e):
        k = e["data"].shape[1]
        raw = np.zeros((len(e["ids"]), 1 + k, 4), np.float32)
        raw[:, 1:, :] = e["data"]
        raw = raw.view(np.uint32)
        raw[:, 0, :] = e["ids"].astype(np.int32).view(np.uint32)
        return raw

    lraw, mraw = entries(lts), entries(mat)
    bufs = [device.buffer(sample.nbytes, usage_s), device.buffer(16 * n, usage_s), device.buffer(16, usage_u),
            device.buffer(max(lraw.nbytes, 16), usage_s), device.buffer(max(mraw.nbytes, 16), usage_s)]
    try:
        bufs[0].array(np.float32)[: sample.size] = sample.reshape(-1)
        bufs[2].array(np.uint32)[:4] = (n, 0, 0, 0)
        bufs[3].array(np.uint32)[: lraw.size] = lraw.reshape(-1)
        bufs[4].array(np.uint32)[: mraw.size] = mraw.reshape(-1)
        pipe.bind(bufs)
        pipe.dispatch(-(-n // 64))
        return bufs[1].array(np.float32)[: 4 * n].reshape(n, 4).astype(np.float64)
    finally:
        pipe.destroy()
        for b in bufs:
            b.destroy()
