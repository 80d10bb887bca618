"""Accuracy of the bricks against the float64 references: sample domains, the stress set, error metrics.

Two sample sets per BRDF spec:
- `hemisphere`: L and V stratified jointly over the upper hemisphere (uniform in
  solid angle: cos θ and φ in a jittered k⁴ grid), with the bricks' default
  parameters, in a rotated frame so that float32 directions carry rounding;
- `stress`: the degenerate and extreme configurations below, plus the extremes of every
  tangent-frame row of the inputs table (library/inputs.py) for anisotropic models (grazing cosines
  0, 1e-7, 1e-4, 1e-2; L = V; L = -V; V below the horizon; the mirror direction,
  also at grazing; h = n and 0.05° off it) crossed with parameter sweeps (alpha
  0 … 1, exponents 1 … 1e5, f0 = 0 and 1, sigma 0 … 1.2 rad), in the canonical
  frame (exact zeros) and in the rotated frame.

Errors are per RGB component against the reference evaluated at the inputs as
rounded to the target's dtype (the target's arithmetic, not its input rounding):
absolute, and relative |f - f_ref| / max(|f_ref|, REL_FLOOR). NaN and Inf outputs
are counted on every sample, never averaged. Left out of the errors and counted
apart (see Errors): batches whose reference is a Dirac peak (alpha = 0), samples
that the dtype's input rounding alone moves by more than ILL_CONDITIONED, and
infinite reference values elsewhere. A NaN reference is an error.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from .. import GPU_TARGETS

# Below 1e-6 sr⁻¹ an error is measured relative to 1e-6: at unit light such a value is
# ~1e-3 of an 8-bit step (π f_r c cos θ with f_r ≈ 1.3e-3 per step).
REL_FLOOR = 1e-6
# A sample is ill-conditioned in a dtype when rounding its inputs alone changes the reference
# by more than this (relative, with REL_FLOOR).
ILL_CONDITIONED = 0.1
# A batch is broken (Errors.broken_by_param, fp16_limits) when its relative error exceeds this: the value is
# off by more than itself.
BREAK_REL = 1.0
# The fp16 verdict (reported beside the float32 one, never the exit status): the hemisphere at the default
# parameters within FP16_TOL and free of NaN/Inf on every fp16 run. fp16 rounds at 2^-11 ≈ 4.9e-4 per
# operation; a BRDF's chain of a few dozen operations and a pow() stays within a few percent.
FP16_TOL = 5e-2
GRAZING = (0.0, 1e-7, 1e-4, 1e-2)
SWEEPS = {
    "alpha": (0.0, 1e-4, 1e-3, 1e-2, 0.3, 1.0),
    "n": (1.0, 10.0, 100.0, 1e3, 1e4, 1e5),
    "f0": (0.0, 0.04, 1.0),
    "alpha_u": (1e-4, 1e-2, 0.5),  # the anisotropic GGX/Beckmann NDF and Smith fillers
    "alpha_v": (1e-3, 1.0),
    "eta": (0.2, 1.0, 1.5),  # conductor_exact: metal-like, the degenerate index 1 (with k = 0), glass
    "k": (0.0, 3.5),
    "sigma": (0.0, 0.3, 0.6, 1.2),
    "rho_d": (0.0, 1.0),
    "k_s": (0.0, 1.0),
    "m": (1e-4, 1e-3, 1e-2, 0.3, 1.0),
    "m_u": (1e-4, 1e-2, 1.0),
    "m_v": (1e-4, 0.3, 1.0),
    "n_u": (1.0, 100.0, 1e5),
    "n_v": (1.0, 1e3, 1e5),
    "s": (0.0, 1.0),
}


# ------------------------------------------------------------------ sample domains

@dataclass
class SampleSet:
    """Samples of one parameter set: unit vectors (n, 3) in float64 and a label per sample."""

    name: str
    params: dict
    L: np.ndarray
    V: np.ndarray
    N: np.ndarray
    T: np.ndarray
    labels: list[str]


def rotation() -> np.ndarray:
    """A fixed rotation that makes no frame axis representable exactly (rounding in float32)."""
    axis = np.array([0.36, -0.48, 0.8])
    axis /= np.linalg.norm(axis)
    t = 0.7
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(t) * K + (1.0 - math.cos(t)) * (K @ K)


def direction(cos_theta, phi) -> np.ndarray:
    """Unit vectors with polar cosine `cos_theta` (may be negative) and azimuth `phi`, frame N = z, T = x."""
    c = np.asarray(cos_theta, np.float64)
    s = np.sqrt(np.maximum(0.0, (1.0 - c) * (1.0 + c)))
    p = np.asarray(phi, np.float64)
    return np.stack(np.broadcast_arrays(s * np.cos(p), s * np.sin(p), c), axis=-1)


def _polar(theta: float, phi: float) -> np.ndarray:
    """The unit vector at polar angle theta (negative: the opposite azimuth) and azimuth phi."""
    return np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])


def _framed(name, params, L, V, labels, rotate: bool) -> SampleSet:
    n = len(L)
    N = np.broadcast_to([0.0, 0.0, 1.0], (n, 3))
    T = np.broadcast_to([1.0, 0.0, 0.0], (n, 3))
    if rotate:
        R = rotation()
        L, V, N, T = (np.asarray(x) @ R.T for x in (L, V, N, T))
    return SampleSet(name, params, np.ascontiguousarray(L), np.ascontiguousarray(V),
                     np.ascontiguousarray(N), np.ascontiguousarray(T), labels)


def hemisphere(k: int = 12, seed: int = 0, params: dict | None = None, rotate: bool = True) -> SampleSet:
    """L and V jointly stratified over the hemisphere: a jittered k⁴ grid in (cos θ_l, φ_l, cos θ_v, φ_v).

    rotate=False keeps the canonical frame N = z, T = x.
    """
    rng = np.random.default_rng(seed)
    cells = np.stack(np.meshgrid(*(np.arange(k),) * 4, indexing="ij"), -1).reshape(-1, 4)
    u = (cells + rng.random(cells.shape)) / k
    L = direction(u[:, 0], 2.0 * np.pi * u[:, 1])
    V = direction(u[:, 2], 2.0 * np.pi * u[:, 3])
    return _framed("hemisphere", dict(params or {}), L, V, ["hemisphere"] * len(L), rotate=rotate)


def stress_geometry() -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The degenerate and extreme (L, V) configurations in the canonical frame, with labels."""
    rows: list[tuple[np.ndarray, np.ndarray, str]] = []
    z = np.array([0.0, 0.0, 1.0])
    c45 = math.sqrt(0.5)

    def add(label, L, V):
        rows.append((np.asarray(L, np.float64), np.asarray(V, np.float64), label))

    for c in GRAZING:
        gl = direction(c, 0.0)
        add(f"grazing L (n·l={c:g}), V = n", gl, z)
        add(f"grazing L (n·l={c:g}), V 45° mirror side", gl, direction(c45, np.pi))
        add(f"grazing L (n·l={c:g}), V 45° same side", gl, direction(c45, 0.0))
        add(f"grazing V (n·v={c:g}), L = n", z, gl)
        add(f"grazing V (n·v={c:g}), L 45° mirror side", direction(c45, np.pi), gl)
        add(f"mirror at grazing (cos={c:g})", gl, direction(c, np.pi))
        add(f"L = V grazing (cos={c:g})", gl, gl)
        add(f"grazing L and V 90° apart (cos={c:g})", gl, direction(c, np.pi / 2))
    for c in (1.0, c45, 0.1):
        add(f"L = V (cos={c:g})", direction(c, 0.3), direction(c, 0.3))
    for c in (1.0, 0.8, 1e-4):
        add(f"L = -V (n·l={c:g})", direction(c, 0.0), -direction(c, 0.0))
    for c in (-1e-7, -1e-4, -0.164, -0.5, -1.0):
        v = direction(c, 0.0)
        add(f"V below horizon (n·v={c:g}), L = n", z, v)
        add(f"V below horizon (n·v={c:g}), L 45° mirror side", direction(c45, np.pi), v)
        add(f"V below horizon (n·v={c:g}), L 45° same side", direction(c45, 0.0), v)
        add(f"V below horizon (n·v={c:g}), L grazing opposite", direction(1e-4, np.pi), v)
    rows += _tangent_rows()
    d = math.radians(0.05)
    for deg in (0.0, 30.0, 60.0, 85.0):
        t = math.radians(deg)
        add(f"mirror, h = n (θ={deg:g}°)", _polar(t, 0.0), _polar(t, np.pi))
        add(f"mirror, h 0.05° off n (θ={deg:g}°)", _polar(t + d, 0.0), _polar(t - d, np.pi))
    L, V, labels = zip(*rows)
    return np.stack(L), np.stack(V), list(labels)


