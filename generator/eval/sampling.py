"""Sample a BRDF's terms and evaluate their pdfs in NumPy and on the GPU (link/sampling.py's program).

``sample(spec, u, V, N, T=None, params=None, term=0)`` returns unit directions L (n, 3) drawn by term
`term`'s sampler from uniforms u (n, 2) in [0, 1)²; ``pdf(spec, L, V, N, T=None, params=None, term=0)``
the density (n,) per unit solid angle that sampler draws L with (0 for L below the surface, which a
sampler may return: score such a sample 0). ``how(spec)`` says per term which sampler runs (its own, or
the cosine-weighted fallback and why). T is the tangent; B = N × T as in the eval kernels. For a BRDF
that does not read the tangent frame T may be left out: any orthonormal frame about N serves and one is
built (Duff et al. 2017). Parameters as for evaluate() (defaults filled in, ranges checked).

One-sample MIS over the terms (the lecture's multi-layer rule: sample one term, evaluate every term's pdf
scaled by its selection probability): ``mixture_sample(spec, u3, V, N, ...)`` draws with u3 (n, 3), u3[:, 2]
picking term k with probability w_k(n·v); ``mixture_pdf(spec, L, V, N, ...)`` is Σ_k w_k pdf_k(L). The
weights are ``mis_weights(spec, params)`` unless given: each term's directional albedo at the material's
parameters, estimated on the host at MIS_VIEWS view angles and interpolated in n·v by the shader.
``target`` "numpy" runs the linked program in NumPy (float64, or dtype); "glsl" / "hlsl" / "wgsl" run the
mixture's compute kernels on the GPU (float32) through the eval kernel machinery, in `session`.
"""
from __future__ import annotations

import numpy as np

from ..library.bricks import library_or_builtin
from ..link.sampling import MIS_PARAMS, MIS_TERMS, MIS_VIEWS, SamplingProgram, kernel_programs, sampling_program
from .evaluate import EvalError, _numpy_arg, _param_block, evaluate, own_session, program, resolve_params

GPU_TARGETS = ("glsl", "hlsl", "wgsl")
MIS_MIN_COS = 0.05  # the grazing node n.v = 0 is estimated at this cosine (a sampler's density is 1/(n.v) there)
MIS_GRID = 32  # the albedo estimate's stratified uniforms: MIS_GRID² cell centres, the same every call
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # Rec. 709: what an RGB term's albedo is weighed by


def linked(spec: str, lib=None) -> SamplingProgram:
    """The sampling program of a spec (kept in the library's memo)."""
    lib = library_or_builtin(lib)
    key = ("sampling_program", spec)
    if key not in lib.memo:
        lib.memo[key] = sampling_program(spec, lib)
    return lib.memo[key]


def how(spec: str, lib=None) -> tuple[str, ...]:
    """Per term of the BRDF, which sampler `sample` runs ("lambert: own sampler", "… cosine-weighted fallback (why)")."""
    return linked(spec, lib).how


def _functions(spec: str, lib, dtype: str) -> dict:
    from ..backends.numpy.emit import NumpyTarget

    lib = library_or_builtin(lib)
    key = ("numpy_sampling", spec, dtype)
    if key not in lib.memo:
        sp = linked(spec, lib)
        t = NumpyTarget()
        lib.memo[key] = t.load(t.emit(sp.program.structs, sp.program.functions), np.dtype(dtype))
    return lib.memo[key]


