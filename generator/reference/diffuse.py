"""Float64 references of the diffuse bricks (Oren-Nayar and its variants, Ashikhmin-Shirley, Gotanda), and
the microfacet diffuse model Gotanda fits.

Each function is written from its paper's formula (cited per function), never from
the brick sources; the geometry is the shading policy's (geometry.py: n·v clamped to
[1e-4, 1], f_r = 0 for n·l <= 0 applied by reference_brdf). Where a seed text
misprints a formula, the docstring says so and the reference follows the original
paper (the bricks' docstrings quote the misprints).

Also here: `microfacet_diffuse`, the model Gotanda 2014 eq. 4 integrates numerically
(Lambertian microfacets, GGX D, eq. 6's F_diff per facet, height-correlated Smith G;
his footnote 3), by quadrature, and `gotanda_fit_error_table`, the error of his fit
(eq. 8, brick `gotanda_fitted`) against it.
"""
from __future__ import annotations

import numpy as np

from . import exact
from .geometry import Geometry
from .models import reference

# ------------------------------------------------------------------ helpers


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def _rgb(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)[:, None]


def _sigma(p: dict) -> np.ndarray:
    return np.asarray(p["sigma"], dtype=np.float64)


def _scalar(p: dict, name: str) -> np.ndarray:
    """A float parameter as (N, 1), to scale RGB values."""
    return np.asarray(p[name], dtype=np.float64).reshape(-1, 1)


def _cos_phi(g: Geometry) -> np.ndarray:
    """cos(φ_i - φ_o): the azimuths of l and v about n, from their projections onto the tangent plane.

    0 where either projection vanishes (l or v along ±n): there the azimuth is undefined, and
    for a direction along n the sine that multiplies it is 0 anyway. For v = -n (below the
    horizon, shaded as grazing by the policy) it means no retro-reflection term.
    """
    lp = g.L - g.N * _dot(g.N, g.L)[:, None]
    vp = g.V - g.N * _dot(g.N, g.V)[:, None]
    d = np.sqrt(_dot(lp, lp) * _dot(vp, vp))
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(d > 0.0, _dot(lp, vp) / np.where(d > 0.0, d, 1.0), 0.0)
    return np.clip(c, -1.0, 1.0)


def _on_qualitative(g: Geometry, p: dict, a_const: float) -> np.ndarray:
    """Oren & Nayar 1994 eq. 30, the qualitative model, as a BRDF (L_r / (E0 cos θ_i)):

    f = ρ/π (A + B max(0, cos(φ_r - φ_i)) sin α tan β), α = max(θ_i, θ_r), β = min(θ_i, θ_r),
    A = 1 - 0.5 σ²/(σ² + a_const) (a_const = 0.33; 0.57 with interreflection, Oren & Nayar 1994
    §4.4 / RTR3 p. 263), B = 0.45 σ²/(σ² + 0.09), σ in radians.
    """
    s2 = _sigma(p) ** 2
    A = 1.0 - 0.5 * s2 / (s2 + a_const)
    B = 0.45 * s2 / (s2 + 0.09)
    ti = np.arccos(np.clip(g.NdotL, -1.0, 1.0))
    tr = np.arccos(g.NdotV)
    alpha, beta = np.maximum(ti, tr), np.minimum(ti, tr)
    term = np.maximum(0.0, _cos_phi(g)) * np.sin(alpha) * np.tan(beta)
    return p["rho_d"] / np.pi * _rgb(A + B * term)


def _s(g: Geometry) -> np.ndarray:
    """Gotanda's e·l - (n·e)(n·l) (= sin θ_i sin θ_o cos φ), with the policy's clamped n·v."""
    return g.LdotV - g.NdotV * g.NdotL


def _improved_b_term(g: Geometry) -> np.ndarray:
    """The B term of Gotanda 2014 eq. 5 divided by E0 (n·l): s/max(n·l, n·e) for s >= 0, s otherwise.

    eq. 5's first case, s min(1, n·l/n·e), over n·l is s/max(n·l, n·e) (= cos φ sin α tan β, the
    qualitative model's term). Its "otherwise" case prints the radiance ρ/π E0 [(n·l) A + B s]
    without the n·l factor on B s; read literally, f = ρ/π (A + B s/(n·l)), the radiance goes
    negative at grazing light (L_r → ρ/π E0 B s < 0 as n·l → 0). We read it as ρ/π E0 (n·l)
    (A + B s), i.e. f = ρ/π (A + B s), which is positive (A >= 0.5 > 0.45 >= B|s|), reciprocal,
    and what UE4's Diffuse_OrenNayar (citing Gotanda 2012, eq. 5's source) computes.
    """
    s = _s(g)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(s >= 0.0, s / np.maximum(g.NdotL, g.NdotV), s)


