"""The AmbientBRDF table of image-based lighting (split sum's second factor), baked numerically in float64.

Gotanda 2014 §4: "numerical integration should be used to compute the AmbientBRDF for better accuracy",
with the "integrated diffuse components" stored in the same texture. One table per (NDF, visibility,
Fresnel) of a microfacet term, over (x, y) = (n·v, √α) at texel centres (reference/tables.py conventions:
x_i = i/(W − 1), read at u = x (W − 1)/W + 0.5/W), RGBA:

- R = scale, G = bias of f0: ∫ f cos θ_l dω_l = f0 · R + G. For Schlick, R = ∫ f/F cos (1 − (1 − v·h)^5),
  G = ∫ f/F cos (1 − v·h)^5 (Karis 2013's split sum). Any Fresnel brick *affine in f0* separates so
  (Schlick; Gotanda's spherical Gaussian, eq. 3; `none`, F = f0): the table is baked from the float64
  reference of the whole term at f0 = 1 and f0 = 0 (R = E(1) − E(0), G = E(0)), and affinity is checked
  numerically on every bake (E(½) against the mean), so an engine Fresnel brick is classified by what it
  computes, not by its name. A Fresnel that is not affine (exact dielectric, conductor, a painted ramp)
  is refused, located (`IblRefusal`).
- B = the directional albedo of Gotanda's microfacet diffuse model (eq. 4: Lambertian facets, GGX D,
  eq. 6's F_diff on each facet, height-correlated Smith G; his footnote 3) for ρ = 1 with (1 − f0)
  factored out (eq. 6 carries it as a factor: footnote 4), integrated numerically (`diffuse_albedo`);
  the diffuse ambient term is ρ (1 − f0) B · E(n)/π with E the irradiance. At α → 0 it is
  1 − (1 − n·v)^5 exactly (the facet is the surface; ∫ F_diff cos/π = (1 − f0)(1 − (1 − μ)^5)).
  A spec whose diffuse is Lambert gets B = 1 (ρ/π × irradiance is exact), one with no diffuse term B = 0;
  any other diffuse brick (Oren-Nayar, …) is refused, located.
- A = 1.

The specular integral is importance-sampled with the term's own sampler (generator.eval.sampling: GGX by
visible normals, Heitz 2018; Beckmann by D cos θ_h, Walter et al. 2007), f from the float64 reference
(generator.reference.reference_brdf), on a deterministic Fibonacci lattice of `SAMPLES` points per texel
(the same points for every texel, so the table carries no texel-to-texel noise); `convergence` is the
largest change of any texel from SAMPLES/4 points to SAMPLES. Edges: n·v is floored at the shading
policy's 1e-4 and α at `ALPHA_MIN` (pbrt-v4's delta threshold: below it the lobe is a mirror and the
table's first row holds the mirror's values to < 1e-3).

A baked table is kept in memory and in the per-user content-addressed store (io.Store, namespace
"ibl"), keyed by `input_key`: the term, size, samples and the sources it is computed from (this module,
the references, the samplers, the term's brick files).
"""
from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io import Store, content_key, default_cache_dir
from ..lang.errors import UserError
from ..library.bricks import library_or_builtin

SIZE = (32, 32)  # (n·v, √α) texels
SAMPLES = 4096  # lattice points per texel (specular)
ALPHA_MIN = 1e-3
NV_MIN = 1e-4  # geometry.NV_MIN: the shading policy's floor of n·v
AFFINE_TOL = 1e-9  # relative: E(½) against (E(0) + E(1))/2 for a Fresnel affine in f0 (float64 rounding ~1e-15)
DIFFUSE_NODES = (32, 64, 16, 32)  # facet normals (t, φ) × light directions (cos θ_l, φ_l ∈ [0, π])
NAMESPACE = "ibl"
_HERE = Path(__file__).resolve().parent


class IblRefusal(UserError):
    """A BRDF term the AmbientBRDF machinery cannot tabulate: `where: what — what to do`."""


def _golden_lattice(n: int) -> np.ndarray:
    """n points of the Fibonacci (rank-1, golden-ratio) lattice in [0, 1)², (n, 2)."""
    i = np.arange(n, dtype=np.float64)
    return np.stack([(i + 0.5) / n, np.mod(i * 0.6180339887498949, 1.0)], -1)


