"""Float64 references of the BRDF bricks, written from the papers; a registry keyed by brick id per kind.

A reference computes the model the brick claims to implement, exactly, from
the paper's formula (cited per function) — never from the brick source — under
the shading policy of docs/design/accuracy.md (geometry.py). Guards that a brick applies for
float32 (roughness floors, cosine floors) are *not* reproduced: their cost is
what `shadermatrix accuracy` measures.

Signatures per kind (a new brick adds one function with @reference(kind, id)):
  diffuse, specular:  f(g: Geometry, p: dict, slots: dict) -> (N, 3) f_r in 1/sr
  ndf:                f(cos_h, sin2_h, alpha) -> (N,) D
  fresnel:            f(f0 (N, 3), cos_d) -> (N, 3) F, cos_d = v·h
  visibility:         f(g: Geometry, alpha) -> (N,) the geometry factor G (not G/(4 n·l n·v))
A slot filler that reads more than its contract's arguments (a tangent-frame row, its own
parameters: an anisotropic NDF's alpha_u, alpha_v; a conductor's eta, k) declares keyword-only
parameters `g` (the Geometry) and/or `p` (the spec's parameter values); the host's reference
calls it through the slot with both bound (slot_function()).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from . import exact
from .geometry import Geometry, shading_geometry

REFERENCES: dict[str, dict[str, Callable]] = {
    k: {} for k in ("diffuse", "specular", "ndf", "fresnel", "visibility")}


class ReferenceMissing(LookupError):
    """A brick without a float64 reference."""


def reference(kind: str, brick_id: str):
    """Register the reference of brick `brick_id` of `kind`."""
    def register(fn):
        if brick_id in REFERENCES[kind]:
            raise ValueError(f"two references for {kind} brick '{brick_id}'")
        REFERENCES[kind][brick_id] = fn
        return fn
    return register


def lookup(kind: str, brick_id: str) -> Callable:
    """The reference function of a brick; ReferenceMissing if none is registered."""
    fn = REFERENCES.get(kind, {}).get(brick_id)
    if fn is None:
        raise ReferenceMissing(f"{kind} brick '{brick_id}' has no float64 reference — "
                               f"add one with @reference({kind!r}, {brick_id!r}) in generator/reference/")
    return fn


def _rgb(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)[:, None] if np.ndim(x) == 1 else x


# ------------------------------------------------------------------ diffuse

@reference("diffuse", "lambert")
def lambert(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = ρ_d / π (Lambert 1760; Hoffman & Baker 2006; RTR3 eq. 7.36)."""
    return np.broadcast_to(p["rho_d"] / np.pi, (g.count, 3))


# ------------------------------------------------------------------ specular

