"""Run a permutation's fragment glue, shade(), on samples: NumPy, or a shade kernel on lavapipe.

`shade_samples(perm, P, Ng, V, ...)` returns shade()'s vec4 per sample: the packing, the
normal, the light loop (static lights and storage-buffer lights alike) and the output brick,
exactly as the fragment shader computes them, in a compute kernel
(compose.compose_shade_kernel) so no graphics pipeline is needed. Values are given by the
glue's names (`m_rho_d`, `l0_color`, `o_ev`; the bricks' defaults otherwise); the lights of
dynamic light i are `buffers={i: {"position": (n, 3), "color": (n, 3)}}`. A GPU target runs on the
device of `session` (runtime.eval_kernel.EvalSession, which keeps each kernel's SPIR-V; None: one
for the call alone).
"""
from __future__ import annotations

import numpy as np

from .. import GPU_TARGETS
from ..library.bricks import library_or_builtin
from .evaluate import EvalError, own_session


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


def _buffer_fields(slots, given: dict, n: int) -> dict[str, np.ndarray]:
    """The `data` field, (n, vec4s, 4) float, of n LightData elements from the lights' parameter values, each at
    its slot (the LightBuffer block's parameters; a mat4's columns first)."""
    vec4s = max([1] + [s.index + s.width for s in slots])
    data = np.zeros((n, vec4s * 4), np.float64)
    for s in slots:
        v = np.asarray(given[s.param], np.float64).reshape(n, -1)
        data[:, s.words()] = np.repeat(v, s.ty.components, 1) if v.shape[1] == 1 else v
    return {"data": data.reshape(n, vec4s, 4)}


def shade_samples(perm, P, Ng, V, T=None, uv=None, values: dict | None = None, buffers: dict | None = None,
                  target: str = "numpy", lib=None, session=None) -> np.ndarray:
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
    fields = {i: _buffer_fields(lp.interface.block(f"LightBuffer{i}").slots, b, len(next(iter(b.values()))))
              for i, b in buffers.items()}
    n = len(P)
    if target == "numpy":
        return _numpy(lp, P, Ng, V, T, uv, vals, fields, globs)
    if target not in GPU_TARGETS:
        raise EvalError(f"unknown target {target!r}", f"use numpy or one of {', '.join(GPU_TARGETS)}")
    rows = [P, Ng, V] + ([np.asarray(T)[:, :4]] if T is not None else []) + ([uv] if uv is not None else [])
    with own_session(session) as own:
        return _run(own, c.sources[0], _samples(rows, n), _blocks(c, vals, fields, globs), what="shade kernel")


def _linked(perm, lib):
    """The shade-kernel link of a permutation (kept in the library's memo)."""
    from ..link import link_permutation

    key = ("shade_program", perm.canonical())
    if key not in lib.memo:
        lib.memo[key] = link_permutation(perm, lib, kernel=True)
    return lib.memo[key]


def _numpy(lp, P, Ng, V, T, uv, vals, fields, globs) -> np.ndarray:
    from ..backends.numpy.emit import NumpyTarget

    t = NumpyTarget()
    res = {globs[i].name: f for i, f in fields.items()}
    shade = t.load(t.emit(lp.program.structs, lp.program.functions, lp.program.globals), np.dtype("float64"),
                   resources=res)["shade"]
    local = _surface(P, Ng, V, T, uv)
    args = [local[name] if name in local else vals[name] for name, _ in lp.glue.signature]
    return np.broadcast_to(np.asarray(shade(*args), np.float64), (len(P), 4)).copy()