def _tangent_rows() -> list[tuple[np.ndarray, np.ndarray, str]]:
    """For every tangent-frame row of the inputs table (dot(X, T) or dot(X, B)), configurations where it
    is near ±1 at grazing and where it is 0: the extremes anisotropic models square or divide by.

    In the canonical frame T = x and B = y (azimuth 0 and π/2); X is H (L and V mirrored about the
    axis), L (V = n) or V (L = n).
    """
    import re

    from ..library.inputs import INPUTS

    z = np.array([0.0, 0.0, 1.0])
    out = []
    for row in INPUTS:
        m = re.fullmatch(r"dot\((\w), ([TB])\)", row.expr or "")
        if not (row.tangent and m):
            continue
        x, axis = m.groups()
        phi = 0.0 if axis == "T" else np.pi / 2
        for c in (1e-4, 0.5):
            big = "≈ 1" if c < 0.01 else "= sin θ"  # in the T-N (B-N) plane, |x·axis| is sin θ_x
            if x == "H":
                L, V = direction(c, phi + 0.05), direction(c, phi - 0.05)
                out.append((L, V, f"{row.name} {big} (h near {axis}, cos={c:g})"))
                out.append((direction(c, phi + np.pi / 2), direction(c, phi - np.pi / 2), f"{row.name} = 0 (cos={c:g})"))
            else:
                along, ortho = direction(c, phi), direction(c, phi + np.pi / 2)
                pair = lambda a: (a, z) if x == "L" else (z, a)  # noqa: E731
                out.append((*pair(along), f"{row.name} {big} ({x} near {axis}, cos={c:g})"))
                out.append((*pair(ortho), f"{row.name} = 0 (cos={c:g})"))
    return [(np.asarray(a, np.float64), np.asarray(b, np.float64), s) for a, b, s in out]


def stress_params(declared: dict) -> list[dict]:
    """Parameter sets of the stress set: the product of the sweeps of the parameters a BRDF has.

    declared: {name: (type, default, range)}; sweep values outside a parameter's range are skipped.
    """
    axes = []
    for name, (ty, _default, rng) in declared.items():
        values = [v for v in SWEEPS.get(name, ()) if rng is None or rng[0] <= v <= rng[1]]
        if values:
            axes.append([(name, [v] * ty.components if ty.kind == "vector" else v) for v in values])
    combos = [{}]
    for axis in axes:
        combos = [dict(c, **{k: v}) for c in combos for k, v in axis]
    return combos


