"""Plausibility of a BRDF from its bricks alone: the rules a physical BRDF obeys, with no reference needed.

Every check runs the NumPy target of the bricks' own formula (eval/evaluate.py), so an engine's brick gets
them as a built-in does. After Bikker's lecture (f >= 0, reciprocity, energy) and the project's fp16 policy:

- `non-negative`: f >= 0 (to NEG_TOL) at float64 on the stress set of accuracy.py (grazing angles, L = ±V,
  V below the horizon, the mirror direction) at every parameter set given;
- `reciprocity`: f(l, v) = f(v, l) to RECIP_TOL (relative) at float64 on a stratified hemisphere with
  both cosines at least RECIP_MIN_COS (below it the glue's n·v floor, not the model, decides), unless a
  brick of the spec declares `"reciprocal": "no: why"` (then skipped, with the reason);
- `albedo`: the white furnace, E(v) = ∫ f(l, v) cos θ_l dω_l <= 1 for the views FURNACE_VIEWS, by
  quadrature (a (θ_l, φ_l) grid graded towards the mirror direction, where specular lobes peak) within
  ALBEDO_TOL, and by Monte Carlo with cosine-weighted l (E = π mean f) within MC_SIGMAS standard errors.
  v is fixed and l integrated, as a uniformly lit surface seen from v is: for a reciprocal BRDF this is also
  the albedo over outgoing directions; for a declared non-reciprocal one only this form is checked (the
  original Phong's albedo over v grows like 1/cos θ_l, the model's own defect);
- `float32 finite`: no NaN or Inf in float32 on the hemisphere and the stress set;
- `float16 finite`: no NaN or Inf in float16 on the hemisphere at the parameters given, required unless a
  brick of the spec is declared fp16-unsafe (`"fp16": "unsafe: why"`); the stress set in float16 is counted,
  never judged.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import accuracy

NEG_TOL = 1e-12  # float64 rounding of a sum of positive terms minus another never goes further below 0 than this
RECIP_TOL = 1e-6  # relative (floor accuracy.REL_FLOOR); an exact formula is symmetric to ~1e-13 in float64
RECIP_MIN_COS = 1e-3
FURNACE_VIEWS = (0.0, 30.0, 60.0, 80.0, 88.0)  # θ_v in degrees
# The quadrature's error, measured by doubling its nodes (furnace_nodes): at most 2e-8 (GGX α = 1e-3 at 88°;
# Lambert 1e-13, normalized Phong at n = 1e5 3e-13); the margin leaves room for an engine's lobe off the mirror.
ALBEDO_TOL = 1e-5
MC_SAMPLES = 1 << 16  # a jittered 256 × 256 grid of cosine-weighted directions
MC_SIGMAS = 4.0


# ------------------------------------------------------------------ quadrature (shared with the energy tests)

def gauss_legendre(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n Gauss-Legendre nodes and weights on [a, b]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) * (b - a) / 2 + a, w * (b - a) / 2


def graded(a: float, b: float, levels: int = 24, n: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre on [a, b] in panels halving towards a (for integrands peaked at a)."""
    edges = [a + (b - a) * 2.0 ** -k for k in range(levels, -1, -1)]
    xs, ws = zip(*(gauss_legendre(lo, hi, n) for lo, hi in zip([a] + edges[:-1], edges)))
    return np.concatenate(xs), np.concatenate(ws)


def polar_dirs(theta, phi) -> np.ndarray:
    """Unit vectors at polar angle theta and azimuth phi (frame N = z, T = x), broadcast together."""
    theta, phi = np.broadcast_arrays(theta, phi)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)


def h_nodes(theta: np.ndarray, w_theta: np.ndarray, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Half vectors (m, 3) over the upper hemisphere with their dω_h weights, from θ_h nodes and n_phi azimuths."""
    p, wp = gauss_legendre(0.0, 2 * math.pi, n_phi)
    T, P = np.meshgrid(theta, p, indexing="ij")
    W = (w_theta * np.sin(theta))[:, None] * wp[None, :]
    return polar_dirs(T, P).reshape(-1, 3), W.reshape(-1)


def h_quadrature(alpha: float, n_u: int, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Half-vector nodes with dω weights, θ_h = atan(α tan u): a microfacet lobe of roughness α is resolved."""
    u, w = gauss_legendre(0.0, math.pi / 2, n_u)
    t = np.arctan(alpha * np.tan(u))
    dt = alpha / np.cos(u) ** 2 / (1 + (alpha * np.tan(u)) ** 2)
    return h_nodes(t, w * dt, n_phi)


def cosine_directions(n: int, seed: int = 0) -> np.ndarray:
    """n (a square) cosine-weighted directions about z, jittered-stratified (Malley's method)."""
    k = math.isqrt(n)
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    u1 = ((i.reshape(-1) + rng.random(k * k)) / k)
    u2 = ((j.reshape(-1) + rng.random(k * k)) / k)
    r, phi = np.sqrt(u1), 2 * math.pi * u2
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0.0, 1 - u1))], -1)


