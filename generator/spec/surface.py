"""The surface's render state in a permutation key: what of glTF's alphaMode, doubleSided, COLOR_0 and emission
changes the shader, and nothing that does not.

glTF 2.0 specification, 3.9.4 "Alpha Coverage", 3.9.5 "Double Sided", 3.9.3 "Additional Textures" (emissive),
3.7.2.1 (COLOR_0). Four axes, each with a default that is what every permutation had before, so a key at the
defaults writes nothing more and keeps its canonical string and hash (goldens, caches, manifests unchanged):

- `alpha`: "opaque" (default) | "mask" | "blend". Coverage a = base_alpha · (the base colour texture's A,
  when the packing samples one) · (COLOR_0's A, with vertex_color). MASK: shade() returns alpha 1 where
  a ≥ alpha_cutoff and 0 elsewhere, and the fragment main discards alpha 0 (glTF: "either fully opaque or fully
  transparent"; the returned alpha is 1). BLEND: shade() returns a; the renderer blends source-over. OPAQUE
  reads no alpha (the output brick's 1). alpha_cutoff and base_alpha are material uniforms, not key values:
  materials with different cutoffs share one shader.
- `double_sided`: false (default) | true. The fragment main reverses N, T and B on back faces
  (gl_FrontFacing / SV_IsFrontFace / @builtin(front_facing)) before shading: glTF 3.9.5, "the back-face must
  have its normals reversed before the lighting equation is evaluated". The pipeline's cull mode (none vs
  back) is render state, not shader code: runtime/pipeline_state.py render_state states it for the manifest
  and the renderer (back for a single-sided surface, TOML or glTF).
- `vertex_color`: false (default) | true. COLOR_0 (RGBA; a mesh without one reads white) is a vertex input
  and interpolant; rho_d is multiplied by its RGB before the BRDF (glTF: base colour · COLOR_0; exact for
  rho_d = base (1 − metallic); f0 = mix(0.04, base, metallic) of a metal is not tinted) and its A scales
  the coverage.
- `emissive`: "none" (default) | "factor" | "texture". L_o += emissive (· the sRGB emissive_map's RGB with
  "texture") before the output brick: glTF's emissiveFactor · emissiveTexture, in the same units as the
  lights' "game intensity" colour.

The glue reads these (link/glue.py); the values live in the Material block as `m_<name>` (SURFACE_PARAMS).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..lang.types import FLOAT, VEC3
from .params import ParamSpec

ALPHA_MODES = ("opaque", "mask", "blend")
EMISSIVE = ("none", "factor", "texture")
EMISSIVE_MAP = "emissive_map"  # the material texture of emissive = "texture" (sRGB, as glTF's emissiveTexture)
_WHERE = ("generator/spec/surface.py",)
# The glue's material parameters, per axis value that reads them. Ranges: alpha and cutoff as glTF (a cutoff
# above 1 culls every fragment, which glTF allows; 1e4 is a bound a uniform never needs to exceed), emission
# as the light colours' "game intensity" (KHR_materials_emissive_strength multiplies it past 1).
SURFACE_PARAMS = {
    "base_alpha": ParamSpec("base_alpha", FLOAT, 1.0, (0.0, 1.0), "coverage: glTF baseColorFactor[3]", _WHERE),
    "alpha_cutoff": ParamSpec("alpha_cutoff", FLOAT, 0.5, (0.0, 1.0e4), "MASK: kept where coverage ≥ this "
                              "(glTF alphaCutoff)", _WHERE),
    "emissive": ParamSpec("emissive", VEC3, [1.0, 1.0, 1.0], (0.0, 1.0e6), "emitted radiance added to the lit "
                          "colour (glTF emissiveFactor · KHR_materials_emissive_strength)", _WHERE),
}


@dataclass(frozen=True)
class Surface:
    """The render state of a permutation that changes its shader (module docstring); the defaults change nothing."""

    alpha: str = "opaque"
    double_sided: bool = False
    vertex_color: bool = False
    emissive: str = "none"

    def __post_init__(self):
        assert self.alpha in ALPHA_MODES and self.emissive in EMISSIVE, self

    def canonical(self) -> str:
        """The key's suffix: each axis away from its default, `;name=value`, in this order ('' at the defaults)."""
        parts = []
        if self.alpha != "opaque":
            parts.append(f"alpha={self.alpha}")
        if self.double_sided:
            parts.append("double_sided=true")
        if self.vertex_color:
            parts.append("vertex_color=true")
        if self.emissive != "none":
            parts.append(f"emissive={self.emissive}")
        return "".join(f";{p}" for p in parts)

    def params(self) -> dict[str, ParamSpec]:
        """The glue's material parameters this state reads, in layout order."""
        names = (["base_alpha"] if self.alpha != "opaque" else []) + (["alpha_cutoff"] if self.alpha == "mask" else []) \
            + (["emissive"] if self.emissive != "none" else [])
        return {n: SURFACE_PARAMS[n] for n in names}


DEFAULT = Surface()