def axes(size=SIZE) -> tuple[np.ndarray, np.ndarray]:
    """(n·v, α) of the table's texel columns and rows (floored at NV_MIN and ALPHA_MIN)."""
    w, h = size
    x = np.linspace(0.0, 1.0, w)
    y = np.linspace(0.0, 1.0, h)
    return np.maximum(x, NV_MIN), np.maximum(y * y, ALPHA_MIN)


# ------------------------------------------------------------------ which terms get what

# classify(), Term and DIFFUSE_HOW are the spec stage's verdict (spec/ambient.py), which the glue reads too
from ..spec.ambient import DIFFUSE_HOW, Term, classify  # noqa: E402,F401


def refuse(term: Term, where: str = "") -> None:
    """Raise the located refusal of a term classify() refused."""
    prefix = f"{where}: " if where else ""
    raise IblRefusal(f"{prefix}brdf term '{term.spec}': {term.why}")


# ------------------------------------------------------------------ the cache

_MEMO: dict[str, np.ndarray] = {}


def _code_paths() -> list[Path]:
    ref = _HERE.parent / "reference"
    return [*_HERE.glob("ibl*.py"), _HERE / "sampling.py", _HERE.parent / "link" / "sampling.py",
            *ref.glob("*.py")]


def input_key(what: str, spec: str, size, samples: int, lib=None) -> str:
    """The content key of a table: what it is, the term, size, samples and every source it is computed from,
    each source by its file name and bytes (no directory: the key is the same in any checkout)."""
    from ..spec.resolve import resolve_brdf
    lib = library_or_builtin(lib)
    bricks = [n.brick for top in resolve_brdf(spec, lib).nodes for n in top.tree] if spec else []
    h = hashlib.sha256()
    for p in sorted(_code_paths()) + sorted({Path(b.path) for b in bricks}):
        h.update(p.name.encode() + b"\0" + p.read_bytes() + b"\0")
    return content_key(what, spec, list(size), samples, h.hexdigest())


def _cached(key: str, shape, make, store: Store | None | bool = True) -> tuple[np.ndarray, bool]:
    """(texels, hit): from memory, the store, or made (and kept in both)."""
    if key in _MEMO:
        return _MEMO[key], True
    st = None
    if store is True:
        root = default_cache_dir()
        st = Store(root) if root is not None else None
    elif isinstance(store, Store):
        st = store
    if st is not None:
        data = st.get(NAMESPACE, key)
        if data is not None and len(data) == 8 * int(np.prod(shape)):
            arr = np.frombuffer(data, "<f8").reshape(shape).copy()
            arr.setflags(write=False)
            _MEMO[key] = arr
            return arr, True
    arr = np.ascontiguousarray(make(), np.float64)
    arr.setflags(write=False)
    _MEMO[key] = arr
    if st is not None:
        st.put(NAMESPACE, key, arr.astype("<f8").tobytes())
    return arr, False


# ------------------------------------------------------------------ the specular scale and bias

def _integrals(term: str, mu: np.ndarray, alpha: float, u: np.ndarray, f0s, lib) -> np.ndarray:
    """(len(f0s), len(mu)) E = ∫ f cos θ_l dω_l at each view cosine, term's sampler on the points u."""
    from ..reference import reference_brdf
    from . import sampling
    m, n = len(mu), len(u)
    V = np.repeat(np.stack([np.sqrt(1.0 - mu * mu), np.zeros(m), mu], -1), n, axis=0)
    N = np.broadcast_to([0.0, 0.0, 1.0], V.shape)
    T = np.broadcast_to([1.0, 0.0, 0.0], V.shape)
    U = np.tile(u, (m, 1))
    L = sampling.sample(term, U, V, N, T, {"alpha": alpha}, lib=lib)
    p = sampling.pdf(term, L, V, N, T, {"alpha": alpha}, lib=lib)
    ok = (p > 0.0) & (L[:, 2] > 0.0)
    w = np.where(ok, L[:, 2] / np.where(ok, p, 1.0), 0.0)
    out = []
    for f0 in f0s:
        with np.errstate(all="ignore"):
            f = reference_brdf(term, L, V, N, T, {"alpha": alpha, "f0": f0}, lib=lib)[:, 0]
        out.append(np.where(ok, f * w, 0.0).reshape(m, n).mean(axis=1))
    return np.array(out)


