"""What image-based lighting does with each term of a BRDF: the spec stage's verdict, read by the glue (an
environment's ambient term), the scene loader (a located refusal naming the material) and the bakers
(eval/ibl_tables.py, which re-exports these names).

The microfacet terms with an isotropic NDF get the AmbientBRDF (scale and bias of f0; whether their Fresnel is
affine in f0 is checked when the table is baked), Lambert and Gotanda's diffuse get the table's B channel
(DIFFUSE_HOW); every other term is refused with the reason (docs/design/ibl.md, "Which brick gets what").
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Term:
    """One term of a BRDF spec as IBL sees it: its spec, brick, and how its ambient term is computed."""

    spec: str
    kind: str  # "diffuse" | "specular"
    brick: str
    how: str  # "ambient_brdf" | "gotanda_eq4" | "lambert" | "refused"
    why: str = ""
    fillers: dict = field(default_factory=dict)


# how a diffuse brick's ambient term is computed, and what the glue passes as kd (link/glue.py ambient)
DIFFUSE_HOW = {"lambert": ("lambert", "exact: ρ/π × irradiance (B = 1)"),
               "gotanda_fitted": ("gotanda_eq4", "B channel: eq. 4 integrated numerically (not the eq. 8 fit)")}


def classify_nodes(nodes) -> list[Term]:
    """classify() of a resolved BRDF's term nodes (diffuse first)."""
    out = []
    for node in nodes:
        b = node.brick
        fillers = {slot: f.brick.id for slot, f in node.fillers}
        own = {slot: set(f.brick.params or {}) for slot, f in node.fillers}
        ndf_params, fresnel_params = own.get("ndf", set()), own.get("fresnel", set()) - {"f0"}
        if b.kind == "diffuse":
            how, why = DIFFUSE_HOW.get(b.id, ("refused", f"diffuse brick '{b.id}' has no ambient table: use "
                                             "lambert or gotanda_fitted for image-based lighting"))
        elif b.id == "microfacet":
            aniso = bool(ndf_params & {"alpha_u", "alpha_v"})
            how, why = (("refused", f"NDF '{fillers['ndf']}' is anisotropic: a table over (n·v, α) holds isotropic "
                         "lobes only — use its isotropic form") if aniso else ("ambient_brdf", ""))
            if fresnel_params and not aniso:
                # a table baked at the brick's default eta, k would be silently wrong for every other metal
                how, why = "refused", (f"Fresnel '{fillers['fresnel']}' reads {', '.join(sorted(fresnel_params))}, "
                                       "which a table over (n·v, α) with f0 as scale and bias cannot hold — use "
                                       "fresnel=schlick (f0 from the metal's reflectance) for image-based lighting")
        else:
            how, why = "refused", (f"specular brick '{b.id}' is not a microfacet term: the split sum's prefiltered "
                                   "cube assumes a microfacet lobe — use microfacet(...)")
        out.append(Term(node.key, b.kind, b.id, how, why, fillers))
    return out


def classify(spec: str, lib=None) -> list[Term]:
    """How IBL treats each term of `spec` (no baking): see the module docstring."""
    from ..library.bricks import library_or_builtin
    from .resolve import resolve_brdf
    return classify_nodes(resolve_brdf(spec, library_or_builtin(lib)).nodes)


def ambient_problem(nodes, params) -> tuple[str, str]:
    """('', '') when an environment can light a BRDF of these term nodes and parameters, else (what is wrong,
    what to do): a refused term, no microfacet specular term (the table's scale and bias belong to one), or no
    `alpha` and `f0` parameters for the glue to bind by name."""
    terms = classify_nodes(nodes)
    refused = [t for t in terms if t.how == "refused"]
    if refused:
        return (f"image-based lighting cannot light brdf term '{refused[0].spec}': {refused[0].why}",
                "light this material without an environment, or change its brdf")
    if not any(t.kind == "specular" for t in terms):
        return ("image-based lighting needs a microfacet specular term (the AmbientBRDF's scale and bias of f0 "
                "belong to one), and this brdf has none", "add one, e.g. lambert+microfacet(ndf=ggx,fresnel=schlick)")
    missing = [p for p in ("alpha", "f0") if p not in params]
    if missing:
        return (f"image-based lighting reads the BRDF's '{missing[0]}' (the split sum's lod and table row are √α, "
                f"its scale and bias multiply f0), and this brdf has no parameter '{missing[0]}'",
                "use an NDF with an alpha parameter (ggx, beckmann) and a Fresnel reading f0 (schlick)")
    return "", ""