def stress_sets(declared: dict, params: dict | None = None) -> list[SampleSet]:
    """One SampleSet per parameter set, each holding every stress geometry in both frames.

    params: a material's own values (`accuracy SCENE`): one set at those values instead of the sweeps.
    """
    L, V, labels = stress_geometry()
    out = []
    for p in (stress_params(declared) if params is None else [dict(params)]):
        a = _framed("stress", p, L, V, labels, rotate=False)
        b = _framed("stress", p, L, V, [f"{s} [rotated]" for s in labels], rotate=True)
        out.append(SampleSet("stress", p, *(np.concatenate([getattr(a, f), getattr(b, f)])
                                            for f in ("L", "V", "N", "T")), a.labels + b.labels))
    return out


# ------------------------------------------------------------------ error metrics

@dataclass
class Errors:
    """Error statistics of one target × dtype on one sample set of one spec.

    nan/inf count the target's non-finite outputs over every sample. The errors
    leave out (and count) samples that cannot be compared: `dirac` — batches whose
    reference has a Dirac peak (alpha = 0: a distribution, not point values),
    `ill_conditioned` — samples where rounding the inputs to the dtype alone moves
    the reference by more than ILL_CONDITIONED (h from l + v at l ≈ -v, cosines of
    1e-7 in a rotated float32 frame): there no dtype-rounded evaluation can agree,
    and `ref_inf` — values where the reference is infinite in any other batch. A NaN
    in the reference is a bug in it: add() raises ValueError.
    """

    samples: int = 0  # RGB components compared
    nan: int = 0
    inf: int = 0
    dirac: int = 0
    ill_conditioned: int = 0
    ref_inf: int = 0
    ref_nan: int = 0  # values where the bricks' own float64 formula is NaN (precision mode only: add(nan_ref_ok))
    max_abs: float = 0.0
    mean_abs: float = 0.0
    max_rel: float = 0.0
    mean_rel: float = 0.0
    worst: dict = field(default_factory=dict)  # the sample of max_rel: case, params, value, reference
    by_param: dict = field(default_factory=dict)  # "alpha=0.001" -> max rel over the batches with that value
    by_case: dict = field(default_factory=dict)  # stress geometry label -> max rel (both frames)
    # "alpha=0.001" -> {stress geometry label: [batches where it broke, batches]}: a geometry breaks in a batch
    # when a sample of it (either frame) gives a NaN or Inf or a relative error above BREAK_REL (fp16_limits)
    broken_by_param: dict = field(default_factory=dict)

    def add(self, got: np.ndarray, ref: np.ndarray, labels: list[str], params: dict,
            comparable: np.ndarray | None = None, nan_ref_ok: bool = False) -> None:
        """Fold one batch ((n, 3) arrays) into the statistics; `comparable`: (n,) well-conditioned samples.
        nan_ref_ok: `ref` is the bricks' own formula at float64, not an independent reference: its NaNs are
        the formula's (plausibility counts them), left out and counted in ref_nan."""
        self.nan += int(np.count_nonzero(np.isnan(got)))
        self.inf += int(np.count_nonzero(np.isinf(got)))
        nonfinite = ~np.isfinite(got).all(axis=1)
        if params.get("alpha") == 0:
            self.dirac += got.size
            self._tally(params, labels, nonfinite)
            return
        nan_ref = np.isnan(ref)
        was_nan = nan_ref if nan_ref_ok else np.zeros_like(nan_ref)
        if was_nan.any():
            ref = np.where(was_nan, np.inf, ref)  # left out below, as an infinite reference is
            nan_ref = np.zeros_like(nan_ref)
        if nan_ref.any():
            i = int(np.argmax(nan_ref.any(axis=1)))
            raise ValueError(f"the float64 reference is NaN in {int(nan_ref.sum())} values (first: "
                             f"{labels[i]}, {_plain(params)}) — fix the BRDF's reference function "
                             "(generator/reference/)")
        keep = np.ones(len(got), bool) if comparable is None else comparable
        self.ill_conditioned += 3 * int(np.count_nonzero(~keep))
        inf_ref = keep[:, None] & np.isinf(ref)
        self.ref_inf += int(np.count_nonzero(inf_ref & ~was_nan))
        self.ref_nan += int(np.count_nonzero(inf_ref & was_nan))
        m = keep[:, None] & np.isfinite(got) & ~inf_ref
        if not m.any():
            self._tally(params, labels, nonfinite)
            return
        with np.errstate(invalid="ignore", over="ignore"):
            a = np.abs(got - ref)
            rel = a / np.maximum(np.abs(ref), REL_FLOOR)
        n_new = int(np.count_nonzero(m))
        total = self.samples + n_new
        self.mean_abs = (self.mean_abs * self.samples + float(a[m].sum())) / total
        self.mean_rel = (self.mean_rel * self.samples + float(rel[m].sum())) / total
        self.samples = total
        self.max_abs = max(self.max_abs, float(a[m].max()))
        r = np.where(m, rel, -1.0)
        i, j = np.unravel_index(int(np.argmax(r)), r.shape)
        self._tally(params, labels, nonfinite | (r.max(axis=1) > BREAK_REL))
        for k, v in _plain(params).items():
            key = f"{k}={v:g}" if not isinstance(v, list) else f"{k}={v}"
            self.by_param[key] = max(self.by_param.get(key, 0.0), float(r[i, j]))
        cases, inverse = np.unique([lab.removesuffix(" [rotated]") for lab in labels], return_inverse=True)
        worst_case = np.full(len(cases), -1.0)
        np.maximum.at(worst_case, inverse, r.max(axis=1))
        for case, w in zip(cases.tolist(), worst_case.tolist()):
            if w >= 0.0:
                self.by_case[case] = max(self.by_case.get(case, 0.0), w)
        if r[i, j] > self.max_rel or not self.worst:
            self.max_rel = float(r[i, j])
            self.worst = {"case": labels[i], "params": _plain(params),
                          "value": float(got[i, j]), "reference": float(ref[i, j])}

    def _tally(self, params: dict, labels: list[str], broken: np.ndarray) -> None:
        """Count, per parameter value and stress geometry, the batches where the geometry broke."""
        cases: dict[str, bool] = {}
        for lab, b in zip(labels, broken.tolist()):
            case = lab.removesuffix(" [rotated]")
            cases[case] = cases.get(case, False) or b
        for key in _param_keys(params):
            per = self.broken_by_param.setdefault(key, {})
            for case, b in cases.items():
                c = per.setdefault(case, [0, 0])
                c[0] += int(b)
                c[1] += 1


