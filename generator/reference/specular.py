"""Float64 references of the classic specular bricks, written from the papers.

Phong (original and its plausibility steps), Blinn-Phong with R_F(alpha_h), Banks, Ward
(isotropic, anisotropic), Ashikhmin-Shirley, Lafortune, Cook-Torrance. Each function cites
the paper and equation it computes; where a model is printed in two formulations, both are
here (the registered one and an alternative that tests/library/test_library_specular.py checks against
it), computed from angles where the paper uses angles. Brick guards are not reproduced
(models.py). Imported by models.py, which registers them.
"""
from __future__ import annotations

import numpy as np

from . import exact
from .geometry import Geometry
from .models import _rgb, reference


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


# ------------------------------------------------------------------ Phong (Hoffman & Baker 2006)

@reference("specular", "phong")
def phong(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = k_s (cos α_r)^n / (π cos θ_i) (Hoffman & Baker 2006, "Phong - Written as a BRDF")."""
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(g.NdotL > 0.0, g.RdotV ** p["n"] / (np.pi * g.NdotL), 0.0)
    return p["k_s"] * _rgb(s)


@reference("specular", "phong_reciprocal")
def phong_reciprocal(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = (k_s / π) (cos α_r)^n (Hoffman & Baker 2006, first plausibility step: the cosine factor removed)."""
    return p["k_s"] * _rgb(g.RdotV ** p["n"] / np.pi)


def phong_albedo_outgoing(n: float, k_s: float = 1.0, cos_i: float = 1.0) -> float:
    """R_s(θ_i) of `phong_reciprocal` at normal incidence, closed form 2 k_s / (n + 2) (the course)."""
    assert cos_i == 1.0
    return 2.0 * k_s / (n + 2.0)


# ------------------------------------------------------------------ Blinn-Phong with R_F(α_h)

@reference("specular", "blinn_phong_normalized_fresnel")
def blinn_phong_normalized_fresnel(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = (n+4)/(8π) R_F(α_h) cos^n θ_h, R_F Schlick's on l·h (Hoffman & Baker 2006; Schlick 1994 eq. 15)."""
    n = p["n"]
    return exact.fresnel_schlick(p["f0"], g.LdotH) * _rgb((n + 4.0) / (8.0 * np.pi)
                                                           * exact.cos_power(g.NdotH, g.NxH2, n))


# ------------------------------------------------------------------ Banks 1994

def banks_kernel(L, V, T) -> np.ndarray:
    """max over the fiber's normals n' ⊥ t of v·r(n'), r(n') = 2(n'·l)n' - l the mirror of l (Banks 1994).

    The mirror directions of l about every normal of a thread form the cone r·t = -(l·t); the one
    nearest v is r* = -(l·t) t + sqrt(1 - (l·t)²) v⊥/|v⊥|, v⊥ = v - (v·t) t. Built from the vectors,
    not from the closed form sqrt(1-(l·t)²) sqrt(1-(v·t)²) - (l·t)(v·t) (ACCURACY-FACTS §4.10;
    Heidrich & Seidel 1998) that the brick uses. v ∥ t: every r of the cone gives -(l·t)(v·t).
    """
    lt, vt = _dot(L, T), _dot(V, T)
    P = V - vt[:, None] * T
    pl = np.sqrt(_dot(P, P))
    Vp = np.where(pl[:, None] > 0.0, P / np.where(pl > 0.0, pl, 1.0)[:, None], 0.0)
    R = -lt[:, None] * T + np.sqrt(np.maximum(1.0 - lt * lt, 0.0))[:, None] * Vp
    return _dot(V, R)


@reference("specular", "banks")
def banks(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = (k_s/π) max(0, v·r')^n for n·l > 0, else 0 (Banks 1994 with the course's cosine step), with
    v·r' = sqrt(1-(l·t)²) sqrt(1-(v·t)²) - (l·t)(v·t) (Heidrich & Seidel 1998; ACCURACY-FACTS §4.10):
    symmetric in l and v to the last bit, which the construction of banks_kernel() (checked against it
    by tests/library/test_library_specular.py) is not."""
    lt, vt = g["LdotT"], g["VdotT"]
    # sin = sqrt(1 - cos²) of the unit vectors; inputs rounded to float32 are unit only to rounding
    sl, sv = np.sqrt(np.maximum(1.0 - lt * lt, 0.0)), np.sqrt(np.maximum(1.0 - vt * vt, 0.0))
    k = np.clip(sl * sv - lt * vt, 0.0, None)
    return p["k_s"] * _rgb(np.where(g.lit, k ** p["n"] / np.pi, 0.0))


# ------------------------------------------------------------------ Ward 1992

def _tan2_h(g: Geometry) -> np.ndarray:
    """tan²θ_h = sin²θ_h / cos²θ_h, +inf at n·h = 0 (and for the undefined h of l = -v)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(g.NdotH > 0.0, g.NxH2 / (g.NdotH * g.NdotH), np.inf)


def _ward(g: Geometry, f0, exponent, m_u, m_v, dirac) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.exp(-exponent) / (4.0 * np.pi * m_u * m_v * g.NdotL * g.NdotV)
        s = np.where(np.isinf(exponent), 0.0, s)
        s = np.where((m_u > 0.0) & (m_v > 0.0), s, dirac)
        f = f0 * _rgb(s)
    return np.where(f0 == 0.0, 0.0, f)  # zero albedo times a Dirac peak is no reflection


@reference("specular", "ward_isotropic")
def ward_isotropic(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = R_F(0) exp(-tan²θ_h/m²) / (4π m² cos θ_i cos θ_e) (Hoffman & Baker 2006, "Ward - Isotropic";
    Ward 1992 eq. 4 with the 1/(cos θ_i cos θ_e) normalization the course prints). m = 0: a Dirac peak."""
    m = np.asarray(p["m"], np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        ex = _tan2_h(g) / (m * m)
    return _ward(g, p["f0"], ex, m, m, exact._delta(g.NdotH, g.NxH2))


def _phi_h(g: Geometry) -> np.ndarray:
    """Azimuth φ_h of h in the tangent frame (t, b), atan2(h·b, h·t); 0 where h ∥ n (undefined)."""
    return np.arctan2(g["HdotB"], g["HdotT"])


@reference("specular", "ward_anisotropic")
def ward_anisotropic(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = R_F(0) exp(-tan²θ_h (cos²φ_h/m_u² + sin²φ_h/m_v²)) / (4π m_u m_v cos θ_i cos θ_e)
    (Ward 1992 eq. 5a; Hoffman & Baker 2006's first anisotropic formulation, with the minus sign
    and the squares of m_u, m_v that the seed text lost). From the angles θ_h, φ_h."""
    mu, mv = np.asarray(p["m_u"], np.float64), np.asarray(p["m_v"], np.float64)
    phi = _phi_h(g)
    with np.errstate(divide="ignore", invalid="ignore"):
        ex = _tan2_h(g) * (np.cos(phi) ** 2 / (mu * mu) + np.sin(phi) ** 2 / (mv * mv))
    return _ward(g, p["f0"], ex, mu, mv, exact._delta(g.NdotH, g.NxH2))


def ward_anisotropic_dot_form(g: Geometry, p: dict) -> np.ndarray:
    """The course's second formulation: exp(-((cos α_u/m_u)² + (cos α_v/m_v)²)/cos²θ_h), cos α_u = h·t,
    cos α_v = h·b (Hoffman & Baker 2006, "more implementation-friendly"; minus sign restored)."""
    mu, mv = np.asarray(p["m_u"], np.float64), np.asarray(p["m_v"], np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        ex = np.where(g.NdotH > 0.0, ((g["HdotT"] / mu) ** 2 + (g["HdotB"] / mv) ** 2) / g.NdotH ** 2, np.inf)
    return _ward(g, p["f0"], ex, mu, mv, 0.0)


# ------------------------------------------------------------------ Ashikhmin-Shirley 2000

def _ashikhmin_shirley(g: Geometry, p: dict, e) -> np.ndarray:
    nu, nv = p["n_u"], p["n_v"]
    kh = g.LdotH
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (np.sqrt((nu + 1.0) * (nv + 1.0)) / (8.0 * np.pi) * exact.cos_power(g.NdotH, g.NxH2, e)
             / (kh * np.maximum(g.NdotL, g.NdotV)))
    s = np.where(kh > 0.0, s, 0.0)  # h undefined (l = -v): n·h = 0, no reflection
    return exact.fresnel_schlick(p["f0"], kh) * _rgb(s)


@reference("specular", "ashikhmin_shirley")
def ashikhmin_shirley(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = sqrt((n_u+1)(n_v+1))/(8π) (n·h)^(n_u cos²φ_h + n_v sin²φ_h) / ((k·h) max(n·l, n·v)) F(k·h)
    (Ashikhmin & Shirley 2000 eq. 4, Schlick's F eq. 5; Hoffman & Baker 2006's first formulation)."""
    phi = _phi_h(g)
    return _ashikhmin_shirley(g, p, p["n_u"] * np.cos(phi) ** 2 + p["n_v"] * np.sin(phi) ** 2)


def ashikhmin_shirley_dot_form(g: Geometry, p: dict, seed_typo: bool = False) -> np.ndarray:
    """The dot-product formulation, exponent (n_u (h·t)² + n_v (h·b)²)/(1 - (n·h)²) (Ashikhmin & Shirley
    2000 eq. 4). seed_typo: the denominator 1 + cos²θ_h as the seed text of the course prints it."""
    tu, tv = g["HdotT"] ** 2, g["HdotB"] ** 2
    den = 1.0 + g.NdotH ** 2 if seed_typo else g.NxH2
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.where(den > 0.0, (p["n_u"] * tu + p["n_v"] * tv) / den, p["n_u"])
    return _ashikhmin_shirley(g, p, e)


def ashikhmin_shirley_ndf(cos_h, phi_h, n_u, n_v) -> np.ndarray:
    """The density of h behind the specular term, sqrt((n_u+1)(n_v+1))/(2π) (n·h)^(n_u cos²φ + n_v sin²φ)
    (Ashikhmin & Shirley 2000): ∫ D dω_h = 1 over the solid angle of h (not against cos θ_h as
    ACCURACY-FACTS §4.9 has it); the specular term is D F / (4 (k·h) max(n·l, n·v))."""
    e = n_u * np.cos(phi_h) ** 2 + n_v * np.sin(phi_h) ** 2
    return np.sqrt((n_u + 1.0) * (n_v + 1.0)) / (2.0 * np.pi) * cos_h ** e


# ------------------------------------------------------------------ factored forms (Hoffman & Baker 2006, "BRDF Costs")
# The model each factored brick approximates with its baked tables (tables_specular.py) is the direct
# model, exactly: the tables' error is what accuracy measures against these.

@reference("specular", "blinn_phong_factored")
def blinn_phong_factored(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """The normalized Blinn-Phong of `blinn_phong_normalized`, (n+4)/(8π) R_F(0) cos^n θ_h (Hoffman & Baker 2006)."""
    from .models import blinn_phong_normalized
    return blinn_phong_normalized(g, p, slots)


@reference("specular", "banks_factored")
def banks_factored(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Banks 1994 as `banks`: (k_s/π) max(0, v·r')^n for n·l > 0."""
    return banks(g, p, slots)


@reference("specular", "ashikhmin_shirley_factored")
def ashikhmin_shirley_factored(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Ashikhmin & Shirley 2000 eq. 4 with Schlick's F, as `ashikhmin_shirley`."""
    return ashikhmin_shirley(g, p, slots)


@reference("diffuse", "ashikhmin_shirley_diffuse_factored")
def ashikhmin_shirley_diffuse_factored(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """Ashikhmin & Shirley 2000 eq. 5, as `ashikhmin_shirley_diffuse` (the diffuse half of the course's
    "Ashikhmin/Shirley factored" row; registered here beside its specular half)."""
    from .diffuse import ashikhmin_shirley_diffuse
    return ashikhmin_shirley_diffuse(g, p, slots)


# ------------------------------------------------------------------ Lafortune 1997

@reference("specular", "lafortune")
def lafortune(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = Σ_j K_j max(0, C_x,j l_x v_x + C_y,j l_y v_y + C_z,j l_z v_z)^n_j, (x, y, z) the frame (t, b, n)
    (Lafortune et al. 1997 eq. 4; Hoffman & Baker 2006). 0^0 = 1 (the n = 0 Lambertian lobe)."""
    lobes = np.asarray(p["lobes"], np.float64)
    K = np.asarray(p["K"], np.float64)
    count = int(p.get("lobes_count", len(lobes)))
    L, V, T, B = g.L, g.V, g.T, g["B"]
    lx, ly, vx, vy = _dot(L, T), _dot(L, B), _dot(V, T), _dot(V, B)
    lz, vz = g.NdotL, g.NdotV  # n·l as the policy passes it, n·v clamped to [1e-4, 1]
    f = np.zeros((g.count, 3))
    for j in range(count):
        cx, cy, cz, n = lobes[j]
        d = cx * lx * vx + cy * ly * vy + cz * lz * vz
        with np.errstate(invalid="ignore"):
            t = np.where(d > 0.0, np.maximum(d, 0.0) ** n, 1.0 if n == 0.0 else 0.0)
        f = f + t[:, None] * K[j]
    return f


# ------------------------------------------------------------------ Cook-Torrance 1982

@reference("specular", "cook_torrance")
def cook_torrance(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """f = (1 - s) ρ_d/π + s F D G / (4 (n·l)(n·v)) (Cook & Torrance 1982 with s + d = 1, as Hoffman & Baker
    2006 print it; the specular term with the 4 of Walter et al. 2007 eq. 20 / RTR3 eq. 7.51 for a
    normalized D, where the course and the paper write π over Cook & Torrance's D without 1/π)."""
    a, s = p["alpha"], np.asarray(p["s"], np.float64)
    D = slots["ndf"](g.NdotH, g.NxH2, a)
    G = slots["vis"](g, a)
    F = slots["fresnel"](p["f0"], g.VdotH)
    with np.errstate(divide="ignore", invalid="ignore"):
        spec = F * _rgb(D * G / (4.0 * g.NdotL * g.NdotV))
    spec = np.where((F == 0.0) | (G == 0.0)[:, None], 0.0, spec)
    with np.errstate(invalid="ignore"):
        spec = np.where(_rgb(s) > 0.0, _rgb(s) * spec, 0.0)  # s = 0: no specular, even at a Dirac peak
    return _rgb(1.0 - s) * p["rho_d"] / np.pi + spec


# ------------------------------------------------------------------ homomorphic factorization (McCool et al. 2001)

# The BRDF the factored brick approximates: Ashikhmin-Shirley (the course's anisotropic model) at fixed
# parameters, a copper-like Schlick f0 (a coloured Fresnel, so the factors are RGB).
HOMOMORPHIC_TARGET = {"n_u": 4.0, "n_v": 16.0, "f0": np.array([0.95, 0.64, 0.54])}


@reference("specular", "homomorphic_factorization")
def homomorphic_factorization(g: Geometry, p: dict, slots: dict) -> np.ndarray:
    """The BRDF that the cube maps P, Q of `homomorphic_factorization` factor (tables_homomorphic.py):
    Ashikhmin & Shirley 2000 eq. 4 with Schlick's F at HOMOMORPHIC_TARGET (the brick's accuracy is the
    factorization's error against it)."""
    t = HOMOMORPHIC_TARGET
    return ashikhmin_shirley(g, {**t, "f0": np.broadcast_to(t["f0"], (g.count, 3))}, slots)


# ------------------------------------------------------------------ hand-painted BRDFs

from .tables_painted import register_references as _painted_references  # noqa: E402

_painted_references()
