"""IBL accuracy: the split sum and SH9 × the AmbientBRDF's diffuse channel against a brute-force float64 Monte
Carlo integral of the whole environment, the same environment and BRDF (`ibl_accuracy`, for `accuracy`).

Geometry: the normal n is tilted 30° from +Y towards +Z; v lies in the plane of n and +Y at θ_v from n on
the side away from +Y, so r = reflect(−v, n) rises into the sky as θ_v grows. Per roughness α and θ_v:

- specular (the microfacet term, f0 = 1: a white metal): reference ∫ L f cos dω by one-sample MIS of
  the term's own sampler and of the environment's luminance distribution (balance heuristic, `samples`
  of each, a fixed seed); split sum = prefiltered(r, lod = √α (L − 1)) × (f0 R + G)(n·v, α).
- diffuse (Gotanda eq. 4 with ρ = 1, f0 = 0.04): reference by MIS of cosine-weighted and environment
  samples, f of eq. 4 by quadrature (`diffuse_brdf`); IBL = ρ (1 − f0) B(n·v, α) × E_SH9(n)/π; the
  Lambert-only ambient an engine without the diffuse channel uses = ρ E_SH9(n)/π.

Errors are relative, of the luminance: (approximation − reference)/reference; `std` is the reference's own
standard error relative to it.
"""
from __future__ import annotations

import numpy as np

from . import ibl_env, ibl_tables

ROUGHNESS = (0.05, 0.2, 0.5, 0.9)  # α
VIEWS_DEG = (0.0, 45.0, 75.0, 85.0)
LUM = np.array([0.2126, 0.7152, 0.0722])
SPEC = "gotanda_fitted+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"
TILT_DEG = 30.0


def geometry(theta_v_deg: float):
    """(n, t, b, v) world vectors of the measured configuration."""
    tilt = np.radians(TILT_DEG)
    n = np.array([0.0, np.cos(tilt), np.sin(tilt)])
    t = np.array([0.0, -np.sin(tilt), np.cos(tilt)])  # in the plane of n and +Y, away from +Y
    b = np.cross(n, t)
    th = np.radians(theta_v_deg)
    return n, t, b, np.cos(th) * n + np.sin(th) * t


class EnvSampler:
    """Directions drawn ∝ texel luminance × solid angle (piecewise constant per texel, mixed with 5 % uniform
    so that every direction has density), and that density."""

    def __init__(self, env: ibl_env.Environment):
        h, w = env.image.shape[:2]
        self.env, self.w, self.h = env, w, h
        self.dw = ibl_env.texel_solid_angles(w, h)
        p = (env.image @ LUM) * self.dw[:, None]
        p = p / p.sum()
        self.p = 0.95 * p + 0.05 * np.broadcast_to(self.dw[:, None] / (4 * np.pi), p.shape)
        self.cdf = np.cumsum(self.p.ravel())

    def sample(self, rng, n: int) -> np.ndarray:
        k = np.minimum(np.searchsorted(self.cdf, rng.random(n) * self.cdf[-1]), self.cdf.size - 1)
        j, i = np.divmod(k, self.w)
        u = (i + rng.random(n)) / self.w
        c0, c1 = np.cos(j * np.pi / self.h), np.cos((j + 1) * np.pi / self.h)
        cos_t = c0 + rng.random(n) * (c1 - c0)  # uniform in solid angle within the texel
        sin_t = np.sqrt(np.maximum(1.0 - cos_t ** 2, 0.0))
        phi = (u - 0.5) * 2.0 * np.pi + self.env.rotation
        return np.stack([sin_t * np.sin(phi), cos_t, -sin_t * np.cos(phi)], -1)

    def pdf(self, d: np.ndarray) -> np.ndarray:
        u, v = self.env.uv(d)
        i = np.minimum((u * self.w).astype(np.intp), self.w - 1)
        j = np.minimum((v * self.h).astype(np.intp), self.h - 1)
        return self.p[j, i] / self.dw[j]


def diffuse_brdf(L_local: np.ndarray, v_local: np.ndarray, alpha: float, nodes=(32, 64)) -> np.ndarray:
    """(m,) f_r of Gotanda eq. 4 (ρ = 1, divided by 1 − f0) for many lights and one view, local frame n = z."""
    from ..reference import exact
    m, wm = ibl_tables._facets(float(alpha), *nodes)
    fv = ibl_tables._facet_fresnel(m @ v_local) * wm
    nl, nv = np.maximum(L_local[:, 2], 1e-12), max(float(v_local[2]), ibl_tables.NV_MIN)
    out = np.empty(len(L_local))
    for i in range(0, len(L_local), 2048):
        out[i:i + 2048] = ibl_tables._facet_fresnel(L_local[i:i + 2048] @ m.T) @ fv
    g2 = 1.0 / (1.0 + exact.lambda_ggx(nl, alpha) + exact.lambda_ggx(np.array([nv]), alpha)[0])
    return np.where(L_local[:, 2] > 0.0, 21.0 / 20.0 * g2 * out / (np.pi * nl * nv), 0.0)


def _cosine(rng, n: int) -> np.ndarray:
    u = rng.random((n, 2))
    r, phi = np.sqrt(u[:, 0]), 2 * np.pi * u[:, 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1 - u[:, 0], 0.0))], -1)