def _param_keys(params: dict) -> list[str]:
    return [f"{k}={v:g}" if not isinstance(v, list) else f"{k}={v}" for k, v in _plain(params).items()]


def _first(items: list[str], n: int = 3) -> str:
    """A report cell naming at most n items: the rest counted (the JSON report lists them all)."""
    if not items:
        return "none"
    return "; ".join(items[:n]) + (f"; and {len(items) - n} more" if len(items) > n else "")


def _params_text(params: dict | None) -> str:
    """{"alpha": 0.001, "f0": [1, 0.5, 0]} -> "alpha = 0.001, f0 = (1, 0.5, 0)": for a report's cell, not a Python dict."""
    def one(v):
        return f"({', '.join(f'{x:g}' for x in v)})" if isinstance(v, (list, tuple)) else f"{v:g}"
    return ", ".join(f"{k} = {one(v)}" for k, v in (params or {}).items())


def _plain(params: dict) -> dict:
    return {k: (v if not isinstance(v, (list, tuple)) else (v[0] if len(set(v)) == 1 else list(v)))
            for k, v in params.items()}


# ------------------------------------------------------------------ running

def default_specs(lib, full: bool = False) -> list[str]:
    """Every BRDF brick: each diffuse term alone, and each specular term with its slot fillers.

    full: every combination of slot fillers (the product grows as the library does: a `slow`
    sweep and `accuracy --all-combinations`). Otherwise the fillers are sampled one factor at
    a time: the host with its default fillers, then each other filler of each slot in turn with
    the other slots at their defaults, so every filler is measured at least once.
    """
    from itertools import product
    specs = [b.id for b in lib.of_kind("diffuse")]
    for b in lib.of_kind("specular"):
        if not b.slots:
            specs.append(b.id)
            continue
        slots = list(b.slots.items())
        choices = [[f.id for f in lib.of_kind(slot["kind"])] for _s, slot in slots]
        if full:
            combos = list(product(*choices))
        else:
            default = tuple(slot.get("default") if slot.get("default") in ids else ids[0]
                            for (_s, slot), ids in zip(slots, choices))
            combos = [default]
            for i, ids in enumerate(choices):
                combos += [default[:i] + (f,) + default[i + 1:] for f in ids if f != default[i]]
        for combo in combos:
            specs.append(f"{b.id}({','.join(f'{s}={f}' for (s, _slot), f in zip(slots, combo))})")
    return specs


def default_targets() -> list[str]:
    """numpy, plus the GPU languages when a lavapipe device is present."""
    from ..runtime.probe import lavapipe_present
    return ["numpy"] + (list(GPU_TARGETS) if lavapipe_present() else [])


def runs(targets, dtypes, session=None) -> list[tuple[str, str]]:
    """(target, dtype) pairs to measure: numpy in each dtype asked; GPU languages in float32, and in float16
    (their fp16 kernels) where the device of `session` reports shaderFloat16 (gpu_fp16(); skipped_runs() says
    why not)."""
    out = []
    for t in targets:
        for d in dtypes:
            if t == "numpy" or (t in GPU_TARGETS and d == "float32"):
                out.append((t, d))
            elif t in GPU_TARGETS and d == "float16" and gpu_fp16(session)[0]:
                out.append((t, d))
    return out


def skipped_runs(targets, dtypes, session=None) -> list[dict]:
    """The (target, dtype) pairs asked for that runs() leaves out, each with the reason."""
    out = []
    for t in targets:
        for d in dtypes:
            if t in GPU_TARGETS and d == "float64":
                out.append({"run": f"{t}/{d}", "why": "GPU targets compute in float32 or float16"})
            elif t in GPU_TARGETS and d == "float16" and not gpu_fp16(session)[0]:
                out.append({"run": f"{t}/{d}", "why": gpu_fp16(session)[1]})
    return out


def gpu_fp16(session=None) -> tuple[bool, str]:
    """(whether the GPU targets run float16 here, why not): the device of `session` (an EvalSession; None: one
    opened for the question alone) must report shaderFloat16."""
    from .evaluate import gpu_fp16_status, own_session
    try:
        with own_session(session) as own:
            return gpu_fp16_status(own)
    except Exception as exc:  # no Vulkan device at all (or none may be opened here)
        return False, f"no Vulkan device ({exc})"


def declared_params(spec: str, lib) -> dict:
    """{name: (type, default, range)} of a BRDF spec's parameters, from the bricks' metadata."""
    from ..spec.resolve import resolve_brdf
    from ..reference import brdf_parameters
    return brdf_parameters(resolve_brdf(spec, lib))