# ------------------------------------------------------------------ the checks

@dataclass
class Check:
    """One rule on one spec: pass, and what was measured (worst value, where)."""

    check: str
    passed: bool
    detail: str
    value: float | None = None
    skipped: str = ""  # why the rule does not apply (a declared exception); passed is then True
    data: dict = field(default_factory=dict)

    def asdict(self) -> dict:
        return {"check": self.check, "pass": self.passed, "detail": self.detail, "value": self.value,
                "skipped": self.skipped, **({"data": self.data} if self.data else {})}


def _bricks(spec: str, lib) -> list:
    from ..spec.resolve import resolve_brdf
    return [n.brick for top in resolve_brdf(spec, lib).nodes for n in top.tree]


def _f(spec, L, V, N, T, params, lib, dtype="float64") -> np.ndarray:
    from .evaluate import evaluate
    with np.errstate(all="ignore"):
        return evaluate(spec, L, V, N, T, params, target="numpy", dtype=dtype, lib=lib)


def _param_sets(spec: str, lib, params: dict | None) -> list[dict]:
    """The material's own values, or the stress sweeps (accuracy.stress_params) with the defaults first."""
    if params is not None:
        return [dict(params)]
    return [{}] + accuracy.stress_params(accuracy.declared_params(spec, lib))


def _where(label: str, params: dict) -> str:
    return f"{label} {accuracy._params_text(accuracy._plain(params))}".strip()


def non_negative(spec: str, lib, params: dict | None = None) -> Check:
    worst, where = 0.0, ""
    for s in accuracy.stress_sets(accuracy.declared_params(spec, lib), params):
        f = _f(spec, s.L, s.V, s.N, s.T, s.params, lib)
        with np.errstate(invalid="ignore"):
            m = np.where(np.isnan(f), 0.0, f).min(axis=1)
        i = int(np.argmin(m))
        if m[i] < worst:
            worst, where = float(m[i]), _where(s.labels[i], s.params)
    ok = worst >= -NEG_TOL
    return Check("non-negative", ok, "min f = 0 or more on the stress set" if ok else
                 f"f = {worst:.3g} sr⁻¹ at {where}", worst)


def reciprocity(spec: str, lib, params: dict | None = None, k: int = 8) -> Check:
    declared = [(b.id, b.reciprocal.partition(":")[2].strip()) for b in _bricks(spec, lib) if b.reciprocal]
    if declared:
        why = "; ".join(f"{i}: {w}" for i, w in declared)
        return Check("reciprocity", True, f"not checked: declared not reciprocal ({why})", skipped=why)
    base = accuracy.hemisphere(k, seed=1, rotate=False)
    keep = (base.L[:, 2] >= RECIP_MIN_COS) & (base.V[:, 2] >= RECIP_MIN_COS)
    L, V, N, T = (x[keep] for x in (base.L, base.V, base.N, base.T))
    worst, where = 0.0, ""
    for p in _param_sets(spec, lib, params):
        a, b = _f(spec, L, V, N, T, p, lib), _f(spec, V, L, N, T, p, lib)
        with np.errstate(invalid="ignore", divide="ignore"):
            same = (a == b) | (np.isnan(a) & np.isnan(b))
            rel = np.where(same, 0.0, np.abs(a - b) / np.maximum(np.maximum(np.abs(a), np.abs(b)), accuracy.REL_FLOOR))
        rel = np.where(np.isnan(rel), np.inf, rel)
        i, j = np.unravel_index(int(np.argmax(rel)), rel.shape)
        if rel[i, j] > worst:
            worst = float(rel[i, j])
            where = (f"n·l = {L[i, 2]:.3g}, n·v = {V[i, 2]:.3g}: f(l, v) = {a[i, j]:.4g}, f(v, l) = {b[i, j]:.4g}"
                     f" {accuracy._params_text(accuracy._plain(p))}").strip()
    ok = worst <= RECIP_TOL
    return Check("reciprocity", ok, f"max |f(l,v) - f(v,l)| / f = {worst:.2e}" + ("" if ok else f" at {where}"),
                 worst)