def _blocks(c, vals, fields, globs) -> list:
    """The shade kernel's Lights and Material blocks and its light buffers, as _run binds them."""
    from ..link.interface import pack
    from ..runtime.compute import STORAGE, UNIFORM

    blocks = [(UNIFORM, pack([s for ls in c.lights for s in ls], vals, c.interface.block("Lights").size // 16)),
              (UNIFORM, pack(c.material, vals, c.interface.block("Material").size // 16))]
    for i in sorted(globs):  # (n, vec4s, 4): LightData.data of each light
        blocks.append((STORAGE, fields[i]["data"].astype(np.float32)))
    return blocks


def _surface(P, Ng, V, T=None, uv=None) -> dict:
    """shade()'s surface arguments in float64 as the kernels compute them (Ng, V, T normalized; B = Ng × T · w)."""
    def unit(a):
        a = np.asarray(a, np.float64)
        return a / np.linalg.norm(a, axis=1, keepdims=True)

    local = {"P": np.asarray(P, np.float64), "Ng": unit(Ng), "V": unit(V)}
    if T is not None:
        T4 = np.asarray(T, np.float64)
        local["T"] = unit(T4[:, :3])
        local["B"] = np.cross(local["Ng"], local["T"]) * T4[:, 3:4]
    if uv is not None:
        local["uv"] = np.asarray(uv, np.float64)
    return local


def _samples(rows, n: int) -> np.ndarray:
    """The samples buffer of a shade kernel: one vec4 per row per sample (backends/*/templates/shade.*.j2)."""
    sample = np.zeros((n, len(rows), 4), np.float32)
    for j, r in enumerate(rows):
        r = np.asarray(r)
        sample[:, j, :r.shape[1]] = r
    return sample


def _run(session, source, sample: np.ndarray, blocks: list, spec: dict | None = None,
         what: str = "kernel") -> np.ndarray:
    """Compile (once per session) and dispatch a shade-style kernel on the session's device: set 0 = samples,
    result, Info, then `blocks` ((STORAGE | UNIFORM, bytes or array) each); returns the (n, 4) results as float64."""
    from ..runtime.compute import STORAGE, UNIFORM, ComputePipeline
    from ..runtime.eval_kernel import KernelError
    from ..toolchain import CompileJob, compile_many

    # WebGPU keys an override declared with @id(N) by N; GLSL/HLSL keep the SpecId for the pipeline
    over = tuple((str(i), v) for i, v in spec.items()) if spec and source.language == "wgsl" else ()
    key = (source.language, source.text, over)
    if key not in session.spirv:
        job = CompileJob(f"{what.replace(' ', '-')}.comp.{source.language}", source.language, "comp", source.text,
                         line_map=tuple(map(tuple, source.line_map)), overrides=over)
        res = compile_many([job])[job.key]
        if not res.ok:
            raise KernelError(f"the {source.language} {what} does not compile: " + "; ".join(res.errors()))
        session.spirv[key] = res.spirv
    device = session.device
    vk = device.vk
    n = len(sample)
    pipe = ComputePipeline(device, session.spirv[key], (STORAGE, STORAGE, UNIFORM) + tuple(k for k, _ in blocks),
                           specialization=spec if source.language != "wgsl" else None)
    usage = {STORAGE: vk.VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, UNIFORM: vk.VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT}
    raw = [sample, np.zeros((n, 4), np.float32), np.array([n, 0, 0, 0], np.uint32)]
    raw += [np.frombuffer(bytes(d), np.uint8) if isinstance(d, (bytes, bytearray)) else np.asarray(d) for _, d in blocks]
    kinds = (STORAGE, STORAGE, UNIFORM) + tuple(k for k, _ in blocks)
    bufs = []
    try:
        for kind, data in zip(kinds, raw):
            b = device.buffer(max(data.nbytes, 16), usage[kind])
            bufs.append(b)
            b.write(data)
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
    from ..link.values import light_entry

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
        ldata[i] = light_entry(u, t, s, values)
    return {"ids": mids, "data": mdata}, {"ids": lids[:len(lights)], "data": ldata[:len(lights)]}


def _values_of(slots, values: dict) -> dict:
    out = {}
    for s in slots:
        v = values.get(s.name)
        out[s.name] = v if v is not None else (s.spec.default if s.element is None else s.spec.default[s.element])
    return out


def uber_samples(perms, P, Ng, V, material, materials, lights, target: str = "numpy", lib=None,
                 variant: int | None = None, T=None, uv=None, session=None) -> np.ndarray:
    """The ubershader kernel's shade() (N, 4): sample i shaded as material material[i] under `lights`.

    materials: (variant index, {glue name: value}); lights: (light type, shadow, {param: value}), looped over
    with a runtime count. variant: run the specialization-constant ubershader with its variant set to this
    (a pipeline of its own: SpecId 0 in GLSL/HLSL, naga's override in WGSL) instead of reading ids.x.
    T: (N, 4) tangents (w: the bitangent's sign) and uv: (N, 2), when the ubershader reads them.
    session: the EvalSession a GPU target runs on (None: one for this call alone).
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
        from ..backends.numpy.emit import NumpyTarget
        t = NumpyTarget()
        res = {"material_buffer": mat, "light_buffer": lts}
        if variant is not None:
            res["material_variant"] = np.int32(variant)
        shade = t.load(t.emit(u.program.structs, u.program.functions, u.program.globals), np.dtype("float64"),
                       resources=res)["shade"]
        local = {**_surface(P, Ng, V, T, uv), "material": material}
        return np.broadcast_to(np.asarray(shade(*[local[name] for name, _ in u.signature]), np.float64),
                               (n, 4)).copy()
    from ..link.values import entry_bytes
    from ..runtime.compute import STORAGE

    spec = None if variant is None else {SPEC_VARIANT: int(variant)}
    rows = [P, Ng, V] + ([T] if "T" in u.surface else []) + ([uv] if "uv" in u.surface else [])
    sample = _samples(rows, n)
    sample[:, 0, 3] = material  # P.w: the material index (backends/*/templates/shade.*.j2 with `uber`)
    blocks = [(STORAGE, entry_bytes(lts["ids"], lts["data"])), (STORAGE, entry_bytes(mat["ids"], mat["data"]))]
    with own_session(session) as own:
        return _run(own, c.sources[0], sample, blocks, spec, what="ubershader kernel")