def spec_tolerance(spec: str, lib, tol: float) -> float:
    """The hemisphere tolerance a spec is judged at: tol, or the largest `tolerance` its bricks declare for
    their approximation (a baked table, a fit), whichever is larger."""
    from ..lang import SourceError
    from ..spec.permutation import SpecError
    from ..spec.resolve import resolve_brdf
    if lib is None:
        return tol
    try:
        rb = resolve_brdf(spec, lib)
    except (SpecError, SourceError):  # not a spec of this library: judged at tol (its own errors come elsewhere)
        return tol
    return max([tol] + [n.brick.tolerance for top in rb.nodes for n in top.tree])


def rounded_inputs(s: SampleSet, dtype: str) -> list[np.ndarray]:
    """(L, V, N, T) rounded to `dtype`, as float64: what the target gets, and what its reference is computed at.

    The reference sees the very vectors the target sees, so the error measures the
    target's arithmetic, not the rounding of its inputs.
    """
    return [x.astype(dtype).astype(np.float64) for x in (s.L, s.V, s.N, s.T)]


def measure(spec: str, targets, dtypes, lib, hemisphere_k: int = 12, params: dict | None = None,
            session=None, own: bool = False) -> dict:
    """Errors of every (target, dtype) against the reference for one spec: {set: {"target/dtype": Errors}}.

    params: a material's parameter values (`accuracy SCENE`): the hemisphere and the stress geometries
    are evaluated at them, instead of at the defaults and the parameter sweeps. session: the EvalSession the
    GPU targets run on (None: one for this measure alone). own: the spec has no independent reference
    (missing_references()): every target is measured against the NumPy target of the bricks' own formula at
    float64 instead, a precision error (which that run itself is left out of).
    """
    from .evaluate import own_session

    if not any(t in GPU_TARGETS for t in targets):
        return _measure(spec, targets, dtypes, lib, hemisphere_k, params, session, own)
    with own_session(session) as s:
        return _measure(spec, targets, dtypes, lib, hemisphere_k, params, s, own)


def _own_formula(spec, L, V, N, T, params, lib):
    from .evaluate import evaluate
    with np.errstate(all="ignore"):
        return evaluate(spec, L, V, N, T, params, target="numpy", dtype="float64", lib=lib)


def _measure(spec: str, targets, dtypes, lib, hemisphere_k: int, params: dict | None, session, own: bool) -> dict:
    from .evaluate import evaluate, gpu_kernel
    from ..reference import reference_brdf

    reference_of = _own_formula if own else (lambda *a, lib: reference_brdf(*a, lib=lib))
    declared = declared_params(spec, lib)
    sets = {"hemisphere": [hemisphere(hemisphere_k, params=params)], "stress": stress_sets(declared, params)}
    todo = [(t, d) for t, d in runs(targets, dtypes, session) if not (own and (t, d) == ("numpy", "float64"))]
    out: dict = {}
    for set_name, batches in sets.items():
        stats = {f"{t}/{d}": Errors() for t, d in todo}
        for s in batches:
            exact = reference_of(spec, s.L, s.V, s.N, s.T, s.params, lib=lib)
            refs: dict = {}
            for t, d in todo:
                given = rounded_inputs(s, d)
                if d not in refs:
                    ref = reference_of(spec, *given, s.params, lib=lib)
                    with np.errstate(invalid="ignore"):
                        moved = np.abs(ref - exact) > ILL_CONDITIONED * np.maximum(np.abs(exact), REL_FLOOR)
                    refs[d] = ref, ~moved.any(axis=1)
                with np.errstate(all="ignore"):  # float16 overflows (n = 1e5) are what we count
                    got = evaluate(spec, *given, s.params, target=t, dtype=d, lib=lib, session=session)
                stats[f"{t}/{d}"].add(got, refs[d][0], s.labels, s.params, refs[d][1], nan_ref_ok=own)
        out[set_name] = stats
    for t, d in sorted({(t, d) for t, d in todo if t in GPU_TARGETS}):  # float32 and float16
        gpu_kernel(spec, t, lib, session, precision="fp16" if d == "float16" else "fp32").release()  # buffers
        # of the largest batch's size; the pipeline stays
    return out


DEFAULT_TOL = 1e-3  # float32 hemisphere max relative error a spec may have and pass (the worst exact brick: 3.2e-4, docs/benchmarks.md)


def run(specs, targets, dtypes, lib, hemisphere_k: int = 12, tol: float = DEFAULT_TOL,
        materials: dict | None = None, session=None, user: dict | None = None) -> dict:
    """The accuracy report of several specs as a JSON-ready dict, with a verdict per spec (see verdicts()).

    materials: {label: (spec, params)} — an entry of `specs` that is a label there is measured as
    that BRDF at those parameter values (a scene's material: `accuracy SCENE`); its results carry
    the label as "spec" and the BRDF as "brdf". session: the EvalSession the GPU targets run on (None:
    one for this run alone, when a GPU target is asked for). user: {"kind/id": file} of the references
    registered from files the user named (user_references.py), reported as such.

    A spec whose bricks lack a float64 reference is never an error: it gets the plausibility checks
    (eval/plausibility.py) and the precision error of every target against its own formula at float64.
    """
    from .evaluate import own_session

    if not any(t in GPU_TARGETS for t in targets):
        return _run(specs, targets, dtypes, lib, hemisphere_k, tol, materials or {}, session, user or {})
    with own_session(session) as own:
        return _run(specs, targets, dtypes, lib, hemisphere_k, tol, materials or {}, own, user or {})


