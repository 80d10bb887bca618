"""THE table of shading inputs: what a BRDF term or slot filler may name as a parameter.

One row per quantity: its name, type, the brick-language expression the glue
computes it with (over the rows it depends on), the float64 formula the
references use, the guard the policy applies and why. The glue (link/), the
float64 reference geometry (reference/geometry.py), the cost stand-ins and the
stress sweeps all read this table; nothing else lists shading inputs.

The policy (docs/design/accuracy.md, "Shading conventions"): f_r is 0 for n·l <= 0; n·v is
clamped to [1e-4, 1] so a view below the horizon after normal mapping shades as
grazing; cosines with h are clamped to [0, 1] before any pow; an undefined half
vector (l = -v) is the zero vector. Tangent-frame quantities are signed and
unclamped: anisotropic models square them (Ward 1992 eq. 5a; Ashikhmin & Shirley
2000 eq. 4) or read their sign (Banks 1994).

The frame inputs L, V, N (and T, B when a brick reads the tangent frame) are given
by the caller: the eval kernel reads them from its samples, the fragment shader
from interpolants and the light loop.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass
from typing import Callable

from ..lang import ir
from ..lang.errors import SourceError
from ..lang.typecheck import Checker
from ..lang.types import FLOAT, VEC2, VEC3, Type

NV_MIN = 1e-4  # the n·v clamp of the policy (Filament's clampNoV)


class _Numpy:
    """NumPy, imported on first use: the shader targets and the CLI parser do not need it."""

    def __getattr__(self, name):
        import numpy
        return getattr(numpy, name)


np = _Numpy()


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def _half(g):
    s = g["L"] + g["V"]
    s2 = _dot(s, s)
    ok = s2 > 0.0
    return np.where(ok[:, None], s / np.sqrt(np.where(ok, s2, 1.0))[:, None], 0.0)


def _sin2_h(g):
    # sin²θ_h in its well-conditioned form: |n × h|² near h = n, (1 - c)(1 + c) elsewhere.
    nh = _dot(g["N"], g["H"])
    c = np.cross(g["N"], g["H"])
    s2 = np.where(nh * nh > 0.5, _dot(c, c), (1.0 - nh) * (1.0 + nh))
    return np.minimum(np.where(_dot(g["H"], g["H"]) > 0.0, np.where(nh > 0.0, s2, 1.0), 1.0), 1.0)


@dataclass(frozen=True)
class ShadingInput:
    """One row of the table.

    expr: brick-language expression over `deps` (None for the frame inputs the caller gives).
    formula: float64 NumPy formula over a dict of the rows computed so far (arrays (N,) or (N, 3)).
    tangent: needs the tangent frame (T, B): a permutation without tangents cannot supply it.
    internal: an intermediate of the glue, not readable by bricks.
    """

    name: str
    ty: Type
    expr: str | None
    deps: tuple[str, ...]
    formula: Callable
    guard: str
    why: str
    tangent: bool = False
    internal: bool = False


I = ShadingInput
INPUTS: tuple[ShadingInput, ...] = (
    I("L", VEC3, None, (), lambda g: g["L"], "none", "unit vector to the light, given"),
    I("V", VEC3, None, (), lambda g: g["V"], "none", "unit vector to the eye, given"),
    I("N", VEC3, None, (), lambda g: g["N"], "none", "unit shading normal, given"),
    I("T", VEC3, None, (), lambda g: g["T"], "none", "unit tangent, given", tangent=True),
    I("B", VEC3, None, (), lambda g: g["B"], "none", "bitangent B = N × T (eval) or from the tangent's sign (mesh)",
      tangent=True),
    I("NdotL", FLOAT, "min(dot(N, L), 1.0)", (), lambda g: np.minimum(_dot(g["N"], g["L"]), 1.0), "≤ 1",
      "rounding of unit vectors must not push a cosine past 1; n·l ≤ 0 never reaches a term"),
    I("NdotV", FLOAT, "clamp(dot(N, V), 0.0001, 1.0)", (),
      lambda g: np.clip(_dot(g["N"], g["V"]), NV_MIN, 1.0), "[1e-4, 1]",
      "a view below the horizon after normal mapping shades as grazing, not black or NaN (Filament's clampNoV)"),
    I("Hsum", VEC3, "L + V", (), lambda g: g["L"] + g["V"], "none", "l + v before normalization", internal=True),
    I("H", VEC3, "Hsum * rsqrt(max(dot(Hsum, Hsum), 1e-30))", ("Hsum",), _half, "|l+v|² ≥ 1e-30",
      "l = -v gives h = 0, not NaN; the floor is far below the grazing mirror configuration |l+v|² = 4cos²θ"),
    I("NdotH", FLOAT, "clamp(dot(N, H), 0.0, 1.0)", ("H",), lambda g: np.clip(_dot(g["N"], g["H"]), 0.0, 1.0),
      "[0, 1]", "pow of a negative base is undefined"),
    I("NxH", VEC3, "cross(N, H)", ("H",), lambda g: np.cross(g["N"], g["H"]), "none", "n × h", internal=True),
    I("NxH2", FLOAT, "dot(NxH, NxH) if NdotH > 0.0 else 1.0", ("NxH", "NdotH"), _sin2_h, "1 where n·h ≤ 0",
      "sin²θ_h = |n × h|² keeps its digits as h → n, where 1 - (n·h)² is all rounding in float32 "
      "(ACCURACY-FACTS pitfall 4)"),
    I("LdotH", FLOAT, "clamp(dot(L, H), 0.0, 1.0)", ("H",), lambda g: np.clip(_dot(g["L"], g["H"]), 0.0, 1.0),
      "[0, 1]", "a Fresnel or Smith term of a negative cosine is undefined"),
    I("VdotH", FLOAT, "clamp(dot(V, H), 0.0, 1.0)", ("H",), lambda g: np.clip(_dot(g["V"], g["H"]), 0.0, 1.0),
      "[0, 1]", "as LdotH (equal to it for a unit h)"),
    I("LdotV", FLOAT, "dot(L, V)", (), lambda g: _dot(g["L"], g["V"]), "none", "signed: retro-reflection reads it"),
    I("RdotV", FLOAT, "clamp(dot(reflect(-L, N), V), 0.0, 1.0)", (),
      lambda g: np.clip(_dot(2.0 * _dot(g["N"], g["L"])[:, None] * g["N"] - g["L"], g["V"]), 0.0, 1.0),
      "[0, 1]", "Phong's pow of a negative cosine is undefined"),
    I("HdotT", FLOAT, "dot(H, T)", ("H",), lambda g: _dot(g["H"], g["T"]), "none",
      "signed; squared by anisotropic NDFs (Ward eq. 5a, Ashikhmin-Shirley eq. 4)", tangent=True),
    I("HdotB", FLOAT, "dot(H, B)", ("H",), lambda g: _dot(g["H"], g["B"]), "none", "as HdotT", tangent=True),
    I("LdotT", FLOAT, "dot(L, T)", (), lambda g: _dot(g["L"], g["T"]), "none", "signed; Banks 1994 reads it",
      tangent=True),
    I("VdotT", FLOAT, "dot(V, T)", (), lambda g: _dot(g["V"], g["T"]), "none", "as LdotT", tangent=True),
    I("LdotB", FLOAT, "dot(L, B)", (), lambda g: _dot(g["L"], g["B"]), "none", "signed", tangent=True),
    I("VdotB", FLOAT, "dot(V, B)", (), lambda g: _dot(g["V"], g["B"]), "none", "signed", tangent=True),
)
del I

BY_NAME: dict[str, ShadingInput] = {i.name: i for i in INPUTS}
FRAME = ("L", "V", "N")
TANGENT_FRAME = ("T", "B")
# What a BRDF term or slot filler may name: every row that is not an intermediate of the glue.
SHADING: dict[str, Type] = {i.name: i.ty for i in INPUTS if not i.internal}


@dataclass(frozen=True)
class SurfaceInput:
    """A shading-context input of light, shadow, packing and normal bricks, and where it comes from."""

    name: str
    ty: Type
    interpolant: str  # the vertex→fragment interpolant that carries it ("" = computed in the fragment)
    why: str


SURFACE_INPUTS: tuple[SurfaceInput, ...] = (
    SurfaceInput("P", VEC3, "v_position", "world-space position"),
    SurfaceInput("N", VEC3, "v_normal", "the interpolated vertex normal (normalized)"),
    SurfaceInput("T", VEC3, "v_tangent", "tangent, xyz of the vertex tangent (w: the bitangent's sign)"),
    SurfaceInput("B", VEC3, "v_tangent", "bitangent cross(N, T) · w"),
    SurfaceInput("uv", VEC2, "v_uv", "texture coordinates"),
)
SURFACE: dict[str, Type] = {s.name: s.ty for s in SURFACE_INPUTS}


def closure(names) -> list[str]:
    """The rows needed to compute `names`, dependencies included, in table order (frame rows left out)."""
    needed = set(names)
    for row in reversed(INPUTS):
        if row.name in needed:
            needed.update(row.deps)
    return [r.name for r in INPUTS if r.name in needed and r.expr is not None]


_PATH = "<inputs>"
_PARSED: dict[str, ir.Expr] = {}


def expression(name: str) -> ir.Expr:
    """The typed IR of row `name`'s expression (parsed once from the table; callers copy it)."""
    if name not in _PARSED:
        row = BY_NAME[name]
        checker = Checker(_PATH, {}, {}, {}, set())
        scope = {d: (BY_NAME[d].ty, "local") for d in row.deps}
        scope.update({f: (BY_NAME[f].ty, "param") for f in FRAME + TANGENT_FRAME})
        checker.scopes = [scope]
        node = ast.parse(row.expr, mode="eval").body
        e = checker.expr(node)
        if e.ty != row.ty:
            raise SourceError(_PATH, 1, 1, f"shading input {name} computes {e.ty}, declared {row.ty}",
                              "fix generator/library/inputs.py")
        _PARSED[name] = e
    return _PARSED[name]


def float64_geometry(L, V, N, T=None, B=None, names=None) -> dict[str, np.ndarray]:
    """Every row (or `names` and their dependencies) in float64 from its formula."""
    g = {"L": L, "V": V, "N": N}
    if T is not None:
        g["T"] = T
        g["B"] = B if B is not None else np.cross(N, T)
    rows = INPUTS if names is None else [BY_NAME[n] for n in closure(names)]
    for row in rows:
        if row.name in g:
            continue
        if row.tangent and "T" not in g:
            continue
        g[row.name] = row.formula(g)
    return g
