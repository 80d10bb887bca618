"""Kind contracts as data: what each kind of brick's entries take and return.

An entry's parameters are bound by name. A name is one of
- an argument of the contract (`args`): what the caller passes, positionally, in
  the contract's order (a slot's host, or the glue: `output(color)`);
- a shading input (`reads` = "shading": the inputs table of library/inputs.py) or a
  surface input (`reads` = "surface": P, N, T, B, uv);
- a parameter or texture the brick declares in BRICK.
An optional argument may be left out of an entry; a required one must be declared.
The loader (library/bricks.py) checks entries against these contracts; the linker
(link/) binds them.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..lang.types import FLOAT, VEC2, VEC3, VEC4, Type


@dataclass(frozen=True)
class Arg:
    """A value the caller of an entry passes."""

    name: str
    ty: Type
    required: bool = False  # the entry must declare it


@dataclass(frozen=True)
class Entry:
    name: str
    ret: Type | None  # None: the type of what it provides (a packing's get_<input>)
    args: tuple[Arg, ...] = ()
    optional: bool = False  # a brick of the kind may leave it out (the glue then does without it)
    # a sampling entry (sample, pdf, sample_h, pdf_h): called by the sampler, never by the shading glue; it reads
    # only its arguments and the brick's parameters (no shading input), and is linked only into sampling programs
    sampling: bool = False


@dataclass(frozen=True)
class Kind:
    """One kind of brick.

    entries: the functions the generator calls; a packing's entries are every
      function named `get_<material input>` (prefix_entries), returning that input
      with the type the BRDF gives it (spec/resolve.check_packing).
    reads: "shading" (the inputs table) or "surface" (P, N, T, B, uv).
    slot: a kind that fills a slot of a host brick (called from the host, not the glue).
    """

    name: str
    entries: tuple[Entry, ...]
    reads: str
    slot: bool = False
    prefix_entries: str = ""
    doc: str = ""

    def entry(self, name: str) -> Entry | None:
        for e in self.entries:
            if e.name == name:
                return e
        if self.prefix_entries and name.startswith(self.prefix_entries):
            return Entry(name, None)  # returns the type of the material input it provides (checked when linked)
        return None

    def signature(self, entry: str) -> tuple[tuple[str, Type], ...]:
        """The positional signature a caller of `entry` is type-checked against (its args)."""
        return tuple((a.name, a.ty) for a in self.entry(entry).args)


def _frame(first: str, ty: Type, *more: Arg) -> tuple[Arg, ...]:
    return (Arg(first, ty), Arg("V", VEC3), Arg("N", VEC3), Arg("T", VEC3), Arg("B", VEC3)) + more


# The sampling contract (docs/guide/sampling.md). The caller gives an orthonormal frame: N the shading normal,
# T, B the tangent and bitangent (any orthonormal pair for an isotropic BRDF), V the unit view vector.
# `sample(u, ...)` maps a uniform u in [0, 1)^2 to a unit direction L; `pdf(L, ...)` is the density of L per
# unit solid angle that `sample` draws with. A sampler may return L below the surface (n·l <= 0: a lobe
# clipped by the horizon); the caller scores such a sample 0 (f_r is 0 there), and pdf is 0 there, so pdf
# integrates to 1 minus the mass the sampler loses below the horizon. A BRDF term without a sampler is
# sampled cosine-weighted (link/sampling.py decides it and says so). The NDF slot's `sample_h` / `pdf_h` do the
# same for the half vector H (density per unit solid angle of H); the microfacet host reflects V about H.
SAMPLE = Entry("sample", VEC3, _frame("u", VEC2), optional=True, sampling=True)
PDF = Entry("pdf", FLOAT, _frame("L", VEC3), optional=True, sampling=True)
SAMPLING_ENTRIES = ("sample", "pdf", "sample_h", "pdf_h")

KINDS: dict[str, Kind] = {k.name: k for k in (
    Kind("diffuse", (Entry("diffuse", VEC3), SAMPLE, PDF), "shading", doc="a diffuse BRDF term f_r (1/sr)"),
    Kind("specular", (Entry("specular", VEC3), SAMPLE, PDF), "shading", doc="a specular BRDF term f_r (1/sr)"),
    Kind("ndf", (Entry("ndf", FLOAT, (Arg("NdotH", FLOAT), Arg("NxH2", FLOAT), Arg("alpha", FLOAT))),
                 Entry("sample_h", VEC3, _frame("u", VEC2, Arg("alpha", FLOAT)), optional=True, sampling=True),
                 Entry("pdf_h", FLOAT, _frame("H", VEC3, Arg("alpha", FLOAT)), optional=True, sampling=True)),
         "shading", slot=True, doc="a normal distribution D(h), normalized: ∫ D cosθ_h dω = 1"),
    Kind("fresnel", (Entry("fresnel", VEC3, (Arg("f0", VEC3), Arg("VdotH", FLOAT))),), "shading", slot=True,
         doc="a Fresnel reflectance F"),
    Kind("visibility", (Entry("vis", FLOAT, (Arg("NdotL", FLOAT), Arg("NdotV", FLOAT), Arg("NdotH", FLOAT),
                                             Arg("VdotH", FLOAT), Arg("alpha", FLOAT))),),
         "shading", slot=True, doc="a visibility term V = G / (4 n·l n·v)"),
    Kind("light", (Entry("light_dir", VEC3), Entry("light_radiance", VEC3)), "surface",
         doc="a light: the unit direction to it and c_light, the game intensity"),
    Kind("shadow", (Entry("shadow", FLOAT),), "surface", doc="a shadow filter: visibility of the light in [0, 1]"),
    Kind("packing", (), "surface", prefix_entries="get_", doc="a texture packing: get_<param> supplies a material input"),
    # `tangent` (optional): the shading tangent T' of the perturbed frame, for BRDFs reading the tangent frame;
    # the glue passes the shading normal N' (what `normal` returned) as Np and sets B' = N' × T' (link/glue.py)
    Kind("normal", (Entry("normal", VEC3), Entry("tangent", VEC3, (Arg("Np", VEC3, required=True),), optional=True)),
         "surface", doc="the shading normal (and, optionally, the shading tangent)"),
    # `uv`: `map_uv` gives the texture coordinates every texture of the material is sampled at (KHR_texture_transform);
    # it fills a packing's optional slot `uv`: the glue calls it once, before the packing, and binds what it returns
    # wherever a later entry reads `uv` (link/glue.py uv_transform). An empty slot: the interpolated uv, no call.
    Kind("uv", (Entry("map_uv", VEC2),), "surface",
         doc="the texture coordinates the material's textures are sampled at (an optional slot of a packing)"),
    Kind("output", (Entry("output", VEC4, (Arg("color", VEC3, required=True),)),), "surface",
         doc="the output transform of the outgoing radiance"),
    # `ambient`: the outgoing radiance an environment adds after the lights (image-based lighting). The glue
    # passes the shading normal N, the unit view vector V and, from the BRDF's parameters by name, kd (what the
    # diffuse ambient term multiplies: rho_d (1 - f0) for Gotanda's diffuse, rho_d for Lambert, 0 with no diffuse
    # term: eval/ibl_tables.py DIFFUSE_HOW), f0 and alpha of the microfacet term (link/glue.py ambient). Its
    # textures are the contract's too (ENVIRONMENT_TEXTURES): the scene's environment binds the radiance cube in
    # the light set's group, the renderer the BRDF's AmbientBRDF table in the material's.
    Kind("environment", (Entry("ambient", VEC3, (Arg("N", VEC3, required=True), Arg("V", VEC3, required=True),
                                                 Arg("kd", VEC3), Arg("f0", VEC3), Arg("alpha", FLOAT))),),
         "surface", doc="image-based lighting: the outgoing radiance of an environment, added after the lights"),
)}
# The textures an environment brick declares, by name and dimension: the prefiltered radiance cube (the light
# set's environment: set 0) and the AmbientBRDF table of the material's BRDF (set 1); textures are bound by name.
ENVIRONMENT_TEXTURES = {"radiance": "cube", "ambient_brdf": "2d"}
ENVIRONMENT_GROUP = {"radiance": "light", "ambient_brdf": "material"}
BRDF_KINDS = ("diffuse", "specular")