def around(a: float, b: float, c: float, levels: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre on [a, b] in panels halving towards c from both sides (c in [a, b])."""
    parts = [graded(c, hi, levels, n) for hi in (b,) if hi - c > 1e-12]
    parts += [(2 * c - x, w) for x, w in (graded(c, 2 * c - a, levels, n),) if c - a > 1e-12]
    return np.concatenate([x for x, _ in parts]), np.concatenate([w for _, w in parts])


def furnace_nodes(theta_v: float, levels: int = 16, n: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """Directions l (m, 3) over the upper hemisphere with dω_l weights for the view at theta_v (radians, azimuth 0):
    a product grid in (θ_l, φ_l) graded towards the mirror direction (θ_v, π) from every side, so a lobe as
    sharp as α = 1e-4 or an exponent of 1e5 is resolved, and bounded by the horizon exactly (a Lambertian
    term integrates to ρ to 1e-12)."""
    t, wt = around(0.0, math.pi / 2, theta_v, levels, n)
    p, wp = around(0.0, 2 * math.pi, math.pi, levels, n)
    T, P = np.meshgrid(t, p, indexing="ij")
    W = (wt * np.sin(t))[:, None] * wp[None, :]
    return polar_dirs(T, P).reshape(-1, 3), W.reshape(-1)


def furnace(spec: str, lib, params: dict | None, theta_v: float, levels: int = 16, n: int = 10) -> np.ndarray:
    """E(v) (3,) = ∫ f(l, v) cos θ_l dω_l at view angle theta_v (degrees), by quadrature (furnace_nodes)."""
    v = polar_dirs(math.radians(theta_v), 0.0)
    L, W = furnace_nodes(math.radians(theta_v), levels, n)
    N = np.broadcast_to([0.0, 0.0, 1.0], L.shape)
    T = np.broadcast_to([1.0, 0.0, 0.0], L.shape)
    f = _f(spec, L, np.broadcast_to(v, L.shape), N, T, params, lib)
    return np.sum(f * (L[:, 2] * W)[:, None], axis=0)


def furnace_mc(spec: str, lib, params: dict | None, theta_v: float,
               samples: int = MC_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """(E, standard error) (3,) each, E = π mean f(l, v) over cosine-weighted l."""
    L = cosine_directions(samples)
    v = np.broadcast_to(polar_dirs(math.radians(theta_v), 0.0), L.shape)
    N = np.broadcast_to([0.0, 0.0, 1.0], L.shape)
    T = np.broadcast_to([1.0, 0.0, 0.0], L.shape)
    x = math.pi * _f(spec, L, v, N, T, params, lib)
    return x.mean(axis=0), x.std(axis=0) / math.sqrt(len(x))


def bright(spec: str, lib, params: dict | None) -> dict | None:
    """The defaults with every colour (vec3) parameter at the top of its range: a BRDF's brightest set, where
    it differs from the defaults (None otherwise)."""
    if params is not None:
        return None
    out = {}
    for name, (ty, default, rng) in accuracy.declared_params(spec, lib).items():
        if ty.kind == "vector" and ty.components == 3 and rng is not None and list(default) != [rng[1]] * 3:
            out[name] = [float(rng[1])] * 3
    return out or None


def _furnace_rows(spec: str, lib, p: dict, mc: bool) -> list[dict]:
    rows = []
    for th in FURNACE_VIEWS:
        e = furnace(spec, lib, p, th)
        row = {"theta_v": th, "quadrature": e.tolist()}
        bad = not (np.isfinite(e).all() and np.all(e <= 1.0 + ALBEDO_TOL))
        if mc:
            m, se = furnace_mc(spec, lib, p, th)
            row |= {"mc": m.tolist(), "mc_stderr": se.tolist()}
            bad |= not (np.isfinite(m).all() and np.all(m - MC_SIGMAS * se <= 1.0 + ALBEDO_TOL))
        rows.append(row | {"pass": not bad})
    return rows


def _furnace_text(rows: list[dict], p: dict) -> str:
    """The worst view of rows: its quadrature E (and the MC estimate), the view angle and the parameters."""
    r = max(rows, key=lambda r: (not r["pass"], max(r["quadrature"])))
    mc = f", MC {max(r['mc']):.4g} ± {max(r['mc_stderr']):.2g}" if "mc" in r else ""
    return f"E = {max(r['quadrature']):.4g}{mc} at θ_v = {r['theta_v']:g}° {accuracy._params_text(accuracy._plain(p))}"


def albedo(spec: str, lib, params: dict | None = None, mc: bool = True) -> Check:
    """The white furnace at the parameters given (None: the defaults), judged; for the defaults, also at the
    brightest colours (bright()), reported beside the verdict (a model may gain energy there: the original Ward
    at grazing angles, a Smith term of another NDF)."""
    p = dict(params or {})
    rows = _furnace_rows(spec, lib, p, mc)
    ok = all(r["pass"] for r in rows)
    worst = max(max(r["quadrature"]) for r in rows)
    views = ", ".join(f"{t:g}" for t in FURNACE_VIEWS)
    detail = (f"max E(v) = {worst:.4f} (θ_v {views}°; quadrature" + (" and cosine-weighted MC)" if mc else ")")
              if ok else _furnace_text(rows, p).strip())
    data = {"furnace": rows, "params": accuracy._plain(p)}
    b = bright(spec, lib, params)
    if b is not None:
        brows = _furnace_rows(spec, lib, b, mc)
        data["bright"] = {"params": b, "furnace": brows, "pass": all(r["pass"] for r in brows)}
        if not data["bright"]["pass"]:
            detail += f"; at the brightest colours (reported): {_furnace_text(brows, b).strip()}"
    return Check("albedo", ok, detail, worst, data=data)


def finite(spec: str, lib, params: dict | None = None, k: int = 8) -> list[Check]:
    """float32 NaN/Inf (required) and float16 NaN/Inf (required on the hemisphere unless declared fp16-unsafe)."""
    declared = accuracy.declared_params(spec, lib)
    hemi = accuracy.hemisphere(k, params=params)
    stress = accuracy.stress_sets(declared, params)
    counts = {}
    for dtype in ("float32", "float16"):
        h = _f(spec, hemi.L, hemi.V, hemi.N, hemi.T, hemi.params, lib, dtype)
        bad_h = int(np.count_nonzero(~np.isfinite(h)))
        bad_s, first = 0, ""
        for s in stress:
            f = _f(spec, s.L, s.V, s.N, s.T, s.params, lib, dtype)
            bad = ~np.isfinite(f).all(axis=1)
            if bad.any() and not first:
                first = _where(s.labels[int(np.argmax(bad))], s.params)
            bad_s += 3 * int(np.count_nonzero(bad))
        counts[dtype] = (bad_h, bad_s, first)
    h32, s32, where32 = counts["float32"]
    c32 = Check("float32 finite", not (h32 or s32), f"{h32} NaN/Inf on the hemisphere, {s32} on the stress set"
                + (f" (first: {where32})" if where32 else ""), float(h32 + s32))
    unsafe = [(b.id, b.fp16_unsafe) for b in _bricks(spec, lib) if b.fp16_unsafe]
    h16, s16, where16 = counts["float16"]
    text = (f"{h16} NaN/Inf on the hemisphere, {s16} on the stress set (reported)"
            + (f" (first: {where16})" if where16 else ""))
    if unsafe:
        why = "; ".join(f"{i}: {w}" for i, w in unsafe)
        c16 = Check("float16 finite", True, f"reported, not required: declared fp16-unsafe ({why}); " + text,
                    float(h16), skipped=why)
    else:
        c16 = Check("float16 finite", not h16, text, float(h16))
    return [c32, c16]


def check(spec: str, lib, params: dict | None = None, mc: bool = True) -> dict:
    """Every plausibility check of one spec: {"spec", "pass", "checks": [...]}.

    params: a material's values (each check at those alone); None: the defaults, and the stress sweeps where
    a check takes a parameter set per sweep value (non-negativity, reciprocity, float32 finite), the
    brightest colours for the furnace (bright())."""
    checks = [non_negative(spec, lib, params), reciprocity(spec, lib, params), albedo(spec, lib, params, mc),
              *finite(spec, lib, params)]
    return {"spec": spec, "pass": all(c.passed for c in checks), "checks": [c.asdict() for c in checks]}


def markdown(results: list[dict]) -> list[str]:
    """The plausibility table of an accuracy report (one row per spec without an independent reference)."""
    if not results:
        return []
    names = [c["check"] for c in results[0]["checks"]]
    lines = ["## Plausibility (no independent reference: the bricks' own formula, NumPy)", "",
             "Checked from the bricks alone: f >= 0 on the stress set; f(l, v) = f(v, l) unless a brick declares "
             "`\"reciprocal\": \"no: why\"`; the white furnace E(v) = ∫ f cos θ_l dω_l <= 1 by quadrature and by "
             "cosine-weighted MC; no NaN or Inf in float32; in float16 on the hemisphere unless a brick is "
             "declared fp16-unsafe.", "",
             "| spec | verdict | " + " | ".join(names) + " |", "|---|---|" + "---|" * len(names)]
    for r in results:
        cells = [("pass" if c["pass"] else "**FAIL**") + f": {c['detail']}" for c in r["checks"]]
        lines.append(f"| `{r['spec']}` | {'pass' if r['pass'] else '**FAIL**'} | " + " | ".join(
            x.replace("|", "\\|") for x in cells) + " |")
    return lines + [""]