def frame(N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """An orthonormal (T, B) about unit normals N (n, 3), without a branch on a reference axis (Duff et al. 2017)."""
    s = np.where(N[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (s + N[:, 2])
    b = N[:, 0] * N[:, 1] * a
    T = np.stack([1.0 + s * N[:, 0] ** 2 * a, s * b, -s * N[:, 0]], -1)
    B = np.stack([b, s + N[:, 1] ** 2 * a, -N[:, 1]], -1)
    return T, B


def _frame_arrays(ep, first, width, V, N, T, n=None):
    first = np.asarray(first, np.float64)
    if first.ndim != 2 or first.shape[1] != width:
        name = "u" if width == 2 else "u3 or L"
        raise EvalError(f"{name} has shape {first.shape}", f"pass it as an array of shape (n, {width})")
    n = len(first)
    V, N = (np.broadcast_to(np.asarray(a, np.float64), (n, 3)) for a in (V, N))
    if T is None:
        if ep.tangent:
            raise EvalError(f"BRDF '{ep.spec}' reads the tangent frame but no T was given", "pass T of shape (n, 3)")
        T, B = frame(N)
    else:
        T = np.broadcast_to(np.asarray(T, np.float64), (n, 3))
        B = np.cross(N, T)
    return first, V, N, T, B


def _run(spec, what, first, V, N, T, params, term, lib, dtype):
    lib = library_or_builtin(lib)
    ep = program(spec, lib)
    sp = linked(spec, lib)
    if not 0 <= term < sp.terms:
        raise EvalError(f"term {term} of BRDF '{ep.spec}', which has {sp.terms}", f"pass term in 0..{sp.terms - 1}")
    first, V, N, T, B = _frame_arrays(ep, first, 2 if what == "sample" else 3, V, N, T)
    values = resolve_params(ep, params)
    f = np.dtype(dtype).type
    args = [a.astype(f) for a in (first, V, N, T, B)]
    args += [_numpy_arg(ty, values[name], f) for name, _, _, ty, _ in sp.specs.flat]
    with np.errstate(all="ignore"):  # masked-out lanes of a select may overflow; what is returned is checked
        out = _functions(spec, lib, dtype)[f"{what}_{term}"](*args)
    shape = (len(first), 3) if what == "sample" else (len(first),)
    return np.broadcast_to(np.asarray(out, np.float64), shape).copy()


def sample(spec: str, u, V, N, T=None, params: dict | None = None, term: int = 0, lib=None,
           dtype: str = "float64") -> np.ndarray:
    """Directions L (n, 3) drawn by term `term`'s sampler from uniforms u (n, 2)."""
    return _run(spec, "sample", u, V, N, T, params, term, lib, dtype)


def pdf(spec: str, L, V, N, T=None, params: dict | None = None, term: int = 0, lib=None,
        dtype: str = "float64") -> np.ndarray:
    """The density (n,) per unit solid angle with which term `term`'s sampler draws L."""
    return _run(spec, "pdf", L, V, N, T, params, term, lib, dtype)


# ------------------------------------------------------------------ the one-sample mixture over the terms

def mis_weights(spec: str, params: dict | None = None, lib=None) -> np.ndarray:
    """The selection weights (MIS_VIEWS, 4) the mixture reads: row j at n·v = j / (MIS_VIEWS - 1), column k term k.

    Term k's weight is its directional albedo ∫ f_k cos θ_l dω at the material's parameters, for V in the
    N-T plane at that view cosine (MIS_MIN_COS at the grazing node), estimated with the term's own sampler
    from MIS_GRID² stratified uniforms (float64; the luminance of an RGB albedo), then normalized per row.
    A row whose terms all have albedo 0 picks them alike. One term: weight 1 everywhere."""
    lib = library_or_builtin(lib)
    sp = linked(spec, lib)
    table = np.zeros((MIS_VIEWS, 4))
    if sp.terms == 1:
        table[:, 0] = 1.0
        return table
    mu = np.maximum(np.arange(MIS_VIEWS) / (MIS_VIEWS - 1), MIS_MIN_COS)
    g = (np.arange(MIS_GRID) + 0.5) / MIS_GRID
    u = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    m = len(u)
    V = np.repeat(np.stack([np.sqrt(1.0 - mu * mu), np.zeros_like(mu), mu], -1), m, axis=0)
    N, T = np.array([[0.0, 0.0, 1.0]]), np.array([[1.0, 0.0, 0.0]])
    U = np.tile(u, (MIS_VIEWS, 1))
    values = dict(params or {})
    for k, node in enumerate(sp.rb.nodes):
        L = sample(spec, U, V, N, T, values, term=k, lib=lib)
        p = pdf(spec, L, V, N, T, values, term=k, lib=lib)
        ok = (p > 0.0) & (L[:, 2] > 0.0)
        own = {n: v for n, v in values.items() if n in program(node.key, lib).params}
        f = evaluate(node.key, L[ok], V[ok], np.broadcast_to(N, L[ok].shape), np.broadcast_to(T, L[ok].shape),
                     params=own, target="numpy", lib=lib)
        est = np.zeros(len(L))
        est[ok] = (f @ LUMINANCE) * L[ok, 2] / p[ok]
        table[:, k] = np.maximum(est.reshape(MIS_VIEWS, m).mean(axis=1), 0.0)
    sums = table.sum(axis=1)
    table[sums == 0.0, : sp.terms] = 1.0
    return table / table.sum(axis=1, keepdims=True)


def _table(spec, weights, params, lib) -> np.ndarray:
    """The (MIS_VIEWS, 4) weight table: mis_weights, a table given, or per-term weights the same at every view."""
    sp = linked(spec, lib)
    if weights is None:
        return mis_weights(spec, params, lib)
    w = np.asarray(weights, np.float64)
    if w.shape == (MIS_VIEWS, 4):
        return w
    if w.shape != (sp.terms,) or np.any(w < 0.0) or not w.sum() > 0.0:
        raise EvalError(f"weights of shape {w.shape} for BRDF '{sp.spec}' with {sp.terms} term(s)",
                        f"pass {sp.terms} non-negative weights, not all 0, or a ({MIS_VIEWS}, {MIS_TERMS}) table")
    table = np.zeros((MIS_VIEWS, 4))
    table[:, : sp.terms] = w / w.sum()
    return table


def _mixture(spec, what, first, V, N, T, params, weights, lib, target, dtype, session):
    lib = library_or_builtin(lib)
    ep = program(spec, lib)
    first, V, N, T, B = _frame_arrays(ep, first, 3, V, N, T)
    table = _table(spec, weights, params, lib)
    values = resolve_params(ep, params) | {n: list(table[j]) for j, n in enumerate(MIS_PARAMS)}
    if target == "numpy":
        sp = linked(spec, lib)
        f = np.dtype(dtype).type
        args = [a.astype(f) for a in (first, V, N, T, B)]
        args += [_numpy_arg(ty, values[name], f) for name, _, _, ty, _ in sp.kernel_specs.flat]
        with np.errstate(all="ignore"):
            out = _functions(spec, lib, dtype)[f"sampling_{what}"](*args)
        return np.broadcast_to(np.asarray(out, np.float64), (len(first), 3)).copy()
    if target not in GPU_TARGETS:
        raise EvalError(f"unknown sampling target '{target}'", f"use numpy or one of {', '.join(GPU_TARGETS)}")
    with own_session(session) as s:
        kernel, kep = gpu_kernel(spec, what, target, lib, s)
        vecs = [a.astype(np.float32) for a in (first, V, N, T)]
        return kernel.run(vecs, _param_block(kep, values)).astype(np.float64)


def mixture_sample(spec: str, u3, V, N, T=None, params=None, weights=None, lib=None, target: str = "numpy",
                   dtype: str = "float64", session=None) -> np.ndarray:
    """Directions L (n, 3) drawn by the mixture: u3[:, 2] picks term k with probability w_k, u3[:, :2] samples it.

    weights: None (mis_weights), one per term, or a (MIS_VIEWS, 4) table. target: "numpy" or a GPU language
    (float32, run in `session`, an EvalSession; None: one for this call)."""
    return _mixture(spec, "sample", u3, V, N, T, params, weights, lib, target, dtype, session)


def mixture_pdf(spec: str, L, V, N, T=None, params=None, weights=None, lib=None, target: str = "numpy",
                dtype: str = "float64", session=None) -> np.ndarray:
    """Σ_k w_k pdf_k(L) (n,): the density of the one-sample mixture over the BRDF's terms (arguments as for
    mixture_sample)."""
    return _mixture(spec, "pdf", L, V, N, T, params, weights, lib, target, dtype, session)[:, 0]


def gpu_kernel(spec: str, what: str, language: str, lib, session):
    """(EvalKernel, its eval program) of the mixture's `what` ("sample" / "pdf") kernel in one language, on the
    device of `session` (which keeps it): composed, compiled and validated as every eval kernel is."""
    from ..compose import compose_eval
    from ..runtime.eval_kernel import compile_kernel

    lib = library_or_builtin(lib)
    memo = ("sampling_kernels", spec)
    if memo not in lib.memo:
        lib.memo[memo] = kernel_programs(linked(spec, lib))
    ep = lib.memo[memo][what]
    key = ("sampling", lib.serial, spec, what, language)
    if key not in session.kernels:
        src = compose_eval(ep.spec, lib, (language,), ep=ep).sources[0]
        session.kernels[key] = compile_kernel(src, session.device, True, ep.param_vec4s)
    return session.kernels[key], ep