def _gotanda_a(sigma) -> np.ndarray:
    s2 = np.asarray(sigma, dtype=np.float64) ** 2
    return 1.0 - 0.5 * s2 / (s2 + 0.65)


def _gotanda_b(sigma) -> np.ndarray:
    s2 = np.asarray(sigma, dtype=np.float64) ** 2
    return 0.45 * s2 / (s2 + 0.09)


def f_diff(f0, NdotL, NdotV) -> np.ndarray:
    """Gotanda 2014 eq. 6 (Shirley et al. 1997): 21/20 (1 - f0)(1 - (1 - n·l)^5)(1 - (1 - n·e)^5)."""
    return 21.0 / 20.0 * (1.0 - np.asarray(f0)) * _rgb((1.0 - (1.0 - NdotL) ** 5) * (1.0 - (1.0 - NdotV) ** 5))


# ------------------------------------------------------------------ Oren-Nayar, qualitative

@reference("diffuse", "oren_nayar")
def oren_nayar(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Oren & Nayar 1994 eq. 30 (qualitative model), as presented by Hoffman & Baker 2006.

    The course notes print C_A = 1 - σ²/(2σ² - 0.66); Oren & Nayar's A = 1 - 0.5 σ²/(σ² + 0.33)
    = 1 - σ²/(2σ² + 0.66): the seed's minus sign is a misprint (it would make C_A > 1 for
    σ² < 0.33 and singular at σ² = 0.33). This reference follows the original paper, including max(0, cos φ)
    and sin α tan β (the notes print cos φ and sin(max θ) cos(min θ)).
    """
    return _on_qualitative(g, p, 0.33)


@reference("diffuse", "oren_nayar_factored")
def oren_nayar_factored(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """The model the factored brick approximates with its table: Oren & Nayar 1994 eq. 30 exactly, as
    `oren_nayar` (the table's error is what accuracy measures)."""
    return _on_qualitative(g, p, 0.33)


@reference("diffuse", "oren_nayar_simplified")
def oren_nayar_simplified(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """RTR3 eqs. 7.57-7.59: the qualitative Oren-Nayar model (Oren & Nayar 1994 eq. 30).

    RTR3 eq. 7.57 prints sin(min(θ_i, θ_o)) tan(max(θ_i, θ_o)); Oren & Nayar's term is
    sin α tan β with α = max, β = min (the printed order diverges at grazing). Followed here.
    """
    return _on_qualitative(g, p, 0.33)


@reference("diffuse", "oren_nayar_simplified_interreflection")
def oren_nayar_simplified_interreflection(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """RTR3 eq. 7.58 with 0.57 for 0.33 in A, "to better approximate surface interreflection" (RTR3 p. 263,
    after Oren & Nayar 1994)."""
    return _on_qualitative(g, p, 0.57)


# ------------------------------------------------------------------ Gotanda 2014

@reference("diffuse", "oren_nayar_improved")
def oren_nayar_improved(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Gotanda 2014 eq. 5 (improved Oren-Nayar of Gotanda 2012) over E0 (n·l):

    f = ρ/π [(1 - 0.5 σ²/(σ² + 0.65)) + 0.45 σ²/(σ² + 0.09) b], b = s/max(n·l, n·e) for
    s = e·l - (n·e)(n·l) >= 0, b = s otherwise (see _improved_b_term for the reading of eq. 5's
    second case).
    """
    sig = _sigma(p)
    return p["rho_d"] / np.pi * _rgb(_gotanda_a(sig) + _gotanda_b(sig) * _improved_b_term(g))


@reference("diffuse", "oren_nayar_fresnel")
def oren_nayar_fresnel(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Gotanda 2014 eq. 7 with F_diff of eq. 6, over E0 (n·l), clamped at 0:

    f = max(0, ρ/π (1 - f0) [F_diff(l, e) A + B b]), A, B, b as in eq. 5 (oren_nayar_improved).
    As printed, (1 - f0) multiplies the bracket and F_diff holds its own (1 - f0): the A term
    carries (1 - f0)², the B term (1 - f0); kept. Eq. 7 prints only eq. 5's s >= 0 case (min(1,
    n·l/n·e)); s < 0 takes eq. 5's other case. F_diff -> 0 at grazing while B b < 0 on the
    backward side, so the bracket goes negative there (e.g. n·l -> 0, e·l < 0): a radiance
    cannot be negative, the value is clamped at 0.
    """
    sig = _sigma(p)
    A, B = _gotanda_a(sig), _gotanda_b(sig)
    f0 = p["f0"]
    bracket = f_diff(f0, g.NdotL, g.NdotV) * _rgb(A) + _rgb(B * _improved_b_term(g))
    return np.maximum(0.0, p["rho_d"] / np.pi * (1.0 - f0) * bracket)


def gotanda_eq8(NdotL, NdotV, LdotV, sigma, f0) -> np.ndarray:
    """Gotanda 2014 eq. 8, L_r(e, l, σ, f0) for ρ = E0 = 1 (= f_r · n·l of the fitted model), unclamped.

    Fr, Lm, Vd, Bp as printed; (n·e²) read as (n·e)²; the seed text repeats Vd's last factor on a
    line of its own, an extraction artifact (UE4's Diffuse_Gotanda has it once), taken once.
    """
    NL, NE = np.asarray(NdotL, np.float64), np.asarray(NdotV, np.float64)
    s = np.asarray(sigma, np.float64)
    s2 = s * s
    d = s2 + 1.36053
    fr = ((1.0 - (0.542026 * s2 + 0.303573 * s) / d)
          * (1.0 - (1.0 - NE) ** (5.0 - 4.0 * s2) / d)
          * ((-0.733996 * s2 * s + 1.50912 * s2 - 1.16402 * s) * (1.0 - NE) ** (1.0 + 1.0 / (39.0 * s2 * s2 + 1.0))
             + 1.0))
    lm = ((np.maximum(1.0 - 2.0 * s, 0.0) * (1.0 - (1.0 - NL) ** 5) + np.minimum(2.0 * s, 1.0))
          * ((1.0 - 0.5 * s) * NL + 0.5 * s * NL ** 2))
    vd = ((s2 / ((s2 + 0.09) * (1.31072 + 0.995584 * NE)))
          * (1.0 - (1.0 - NL) ** ((1.0 - 0.3726732 * NE ** 2) / (0.188566 + 0.388410 * NE))))
    c = np.asarray(LdotV, np.float64) - NE * NL
    bp = np.where(c < 0.0, 1.4 * NE * NL * c, c)
    return 21.0 / (20.0 * np.pi) * (1.0 - np.asarray(f0)) * _rgb(fr * lm + vd * bp)


@reference("diffuse", "gotanda_fitted")
def gotanda_fitted(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Gotanda 2014 eq. 8 as a BRDF, σ = the GGX roughness alpha: f = ρ max(0, L_r) / (n·l) (eq. 8 is
    radiance for ρ = E0 = 1: its Lm carries the n·l factor). The fit goes negative where Vd Bp < 0
    outweighs Fr Lm (backward side, grazing light); clamped at 0. Not reciprocal (ACCURACY-FACTS §4.6)."""
    lr = gotanda_eq8(g.NdotL, g.NdotV, g.LdotV, np.asarray(p["alpha"], np.float64), p["f0"])
    with np.errstate(divide="ignore", invalid="ignore"):
        return p["rho_d"] * np.maximum(0.0, lr) / g.NdotL[:, None]


# ------------------------------------------------------------------ Ashikhmin-Shirley

@reference("diffuse", "ashikhmin_shirley_diffuse")
def ashikhmin_shirley_diffuse(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Ashikhmin & Shirley 2000 eq. 5: f = 28 ρ_d/(23π) (1 - R_s)(1 - (1 - n·l/2)^5)(1 - (1 - n·v/2)^5), R_s = f0."""
    k = (1.0 - (1.0 - g.NdotL / 2.0) ** 5) * (1.0 - (1.0 - g.NdotV / 2.0) ** 5)
    return 28.0 / (23.0 * np.pi) * p["rho_d"] * (1.0 - p["f0"]) * _rgb(k)


# ------------------------------------------------------------------ the microfacet diffuse model (Gotanda eq. 4)

def _m_nodes(alpha: float, n_t: int, n_phi: int):
    """Microfacet normals m (local frame, n = z) and weights w with Σ w g(m) ≈ ∫ g(m) D_GGX(m) dω_m.

    The GGX CDF in u = tan²θ/(α² + tan²θ) makes D cosθ dω = du dφ/(2π); u = 1 - t² removes the
    1/cosθ = O((1-u)^-1/2) of the integrand at the horizon: ∫ g D dω = ∫∫ 2 g sqrt(t² + α²(1-t²))
    dt dφ/(2π). Gauss-Legendre in t, the midpoint rule in φ (periodic).
    """
    t, wt = np.polynomial.legendre.leggauss(n_t)
    t, wt = (t + 1.0) / 2.0, wt / 2.0
    q = np.sqrt(t * t + alpha * alpha * (1.0 - t * t))
    cos_m, sin_m = t / q, alpha * np.sqrt(1.0 - t * t) / q
    phi = (np.arange(n_phi) + 0.5) * 2.0 * np.pi / n_phi
    m = np.stack([np.outer(sin_m, np.cos(phi)), np.outer(sin_m, np.sin(phi)), np.outer(cos_m, np.ones(n_phi))], -1)
    w = np.outer(2.0 * q * wt, np.full(n_phi, 1.0 / n_phi))
    return m.reshape(-1, 3), w.reshape(-1)


def microfacet_diffuse(NdotL, NdotV, cos_phi, alpha: float, f0: float = 0.04, n_t: int = 64, n_phi: int = 128,
                       chunk: int = 256) -> np.ndarray:
    """Gotanda 2014 eq. 4 for ρ = 1 by quadrature: the BRDF of Lambertian microfacets,

    f_r = 1/(π (n·l)(n·e)) ∫ (m·l)⁺ (m·e)⁺ D(m) F_diff(m, l, e) G(m, l, e) dω_m,

    with (footnote 3) D = GGX (roughness α), G = Smith height-correlated, χ⁺(m·l) χ⁺(m·e) /
    (1 + Λ(l) + Λ(e)) (Heitz 2014 eq. 99), and F_diff eq. 6 on the facet: 21/20 (1 - f0)
    (1 - (1 - m·l)^5)(1 - (1 - m·e)^5) (eq. 4 names it F_diff(m, l, e); f0 factors out, as
    eq. 8's 21/20 (1 - f0) and footnote 4 say).

    NdotL, NdotV (> 0), cos_phi: arrays of one shape (the model is isotropic: θ_l, θ_e and the
    azimuth difference φ determine it). Returns f_r, same shape. α = 0 gives the Lambertian
    facet at n: F_diff(n, l, e)/π exactly. Accuracy at the defaults (64 × 128 nodes): <= 1.5e-5
    relative against 256 × 512 over α in [0.05, 1] (the integrand has kinks where m·l or m·e = 0:
    the error falls as 1/n² ); about 1 s per thousand samples.
    """
    NL, NV, cp = np.broadcast_arrays(*(np.asarray(x, np.float64) for x in (NdotL, NdotV, cos_phi)))
    shape = NL.shape
    NL, NV, cp = NL.ravel(), NV.ravel(), np.clip(cp.ravel(), -1.0, 1.0)
    sl, sv = np.sqrt(np.maximum(1.0 - NL * NL, 0.0)), np.sqrt(np.maximum(1.0 - NV * NV, 0.0))
    L = np.stack([sl, np.zeros_like(sl), NL], -1)
    V = np.stack([sv * cp, sv * np.sqrt(np.maximum(1.0 - cp * cp, 0.0)), NV], -1)
    m, w = _m_nodes(float(alpha), n_t, n_phi)
    g2 = 1.0 / (1.0 + exact.lambda_ggx(NL, alpha) + exact.lambda_ggx(NV, alpha))
    out = np.empty(NL.shape)
    for i in range(0, len(NL), chunk):
        ml = np.maximum(L[i:i + chunk] @ m.T, 0.0)
        mv = np.maximum(V[i:i + chunk] @ m.T, 0.0)
        # (m·l)(1 - (1 - m·l)^5) (m·e)(1 - (1 - m·e)^5), the fifth powers multiplied out (NumPy's ** is slow)
        fl = ml * ml * (5.0 + ml * (-10.0 + ml * (10.0 + ml * (-5.0 + ml))))
        fv = mv * mv * (5.0 + mv * (-10.0 + mv * (10.0 + mv * (-5.0 + mv))))
        out[i:i + chunk] = (fl * fv) @ w
    return (21.0 / 20.0 * (1.0 - f0) * g2 * out / (np.pi * NL * NV)).reshape(shape)


def gotanda_fitted_value(NdotL, NdotV, cos_phi, sigma, f0: float = 0.04) -> np.ndarray:
    """f_r of eq. 8 (ρ = 1, clamped at 0 as the brick) at (θ_l, θ_e, φ): the fit's side of the table."""
    NL, NV, cp = np.broadcast_arrays(*(np.asarray(x, np.float64) for x in (NdotL, NdotV, cos_phi)))
    LdotV = NL * NV + np.sqrt((1.0 - NL * NL) * (1.0 - NV * NV)) * cp
    lr = gotanda_eq8(NL.ravel(), NV.ravel(), LdotV.ravel(), sigma, f0)[:, 0]
    return (np.maximum(lr, 0.0) / NL.ravel()).reshape(NL.shape)


FIT_SIGMAS = (0.0, 0.1, 0.25, 0.5, 0.75, 1.0)
FIT_THETAS_DEG = (0.0, 20.0, 40.0, 60.0, 70.0, 80.0, 85.0, 89.0)
FIT_PHIS_DEG = (0.0, 45.0, 90.0, 135.0, 180.0)


def gotanda_fit_error_table(sigmas=FIT_SIGMAS, thetas_deg=FIT_THETAS_DEG, phis_deg=FIT_PHIS_DEG,
                            f0: float = 0.04, n_t: int = 128, n_phi: int = 256) -> list[dict]:
    """The error of Gotanda's fit (eq. 8) against the model it fits (eq. 4 by quadrature, α = σ).

    One row per σ and region of (θ_l, θ_e): "both <= 60°", "one >= 80°" (the other <= 60°),
    "both >= 80°", and "all" over the grid thetas_deg² × phis_deg. Each row: sigma, region,
    samples, max_rel and mean_rel (|fit - exact| / exact), max_abs (|fit - exact| in 1/sr, ρ = 1;
    the Lambertian level is 1/π = 0.318), max_abs_cos (|fit - exact| n·l: the radiance error
    per unit E0, what a light adds), and where max_rel is (theta_l, theta_e, phi in degrees,
    fit, exact). Where both directions graze the exact model is nearly black (1e-7 at
    θ = 89°, φ = 180°) and the relative error is large while the absolute one is not: read
    both. The relative error does not depend on f0 (both carry 21/20 (1 - f0)) except where
    the fit is clamped at 0. The quadrature runs at 128 × 256 nodes: the exact values where both
    directions graze backward are ~1e-7, thin slivers of facets that the default nodes resolve
    only to ~25 % (to < 4 % here, far below the fit's errors there).
    """
    th = np.radians(np.asarray(thetas_deg, np.float64))
    ph = np.radians(np.asarray(phis_deg, np.float64))
    TL, TV, PH = (a.ravel() for a in np.meshgrid(th, th, ph, indexing="ij"))
    NL, NV, CP = np.cos(TL), np.cos(TV), np.cos(PH)
    dl, dv = np.degrees(TL), np.degrees(TV)
    regions = {
        "all": np.ones(len(TL), bool),
        "both <= 60°": (dl <= 60.0) & (dv <= 60.0),
        "one >= 80°": ((dl >= 80.0) & (dv <= 60.0)) | ((dv >= 80.0) & (dl <= 60.0)),
        "both >= 80°": (dl >= 80.0) & (dv >= 80.0),
    }
    rows = []
    for s in sigmas:
        exact_f = microfacet_diffuse(NL, NV, CP, s, f0, n_t=n_t, n_phi=n_phi)
        fit = gotanda_fitted_value(NL, NV, CP, s, f0)
        rel = np.abs(fit - exact_f) / exact_f
        for name, mask in regions.items():
            r = np.where(mask, rel, -1.0)
            i = int(np.argmax(r))
            rows.append({"sigma": float(s), "region": name, "samples": int(mask.sum()),
                         "max_rel": float(rel[mask].max()), "mean_rel": float(rel[mask].mean()),
                         "max_abs": float(np.abs(fit - exact_f)[mask].max()),
                         "max_abs_cos": float((np.abs(fit - exact_f) * NL)[mask].max()),
                         "where": {"theta_l": float(dl[i]), "theta_e": float(dv[i]),
                                   "phi": float(np.degrees(PH[i])), "fit": float(fit[i]),
                                   "exact": float(exact_f[i])}})
    return rows


def fit_error_markdown(rows: list[dict]) -> str:
    """gotanda_fit_error_table() as a Markdown table."""
    out = ["| σ | region | max rel | mean rel | max abs (1/sr) | max abs × n·l | worst rel at (θ_l, θ_e, φ) "
           "| fit / exact |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        w = r["where"]
        out.append(f"| {r['sigma']:g} | {r['region']} | {r['max_rel']:.3g} | {r['mean_rel']:.3g} | "
                   f"{r['max_abs']:.3g} | {r['max_abs_cos']:.3g} | "
                   f"({w['theta_l']:g}°, {w['theta_e']:g}°, {w['phi']:g}°) | {w['fit']:.4g} / {w['exact']:.4g} |")
    return "\n".join(out)