def _specular_texels(term: str, size, samples: int, lib, where: str) -> np.ndarray:
    mu, alphas = axes(size)
    u = _golden_lattice(samples)
    out = np.zeros((size[1], size[0], 2))
    check_row = len(alphas) // 2
    for j, a in enumerate(alphas):
        f0s = (0.0, 1.0, 0.5) if j == check_row else (0.0, 1.0)
        e = _integrals(term, mu, float(a), u, f0s, lib)
        if j == check_row:
            mid, mean = e[2], 0.5 * (e[0] + e[1])
            bad = np.abs(mid - mean) > AFFINE_TOL * np.maximum(np.abs(mean), 1e-12)
            if bad.any():
                k = int(np.argmax(np.abs(mid - mean)))
                prefix = f"{where}: " if where else ""
                raise IblRefusal(f"{prefix}brdf term '{term}': its Fresnel is not affine in f0 (at n·v = {mu[k]:.3g}, "
                                 f"α = {a:.3g}: E(f0 = ½) = {mid[k]:.6g}, the mean of E(0) and E(1) {mean[k]:.6g}), so "
                                 "the AmbientBRDF's scale and bias cannot hold it — use fresnel=schlick or "
                                 "fresnel=spherical_gaussian for image-based lighting")
        out[j, :, 0] = e[1] - e[0]
        out[j, :, 1] = e[0]
    return out


# ------------------------------------------------------------------ the diffuse channel (Gotanda eq. 4)

def _facets(alpha: float, n_t: int, n_phi: int):
    from ..reference.diffuse import _m_nodes
    return _m_nodes(alpha, n_t, n_phi)


def _facet_fresnel(c: np.ndarray) -> np.ndarray:
    """c (1 − (1 − c)^5) for c = max(m·x, 0), multiplied out (eq. 6's factor times the facet cosine)."""
    c = np.maximum(c, 0.0)
    return c * c * (5.0 + c * (-10.0 + c * (10.0 + c * (-5.0 + c))))


def diffuse_albedo(mu, alpha: float, nodes=DIFFUSE_NODES) -> np.ndarray:
    """Directional albedo of Gotanda 2014 eq. 4 (ρ = 1, divided by 1 − f0) at view cosines mu:

    E(v) = ∫ f_r cos θ_l dω_l, f_r = 21/20 / (π (n·l)(n·v)) ∫ (m·l)⁺ (1 − (1 − m·l)^5) (m·v)⁺ (1 − (1 − m·v)^5)
    D(m) G₂(l, v) dω_m, G₂ = 1/(1 + Λ(l) + Λ(v)) (height-correlated Smith, GGX).

    The facet integral uses reference/diffuse.py's GGX-CDF nodes (Gauss-Legendre × midpoint), the light
    integral Gauss-Legendre in cos θ_l × Gauss-Legendre in φ_l over [0, π] (the integrand is even in φ_l
    for v in the x-z plane), doubled. (n·l) cancels against the cosine; the facet sums are one matrix
    product per light chunk, so a whole row of views costs one pass."""
    from ..reference import exact
    from .plausibility import gauss_legendre
    n_t, n_phi, n_a, n_b = nodes
    mu = np.maximum(np.atleast_1d(np.asarray(mu, np.float64)), NV_MIN)
    m, wm = _facets(float(alpha), n_t, n_phi)
    V = np.stack([np.sqrt(1.0 - mu * mu), np.zeros_like(mu), mu], -1)
    fv = _facet_fresnel(V @ m.T) * wm[None, :]  # (views, facets)
    c, wc = gauss_legendre(0.0, 1.0, n_a)
    p, wp = gauss_legendre(0.0, np.pi, n_b)
    C, P = (a.ravel() for a in np.meshgrid(c, p, indexing="ij"))
    W = (2.0 * np.outer(wc, wp)).ravel()  # dω = d(cos θ) dφ, both halves of φ
    s = np.sqrt(1.0 - C * C)
    L = np.stack([s * np.cos(P), s * np.sin(P), C], -1)
    lam_v = exact.lambda_ggx(mu, alpha)
    total = np.zeros(len(mu))
    for i in range(0, len(L), 256):
        fl = _facet_fresnel(L[i:i + 256] @ m.T)  # (lights, facets)
        S = fl @ fv.T  # (lights, views)
        g2 = 1.0 / (1.0 + exact.lambda_ggx(C[i:i + 256], alpha)[:, None] + lam_v[None, :])
        total += (W[i:i + 256, None] * g2 * S).sum(axis=0)
    return 21.0 / 20.0 * total / (np.pi * mu)


def _diffuse_texels(size, nodes=DIFFUSE_NODES) -> np.ndarray:
    mu, alphas = axes(size)
    return np.stack([diffuse_albedo(mu, float(a), nodes) for a in alphas])