def reference_source(spec: str, lib, user: dict | None = None) -> dict:
    """What a spec is measured against: {"kind": "builtin" | "user" | "none", "files": [...], "missing": [...]}
    ("none": some brick of it, "kind/id" in missing, has no float64 reference)."""
    from ..reference import REFERENCES
    from ..spec.resolve import resolve_brdf
    bricks = [n.brick for top in resolve_brdf(spec, lib).nodes for n in top.tree]
    keys = list(dict.fromkeys(f"{b.kind}/{b.id}" for b in bricks))
    missing = [k for k in keys if k.partition("/")[2] not in REFERENCES.get(k.partition("/")[0], {})]
    files = sorted({(user or {})[k] for k in keys if k in (user or {})})
    kind = "none" if missing else "user" if files else "builtin"
    return {"kind": kind, "files": files, "missing": missing}


AGAINST = {"builtin": "float64 reference", "user": "user's float64 reference",
           "none": "precision error (no independent reference)"}


def _run(specs, targets, dtypes, lib, hemisphere_k: int, tol: float, materials: dict, session, user: dict) -> dict:
    from tqdm import tqdm

    from . import plausibility
    from ..io import show_progress
    results, sources, plausible = [], {}, {}
    for label in tqdm(specs, disable=not show_progress(), unit="spec", leave=False):
        spec, params = materials.get(label, (label, None))
        extra = {"brdf": spec, "params": _plain(params)} if label in materials else {}
        sources[label] = src = reference_source(spec, lib, user)
        own = src["kind"] == "none"
        if own:
            plausible[label] = plausibility.check(spec, lib, params) | {"spec": label}
        for set_name, stats in measure(spec, targets, dtypes, lib, hemisphere_k, params, session, own).items():
            for key, e in stats.items():
                t, d = key.split("/")
                results.append({"spec": label, **extra, "set": set_name, "target": t, "dtype": d,
                                "against": AGAINST[src["kind"]], **asdict(e)})
    bad = [r for r in results if r["dtype"] == "float32" and (r["nan"] or r["inf"])]
    return {"rel_floor": REL_FLOOR, "specs": list(specs),
            "runs": [f"{t}/{d}" for t, d in runs(targets, dtypes, session)],
            "results": results, "float32_finite": not bad, "tolerance": tol,
            "verdicts": verdicts(results, specs, tol, lib, sources, plausible),
            "plausibility": list(plausible.values()), "user_references": dict(user),
            "skipped": skipped_runs(targets, dtypes, session)}


def verdicts(results: list[dict], specs, tol: float, lib=None, sources: dict | None = None,
             plausible: dict | None = None) -> list[dict]:
    """Per spec: pass when float32 gives no NaN or Inf anywhere and its hemisphere max relative error is at most
    tol (or the tolerance its bricks declare for their approximation: spec_tolerance) on every target; with the worst hemisphere error (and where) and the worst stress case (and which).
    Where no float32 ran (--dtypes float64), float64 is judged instead; float16 alone is reported, never
    judged (pass stays True). sources: {spec: reference_source()}; plausible: {spec: plausibility.check()} of the
    specs without an independent reference, whose checks must pass too (the failed ones are listed)."""
    out = []
    sources, plausible = sources or {}, plausible or {}
    for spec in specs:
        mine = [r for r in results if r["spec"] == spec]
        f32 = ([r for r in mine if r["dtype"] == "float32"] or [r for r in mine if r["dtype"] == "float64"])
        hemi = max((r for r in f32 if r["set"] == "hemisphere"), key=lambda r: r["max_rel"], default=None)
        stress = max((r for r in f32 if r["set"] == "stress"), key=lambda r: r["max_rel"], default=None)
        nonfinite = sum(r["nan"] + r["inf"] for r in f32)
        case = stress["worst"] if stress and stress["worst"] else None
        brdf = mine[0].get("brdf", spec) if mine else spec
        own = spec_tolerance(brdf, lib, tol)
        src = sources.get(spec, {"kind": "builtin", "files": [], "missing": []})
        plaus = plausible.get(spec)
        failed = [c["check"] for c in plaus["checks"] if not c["pass"]] if plaus else []
        out.append({"spec": spec, "pass": not nonfinite and (hemi is None or hemi["max_rel"] <= own) and not failed,
                    "tolerance": own, "against": AGAINST[src["kind"]], "reference": src,
                    "plausibility": None if plaus is None else ("pass" if not failed else "fail"),
                    "plausibility_failed": failed,
                    "dtypes": sorted({r["dtype"] for r in f32}),
                    "float32_nan_inf": nonfinite,
                    "hemisphere_max_rel": hemi["max_rel"] if hemi else None,
                    "hemisphere_target": hemi["target"] if hemi else None,
                    "stress_max_rel": stress["max_rel"] if stress else None,
                    "stress_target": stress["target"] if stress else None,
                    "stress_case": f"{case['case']} {_params_text(case['params'])}".strip() if case else None,
                    **fp16_verdict(mine, _defaults(mine[0].get("brdf", spec) if mine else spec, lib))})
    return out


def _defaults(spec: str, lib) -> dict:
    """{parameter: default} of a BRDF spec ({} without a library, or for a spec that does not parse)."""
    if lib is None:
        return {}
    try:
        return {k: d for k, (_ty, d, _rng) in declared_params(spec, lib).items()}
    except Exception:
        return {}