@reference("specular", "phong_normalized")
def phong_normalized(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = (n+2)/(2π) R_F(0) max(0, r·v)^n, r the mirror direction of l (Hoffman & Baker 2006, normalized Phong)."""
    n = p["n"]
    return p["f0"] * _rgb((n + 2.0) / (2.0 * np.pi) * g.RdotV ** n)


@reference("specular", "blinn_phong_normalized")
def blinn_phong_normalized(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = (n+4)/(8π) R_F(0) cos^n θ_h (Hoffman & Baker 2006, normalized Blinn-Phong)."""
    n = p["n"]
    return p["f0"] * _rgb((n + 4.0) / (8.0 * np.pi) * exact.cos_power(g.NdotH, g.NxH2, n))


@reference("specular", "microfacet")
def microfacet(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = F(v·h) D(h) G(l, v) / (4 (n·l)(n·v)) (Walter et al. 2007 eq. 20; RTR3 eq. 7.51;
    Cook & Torrance 1982 with the 1/4 of the half-vector Jacobian)."""
    a = p["alpha"]
    D = slots["ndf"](g.NdotH, g.NxH2, a)
    G = slots["vis"](g, a)
    F = slots["fresnel"](p["f0"], g.VdotH)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = D * G / (4.0 * g.NdotL * g.NdotV)
        f = F * _rgb(s)
    # A Dirac NDF (alpha = 0) times zero reflectance or zero visibility is no reflection.
    return np.where((F == 0.0) | (G == 0.0)[:, None], 0.0, f)


# ------------------------------------------------------------------ microfacet slots

@reference("ndf", "ggx")
def ndf_ggx(cos_h, sin2_h, alpha):
    """GGX (Walter et al. 2007 eq. 33)."""
    return exact.d_ggx(cos_h, sin2_h, alpha)


@reference("ndf", "beckmann")
def ndf_beckmann(cos_h, sin2_h, alpha):
    """Beckmann, m = alpha (Walter et al. 2007 eq. 25)."""
    return exact.d_beckmann(cos_h, sin2_h, alpha)


@reference("ndf", "blinn_phong")
def ndf_blinn_phong(cos_h, sin2_h, alpha):
    """Normalized Blinn-Phong NDF, n = 2/α² - 2 (RTR3 eq. 7.48; Walter et al. 2007 eq. 30)."""
    return exact.d_blinn_phong(cos_h, sin2_h, alpha)


@reference("fresnel", "schlick")
def fresnel_schlick(f0, cos_d):
    """Schlick 1994 eq. 15."""
    return exact.fresnel_schlick(f0, cos_d)


@reference("fresnel", "none")
def fresnel_none(f0, cos_d):
    """F = R_F(0) at every angle (RTR3 §7.6.1)."""
    return np.broadcast_to(f0, np.shape(cos_d) + (3,))


@reference("visibility", "implicit")
def vis_implicit(g: Geometry, alpha):
    """G = (n·l)(n·v) (RTR3 eq. 7.53)."""
    return g.NdotL * g.NdotV


@reference("visibility", "torrance_sparrow")
def vis_torrance_sparrow(g: Geometry, alpha):
    """V-cavity G (Torrance & Sparrow 1967; Blinn 1977; RTR3 eq. 7.54)."""
    return exact.g_torrance_sparrow(g.NdotH, g.NdotV, g.NdotL, g.VdotH)


@reference("visibility", "smith_schlick")
def vis_smith_schlick(g: Geometry, alpha):
    """G = G1(l) G1(v), Schlick's G1 with k = m sqrt(2/π) (Schlick 1994; RTR3 eq. 7.56)."""
    k = exact.schlick_k_beckmann(alpha)
    return exact.smith_schlick_g1(g.NdotL, k) * exact.smith_schlick_g1(g.NdotV, k)


# ------------------------------------------------------------------ whole BRDFs

def brdf_parameters(rb) -> dict:
    """{name: (type, default, range)} of a resolved BRDF spec (spec/resolve.py resolve_brdf): the one parameter
    policy's group."""
    return {k: (p.ty, p.default, p.range) for k, p in rb.params.items()}


def _param_values(declared: dict, given: dict | None, count: int) -> dict:
    given = dict(given or {})
    unknown = set(given) - set(declared)
    if unknown:
        raise ValueError(f"unknown parameter(s) {', '.join(sorted(unknown))}; "
                         f"this BRDF has {', '.join(sorted(declared)) or 'none'}")
    out = {}
    for name, (ty, default, _range) in declared.items():
        v = np.asarray(given.get(name, default), dtype=np.float64)
        if ty.kind == "vector":
            v = np.broadcast_to(v, (count, ty.components) if v.ndim < 2 else v.shape)
        elif v.ndim == 0:
            v = np.broadcast_to(v, (count,))
        out[name] = v
    return out


def slot_function(fn: Callable, g: Geometry, p: dict) -> Callable:
    """A slot filler's reference with its keyword-only `g` / `p` bound, when it declares them."""
    import inspect
    kw = {name: value for name, value in (("g", g), ("p", p))
          if (param := inspect.signature(fn).parameters.get(name)) is not None
          and param.kind is inspect.Parameter.KEYWORD_ONLY}
    return (lambda *args: fn(*args, **kw)) if kw else fn


def _term(node, g: Geometry, p: dict) -> np.ndarray:
    if node.counts:  # an array parameter's element count, a key constant: `<array>_count` as the brick reads it
        p = {**p, **{f"{a}_count": c for a, c in node.counts}}
    slots = {slot: slot_function(lookup(filler.brick.kind, filler.brick.id), g, p)
             for slot, filler in node.fillers}
    return lookup(node.brick.kind, node.brick.id)(g, p, slots)


def reference_brdf(spec: str, L, V, N, T=None, params=None, lib=None) -> np.ndarray:
    """f_r of a BRDF spec in float64, (N, 3), from the papers' formulas under the shading policy of docs/design/accuracy.md.

    params: {name: value}; a value is a scalar, an RGB triple, or one per sample
    ((N,) or (N, 3)). Missing parameters take the bricks' defaults.
    """
    from ..library.bricks import library_or_builtin
    from ..spec.resolve import resolve_brdf
    rb = resolve_brdf(spec, library_or_builtin(lib))
    g = shading_geometry(L, V, N, T)
    p = _param_values(brdf_parameters(rb), params, g.count)
    total = np.zeros((g.count, 3))
    for node in rb.nodes:
        total = total + _term(node, g, p)
    return np.where(g.lit[:, None], total, 0.0)


def missing_references(lib=None) -> list[str]:
    """'kind/id' of every BRDF brick (terms and slot fillers) that has no reference."""
    from ..library.bricks import library_or_builtin
    lib = library_or_builtin(lib)
    return [f"{k}/{b.id}" for k in REFERENCES for b in lib.of_kind(k) if b.id not in REFERENCES[k]]
from . import diffuse as _diffuse  # noqa: E402,F401  (registers the diffuse references)
from . import specular as _specular  # noqa: E402,F401
from . import fillers as _fillers  # noqa: E402,F401
