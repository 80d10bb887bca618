"""Sample a BRDF's terms and evaluate their pdfs in NumPy (the NumPy emission of link/sampling.py's program).

``sample(spec, u, V, N, T=None, params=None, term=0)`` returns unit directions L (n, 3) drawn by term
`term`'s sampler from uniforms u (n, 2) in [0, 1)²; ``pdf(spec, L, V, N, T=None, params=None, term=0)``
the density (n,) per unit solid angle that sampler draws L with (0 for L below the surface, which a
sampler may return: score such a sample 0). ``how(spec)`` says per term which sampler runs (its own, or
the cosine-weighted fallback and why). T is the tangent; B = N × T as in the eval kernels. For a BRDF
that does not read the tangent frame T may be left out: any orthonormal frame about N serves and one is
built (Duff et al. 2017). Parameters as for evaluate() (defaults filled in, ranges checked).

``mixture_pdf(spec, weights, L, ...)`` is the pdf of the one-sample mixture that picks term k with
probability weights[k] (the lecture's multi-layer rule: evaluate every term's pdf, scale each by its
selection probability); ``mixture_sample`` draws from it with a third uniform.
"""
from __future__ import annotations

import numpy as np

from ..library.bricks import library_or_builtin
from ..link.sampling import SamplingProgram, sampling_program
from .evaluate import EvalError, _numpy_arg, program, resolve_params


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


def _run(spec, what, first, V, N, T, params, term, lib, dtype):
    lib = library_or_builtin(lib)
    ep = program(spec, lib)
    sp = linked(spec, lib)
    if not 0 <= term < sp.terms:
        raise EvalError(f"term {term} of BRDF '{ep.spec}', which has {sp.terms}", f"pass term in 0..{sp.terms - 1}")
    arrays = [np.asarray(a, np.float64) for a in (first, V, N)]
    width = 2 if what == "sample" else 3
    if arrays[0].ndim != 2 or arrays[0].shape[1] != width:
        raise EvalError(f"{'u' if what == 'sample' else 'L'} has shape {arrays[0].shape}",
                        f"pass it as an array of shape (n, {width})")
    n = len(arrays[0])
    V, N = (np.broadcast_to(a, (n, 3)) for a in arrays[1:])
    if T is None:
        if ep.tangent:
            raise EvalError(f"BRDF '{ep.spec}' reads the tangent frame but no T was given", "pass T of shape (n, 3)")
        T, B = frame(N)
    else:
        T = np.broadcast_to(np.asarray(T, np.float64), (n, 3))
        B = np.cross(N, T)
    values = resolve_params(ep, params)
    f = np.dtype(dtype).type
    args = [a.astype(f) for a in (arrays[0], V, N, T, B)]
    args += [_numpy_arg(ty, values[name], f) for name, _, _, ty, _ in sp.specs.flat]
    with np.errstate(all="ignore"):  # masked-out lanes of a select may overflow; what is returned is checked
        out = _functions(spec, lib, dtype)[f"{what}_{term}"](*args)
    shape = (n, 3) if what == "sample" else (n,)
    return np.broadcast_to(np.asarray(out, np.float64), shape).copy()


def sample(spec: str, u, V, N, T=None, params: dict | None = None, term: int = 0, lib=None,
           dtype: str = "float64") -> np.ndarray:
    """Directions L (n, 3) drawn by term `term`'s sampler from uniforms u (n, 2)."""
    return _run(spec, "sample", u, V, N, T, params, term, lib, dtype)


def pdf(spec: str, L, V, N, T=None, params: dict | None = None, term: int = 0, lib=None,
        dtype: str = "float64") -> np.ndarray:
    """The density (n,) per unit solid angle with which term `term`'s sampler draws L."""
    return _run(spec, "pdf", L, V, N, T, params, term, lib, dtype)


def mixture_pdf(spec: str, weights, L, V, N, T=None, params=None, lib=None) -> np.ndarray:
    """Σ_k weights[k] pdf_k(L): the density of the one-sample mixture over the BRDF's terms."""
    w = np.asarray(weights, np.float64)
    return sum(w[k] * pdf(spec, L, V, N, T, params, k, lib) for k in range(len(w)) if w[k] > 0.0)


def mixture_sample(spec: str, weights, u3, V, N, T=None, params=None, lib=None) -> np.ndarray:
    """Directions drawn by the mixture: u3[:, 2] picks term k with probability weights[k], u3[:, :2] samples it."""
    u3 = np.asarray(u3, np.float64)
    w = np.asarray(weights, np.float64)
    edges = np.cumsum(w / w.sum())
    pick = np.minimum(np.searchsorted(edges, u3[:, 2], side="right"), len(w) - 1)
    out = np.zeros((len(u3), 3))
    for k in range(len(w)):
        m = pick == k
        if m.any():
            out[m] = sample(spec, u3[m, :2], np.broadcast_to(V, (len(u3), 3))[m], np.broadcast_to(N, (len(u3), 3))[m],
                            None if T is None else np.broadcast_to(T, (len(u3), 3))[m], params, k, lib)
    return out