def fp16_verdict(mine: list[dict], defaults: dict | None = None) -> dict:
    """The fp16 columns of one spec's verdict, from its float16 results (numpy and the GPU fp16 kernels):
    fp16_pass (None when no float16 ran): the hemisphere, at the default parameters, has no NaN or Inf
    and a max relative error of at most FP16_TOL on every float16 run; the worst hemisphere error and its
    target; NaN/Inf counts of both sets; and fp16_limits(), where the stress set's parameters break it.
    Reported beside the float32 verdict, which alone decides pass/fail."""
    f16 = [r for r in mine if r["dtype"] == "float16"]
    if not f16:
        return {"fp16_pass": None}
    hemi = [r for r in f16 if r["set"] == "hemisphere"]
    worst = max(hemi, key=lambda r: r["max_rel"], default=None)
    hemi_bad = sum(r["nan"] + r["inf"] for r in hemi)
    stress_bad = sum(r["nan"] + r["inf"] for r in f16 if r["set"] == "stress")
    return {"fp16_pass": not hemi_bad and (worst is None or worst["max_rel"] <= FP16_TOL),
            "fp16_targets": sorted({r["target"] for r in f16}),
            "fp16_hemisphere_max_rel": worst["max_rel"] if worst else None,
            "fp16_hemisphere_target": worst["target"] if worst else None,
            "fp16_hemisphere_nan_inf": hemi_bad, "fp16_stress_nan_inf": stress_bad,
            "fp16_limits": fp16_limits([r for r in f16 if r["set"] == "stress"], defaults),
            "fp16_broken_cases": fp16_broken_cases([r for r in f16 if r["set"] == "stress"], defaults)}


def fp16_limits(stress: list[dict], defaults: dict | None = None) -> dict[str, str]:
    """Per parameter: which of its swept values break the BRDF in fp16, from the stress set's
    broken_by_param merged over the runs given (a geometry is broken at a value when it broke in every
    batch holding that value, whatever the other parameters were, on some run). A value is a limit when
    it breaks a geometry that the parameter's baseline value does not: the swept value nearest its
    default (`defaults`: {name: default}; without one, the value breaking the fewest geometries).
    Geometries broken at the baselines already are fp16_broken_cases().

    {"alpha": ">= 0.01 (breaks at 0.0001, 0.001)", "n": "<= 1000 (breaks at 1e+04, 1e+05)"}; parameters
    with no limit are left out."""
    out = {}
    for name, values in _broken_sets(stress).items():
        base = values[_baseline(name, values, defaults)]
        limit = {v: bool(c - base) for v, c in values.items()}
        try:
            order = sorted(limit, key=float)
        except ValueError:  # vector values ("[0.1, 0.2]"): listed, not ordered
            order = sorted(limit)
        bad = [v for v in order if limit[v]]
        if not bad:
            continue
        good = [v for v in order if not limit[v]]
        where = ", ".join(bad)
        if good and order.index(bad[-1]) < order.index(good[0]):
            out[name] = f">= {good[0]} (breaks at {where})"
        elif good and order.index(bad[0]) > order.index(good[-1]):
            out[name] = f"<= {good[-1]} (breaks at {where})"
        else:
            out[name] = f"breaks at {where}"
    return out


def fp16_broken_cases(stress: list[dict], defaults: dict | None = None) -> list[str]:
    """The stress geometries broken at the baseline value of every parameter (near the defaults)."""
    sets = [values[_baseline(name, values, defaults)] for name, values in _broken_sets(stress).items()]
    return sorted(set.intersection(*sets)) if sets else []


def _baseline(name: str, values: dict[str, set], defaults: dict | None) -> str:
    """The swept value of `name` nearest its default (on a log scale for positive numbers), else the value
    breaking the fewest geometries."""
    d = (defaults or {}).get(name)
    d = d[0] if isinstance(d, (list, tuple)) and d else d
    try:
        nums = {v: float(v) for v in values}
        d = float(d)
    except (TypeError, ValueError):
        return min(values, key=lambda v: (len(values[v]), v))

    def dist(x: float) -> float:
        return abs(math.log(x) - math.log(d)) if x > 0 and d > 0 else abs(x - d) + (1e9 if d > 0 else 0)
    return min(nums, key=lambda v: dist(nums[v]))


def _broken_sets(stress: list[dict]) -> dict[str, dict[str, set]]:
    """{parameter: {value: geometries broken in every batch holding the value, on some run}}."""
    out: dict[str, dict[str, set]] = {}
    for r in stress:
        for key, cases in r.get("broken_by_param", {}).items():
            name, _, value = key.partition("=")
            got = out.setdefault(name, {}).setdefault(value, set())
            got |= {c for c, (b, n) in cases.items() if n and b == n}
    return out


def _fmt(x: float) -> str:
    return "0" if x == 0 else f"{x:.2e}"