def _mis(f_cos, bsdf_dirs, bsdf_pdf, env_dirs, env_pdf_of, bsdf_pdf_of, radiance):
    """Balance-heuristic estimate (mean, std error) of ∫ L f cos from the two strategies' samples."""
    parts = []
    for d, p_own, p_other in ((bsdf_dirs, bsdf_pdf, env_pdf_of(bsdf_dirs)),
                              (env_dirs, env_pdf_of(env_dirs), bsdf_pdf_of(env_dirs))):
        fc = f_cos(d)
        denom = p_own + p_other
        parts.append(np.where(denom > 0, (radiance(d) @ LUM) * fc / np.where(denom > 0, denom, 1.0), 0.0))
    x = parts[0] + parts[1]  # one sample of each per pair: an estimate of the integral
    return float(x.mean()), float(x.std() / np.sqrt(len(x)))


def _specular_reference(env, es, alpha, n, t, b, v, samples, rng, lib):
    from ..reference import reference_brdf
    from . import sampling
    term = ibl_tables.classify(SPEC, lib)[1].spec
    N, T = np.broadcast_to(n, (samples, 3)), np.broadcast_to(t, (samples, 3))
    V = np.broadcast_to(v, (samples, 3))
    prm = {"alpha": alpha}
    Lb = sampling.sample(term, rng.random((samples, 2)), V, N, T, prm, lib=lib)

    def pdf_of(d):
        return sampling.pdf(term, d, V[:len(d)], N[:len(d)], T[:len(d)], prm, lib=lib)

    def f_cos(d):
        with np.errstate(all="ignore"):
            f = reference_brdf(term, d, V[:len(d)], N[:len(d)], T[:len(d)], {"alpha": alpha, "f0": 1.0}, lib=lib)
        return np.nan_to_num(f[:, 0]) * np.maximum(d @ n, 0.0)

    return _mis(f_cos, Lb, pdf_of(Lb), es.sample(rng, samples), es.pdf, pdf_of, env.radiance)


def _diffuse_reference(env, es, alpha, n, t, b, v, samples, rng):
    frame = np.stack([t, b, n])  # world → local rows
    v_loc = frame @ v
    local = _cosine(rng, samples)
    Lc = local @ frame

    def f_cos(d):
        loc = d @ frame.T
        return diffuse_brdf(loc, v_loc, alpha) * np.maximum(loc[:, 2], 0.0)

    def cos_pdf(d):
        return np.maximum(d @ n, 0.0) / np.pi

    return _mis(f_cos, Lc, cos_pdf(Lc), es.sample(rng, samples), es.pdf, cos_pdf, env.radiance)


def ibl_accuracy(env: ibl_env.Environment | None = None, roughness=ROUGHNESS, views_deg=VIEWS_DEG,
                 samples: int = 1 << 15, cube=None, lib=None, seed: int = 7) -> dict:
    """The IBL error tables: {"rows": [...], "sh9": irradiance_error, "cube": cube_error rows, "table": ...}.
    env: the default sky unless given; cube: a prefiltered chain (prefilter(env) unless given)."""
    env = env or ibl_env.sky(256)
    cube = cube if cube is not None else ibl_env.prefilter(env, 32)
    table = ibl_tables.ambient_brdf(SPEC, lib=lib)
    sh = ibl_env.sh9(env)
    es = EnvSampler(env)
    rng = np.random.default_rng(seed)
    rows = []
    levels = len(cube)
    for a in roughness:
        for th in views_deg:
            n, t, b, v = geometry(th)
            mu = float(np.dot(n, v))
            r = 2 * mu * n - v
            R, G, B, _ = table.lookup(mu, a)
            pre = ibl_env.cube_lookup(cube, r[None], np.sqrt(a) * (levels - 1))[0] @ LUM
            split = pre * (R + G)
            ref_s, std_s = _specular_reference(env, es, a, n, t, b, v, samples, rng, lib)
            irr = ibl_env.sh9_irradiance(sh, n[None])[0] @ LUM
            ref_d, std_d = _diffuse_reference(env, es, a, n, t, b, v, samples // 4, rng)
            f0 = 0.04
            ibl_d = (1 - f0) * B * irr / np.pi
            rows.append({"alpha": a, "theta_v": th, "spec_ref": ref_s, "spec_std": std_s / ref_s,
                         "split_sum": split, "spec_err": (split - ref_s) / ref_s,
                         "diff_ref": (1 - f0) * ref_d, "diff_std": std_d / ref_d,
                         "sh9_table": ibl_d, "diff_err": (ibl_d - (1 - f0) * ref_d) / ((1 - f0) * ref_d),
                         "lambert_err": (irr / np.pi - (1 - f0) * ref_d) / ((1 - f0) * ref_d)})
    return {"rows": rows, "spec": SPEC, "samples": samples, "environment": env.name}


def markdown(result: dict) -> str:
    """ibl_accuracy()'s rows as a Markdown table."""
    out = ["| α | θ_v | split sum err | MC std | SH9 × B err | Lambert-only err | MC std (diffuse) |",
           "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        out.append(f"| {r['alpha']:g} | {r['theta_v']:g}° | {100 * r['spec_err']:+.2f} % | {100 * r['spec_std']:.2f} % | "
                   f"{100 * r['diff_err']:+.2f} % | {100 * r['lambert_err']:+.2f} % | {100 * r['diff_std']:.2f} % |")
    return "\n".join(out)