def diffuse_table(size=SIZE, store=True, nodes=DIFFUSE_NODES) -> np.ndarray:
    """(H, W) the B channel: eq. 4's directional albedo over (n·v, √α), cached by input key."""
    key = input_key("gotanda_eq4_albedo", "", size, 0) + "-" + "x".join(map(str, nodes))
    arr, _ = _cached(key, (size[1], size[0]), lambda: _diffuse_texels(size, nodes), store)
    return arr


# ------------------------------------------------------------------ the table

@dataclass(frozen=True)
class AmbientBRDF:
    """A baked AmbientBRDF table: texels (H, W, 4) float64, R scale, G bias, B diffuse (eq. 4), A 1."""

    term: str
    texels: np.ndarray
    samples: int
    key: str
    bake_s: float
    cached: bool

    def lookup(self, mu, alpha) -> np.ndarray:
        """(..., 4) the table filtered bilinearly at n·v = mu, α = alpha, as a shader reads it."""
        return lookup(self.texels, mu, alpha)


def lookup(texels: np.ndarray, mu, alpha) -> np.ndarray:
    """Bilinear sample of an (H, W, 4) AmbientBRDF table at table coordinates (n·v, √α)."""
    from ..reference.tables import bilinear, texel_coordinate
    h, w = texels.shape[:2]
    x = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    y = np.sqrt(np.clip(np.asarray(alpha, np.float64), 0.0, 1.0))
    return bilinear(texels, texel_coordinate(x, w), texel_coordinate(y, h))


def ambient_brdf(spec: str, size=SIZE, samples: int = SAMPLES, lib=None, where: str = "",
                 store=True) -> AmbientBRDF:
    """The AmbientBRDF table of the microfacet term of `spec` (a whole BRDF spec, e.g.
    "gotanda_fitted+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"), baked on demand
    and cached by input key. A spec with no microfacet term, or whose microfacet term is refused, raises
    IblRefusal located at `where` (a scene's "path:line:col"). store: True (the per-user store), a Store,
    or False (memory only)."""
    lib = library_or_builtin(lib)
    terms = [t for t in classify(spec, lib) if t.kind == "specular"]
    if not terms:
        prefix = f"{where}: " if where else ""
        raise IblRefusal(f"{prefix}brdf '{spec}' has no specular term — the AmbientBRDF's scale and bias belong "
                         "to a microfacet term: add one, or light the diffuse term by SH9 alone")
    t = terms[0]
    diffuse = [d for d in classify(spec, lib) if d.kind == "diffuse"]
    for d in [t, *diffuse]:
        if d.how == "refused":
            refuse(d, where)
    # B: Gotanda's eq. 4 albedo for his diffuse, 1 for Lambert (exact: rho/pi x irradiance), 0 with no diffuse term
    b_how = diffuse[0].how if diffuse else "none"
    w, h = int(size[0]), int(size[1])
    key = input_key("ambient_brdf", t.spec, (w, h), samples, lib) + "-" + b_how
    start = time.perf_counter()

    def make():
        out = np.zeros((h, w, 4))
        out[..., :2] = _specular_texels(t.spec, (w, h), samples, lib, where)
        out[..., 2] = diffuse_table((w, h), store) if b_how == "gotanda_eq4" else float(b_how == "lambert")
        out[..., 3] = 1.0
        return out

    arr, hit = _cached(key, (h, w, 4), make, store)
    return AmbientBRDF(t.spec, arr, samples, key, time.perf_counter() - start, hit)


def convergence(spec: str, size=SIZE, samples: int = SAMPLES, lib=None) -> dict:
    """The table's convergence error: the largest texel change of R, G from samples/4 to samples points, and
    of B from half to DIFFUSE_NODES (each axis of nodes halved)."""
    lib = library_or_builtin(lib)
    term = [t for t in classify(spec, lib) if t.kind == "specular"][0].spec
    full = ambient_brdf(spec, size, samples, lib, store=False).texels
    quarter = _specular_texels(term, size, samples // 4, lib, "")
    half_nodes = tuple(max(4, n // 2) for n in DIFFUSE_NODES)
    coarse = _diffuse_texels(size, half_nodes)
    return {"scale": float(np.abs(full[..., 0] - quarter[..., 0]).max()),
            "bias": float(np.abs(full[..., 1] - quarter[..., 1]).max()),
            "diffuse": float(np.abs(full[..., 2] - coarse).max())}