def markdown(report: dict, detail: bool = False) -> str:
    """The report as Markdown: a verdict per spec and NaN/Inf per run; with detail, one table per sample set and
    target, then the stress set by parameter."""
    res = report["results"]
    lines = ["# Accuracy against the float64 references", "",
             f"Relative error: |f - f_ref| / max(|f_ref|, {report['rel_floor']:g} sr⁻¹), per RGB component; "
             "the reference is evaluated at the inputs as rounded to the dtype. NaN/Inf: non-finite "
             "outputs (every sample). Left out of the errors: Dirac (RGB values in batches whose reference "
             "is a Dirac peak, alpha = 0), ill-cond. (values whose reference moves by more than "
             f"{ILL_CONDITIONED:g} when the inputs are rounded to the dtype) and ref. Inf (values where the "
             "reference is infinite in other batches).", ""]
    if "verdicts" in report:
        lines += ["## Verdict per spec", "",
                  f"Pass: float32 gives no NaN or Inf in either sample set and its hemisphere max relative error is "
                  f"at most {report['tolerance']:g} on every target (`--fail-above` sets it), or at most the tolerance "
                  "a brick declares for its approximation (a baked table, a fit: shown beside its verdict). The stress "
                  "set's worst "
                  "case is shown, not judged: it holds grazing angles, α → 0 and huge exponents on purpose.", "",
                  "Measured against: the BRDF's float64 reference (generator/reference/, or a file given with "
                  "`--reference`); where a brick has none, the NumPy target of the bricks' own formula at float64, "
                  "a precision error (no independent reference), with the plausibility checks below.", "",
                  "| spec | verdict | float32 hemisphere max rel (target) | float32 NaN/Inf | stress max rel (target, "
                  "case) | measured against |", "|---|---|---|---|---|---|"]
        for v in report["verdicts"]:
            hemi = (f"{_fmt(v['hemisphere_max_rel'])} ({v['hemisphere_target']})"
                    if v["hemisphere_max_rel"] is not None else "–")
            stress = (f"{_fmt(v['stress_max_rel'])} ({v['stress_target']}, {v['stress_case']})"
                      if v["stress_max_rel"] is not None else "–")
            own = v.get("tolerance", report["tolerance"])  # a brick's declared approximation tolerance
            verdict = ("pass" if v["pass"] else "**FAIL**") + (f" (at {own:g})" if own != report["tolerance"] else "")
            src = v.get("reference") or {}
            against = v.get("against", AGAINST["builtin"]) + (f" ({', '.join(src['files'])})" if src.get("files")
                                                               else "")
            if v.get("plausibility_failed"):
                verdict += f" (plausibility: {', '.join(v['plausibility_failed'])})"
            lines.append(f"| `{v['spec']}` | {verdict} | {hemi} | "
                         f"{v['float32_nan_inf']} | {stress} | {against} |")
        lines.append("")
    if report.get("plausibility"):
        from .plausibility import markdown as plausibility_table
        lines += plausibility_table(report["plausibility"])
    fp16 = [v for v in report.get("verdicts", []) if v.get("fp16_pass") is not None]
    if fp16:
        lines += ["## fp16 per spec (reported, not judged)", "",
                  f"fp16 verdict: the hemisphere at the default parameters has no NaN or Inf and a max relative "
                  f"error of at most {FP16_TOL:g} on every float16 run ({', '.join(fp16[0]['fp16_targets'])}). "
                  "Limits: the swept parameter values that keep the BRDF working in fp16 (a value breaks when a "
                  "stress geometry gives NaN, Inf or a relative error above "
                  f"{BREAK_REL:g} in every batch holding the value, and does not at the swept value nearest the "
                  "parameter's default); the geometries already broken there are listed apart.", "",
                  "| spec | fp16 verdict | fp16 hemisphere max rel (target) | hemisphere NaN/Inf | stress NaN/Inf "
                  "| fp16 limits | stress geometries broken near the defaults |", "|---|---|---|---|---|---|---|"]
        for v in fp16:
            hemi = (f"{_fmt(v['fp16_hemisphere_max_rel'])} ({v['fp16_hemisphere_target']})"
                    if v["fp16_hemisphere_max_rel"] is not None else "–")
            limits = "; ".join(f"{k} {x}" for k, x in v["fp16_limits"].items()) or "none in the sweeps"
            lines.append(f"| `{v['spec']}` | {'pass' if v['fp16_pass'] else 'fail'} | {hemi} | "
                         f"{v['fp16_hemisphere_nan_inf']} | {v['fp16_stress_nan_inf']} | {limits} | "
                         f"{_first(v['fp16_broken_cases'])} |")
        lines.append("")
    for sk in report.get("skipped", []):
        lines.append(f"Not run: {sk['run']} — {sk['why']}.")
    if report.get("skipped"):
        lines.append("")
    lines += ["## NaN / Inf per run (every spec, both sample sets)", "", "| run | NaN | Inf |", "|---|---|---|"]
    for run_ in report["runs"]:
        rows = [r for r in res if f"{r['target']}/{r['dtype']}" == run_]
        lines.append(f"| {run_} | {sum(r['nan'] for r in rows)} | {sum(r['inf'] for r in rows)} |")
    lines.append("")
    for set_name in ("hemisphere", "stress") if detail else ():
        lines += [f"## {set_name}", "",
                  "| spec | target | dtype | max abs | mean abs | max rel | mean rel | NaN | Inf | Dirac | ill-cond. "
                  "| ref. Inf | worst case |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in (r for r in res if r["set"] == set_name):
            w = r["worst"]
            where = f"{w['case']} {w['params'] or ''}".strip() if w and set_name == "stress" else ""
            lines.append(f"| `{r['spec']}` | {r['target']} | {r['dtype']} | {_fmt(r['max_abs'])} | "
                         f"{_fmt(r['mean_abs'])} | {_fmt(r['max_rel'])} | {_fmt(r['mean_rel'])} | "
                         f"{r['nan']} | {r['inf']} | {r['dirac']} | {r['ill_conditioned']} | {r['ref_inf']} | {where} |")
        lines.append("")
    stress32 = [r for r in res if r["set"] == "stress" and r["dtype"] == "float32"] if detail else []
    if stress32:
        first = stress32[0]["target"]
        lines += [f"## stress, {first}/float32: max relative error by parameter value", "",
                  "| spec | max rel per parameter value |", "|---|---|"]
        for r in (r for r in stress32 if r["target"] == first):
            cells = ", ".join(f"{k}: {_fmt(v)}" for k, v in r["by_param"].items())
            lines.append(f"| `{r['spec']}` | {cells} |")
        lines.append("")
    verdict = "no NaN or Inf in float32" if report["float32_finite"] else "**NaN or Inf in float32**"
    lines.append(f"Result: {verdict}.")
    return "\n".join(lines) + "\n"
