"""glTF materials → the scene's materials: each one's BRDF, packing, parameters and surface state.

Every metallic-roughness material (and the glTF default material, for primitives without one) has the
BRDF `lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)`. Its packing follows
the textures present (each changes the shader, so each changes the key):
  - no baseColorTexture and no metallicRoughnessTexture → `constants`, with the converted values
    rho_d = base·(1−metallic), f0 = mix(0.04, base, metallic), alpha = roughness² (glTF Appendix B);
  - baseColorTexture only and metallicFactor 0 → `albedo_texture` (rho_d = baseColorFactor, scaled by
    the texture; f0 = 0.04; alpha = roughness²): exact for a dielectric, one texture sample;
  - otherwise → `gltf_metallic_roughness` (base_color_map + orm_map; base_color, metallic, roughness =
    the factors); a texture the material lacks is bound to a 1×1 white texture (glTF's own meaning of
    an absent texture: the factor alone), recorded as "white" in GltfMaterial.textures.
  - normalTexture → the packing's normal slot `normal_map`, else `vertex`. normalTexture.scale ≠ 1 is
    not applied (normal_map has no scale): a note.
  - occlusionTexture is not read (it scales indirect light; the light loop has direct lights only): a
    note, and it does not change the key.
  - the surface state (spec/surface.py) is part of the key where it changes the shader: alphaMode →
    alpha opaque | mask | blend (base_alpha = baseColorFactor[3] and alpha_cutoff are material uniforms,
    so other cutoffs share the shader); doubleSided → double_sided (the back-face flip; the renderer culls
    back faces otherwise); emissiveFactor · KHR_materials_emissive_strength ≠ 0 → emissive "factor", with
    an emissiveTexture "texture" (emissive_map); an emissiveTexture under a zero factor is not sampled (a
    note). A primitive with COLOR_0 draws with vertex_color: its material is mapped a second time, as
    `<name>+COLOR_0`, since the shader differs. alphaMode, alphaCutoff and doubleSided stay recorded on
    GltfMaterial and on every object too.
  - KHR_texture_transform → the packing's optional slot `uv=texture_transform` (uv_offset, uv_scale,
    uv_rotation = offset, scale, rotation), one transform for all the textures the material samples; an
    identity transform or none leaves the key as without it; textures with different transforms are an
    error (scene/texture_transform.py).
  - a texCoord ≠ 0 (the textureInfo's, or the KHR_texture_transform one that overrides it) is an error (the
    bricks read one UV set, TEXCOORD_0).
  - every material is mapped and checked, used or not (as a TOML scene's materials); only the ones
    objects use make permutations. Each texture a material binds gets its image and sampler read from the
    file (scene/gltf_images.py): a missing, unreadable or corrupt image is an error at /images/N.
A bad value is an error at its own pointer; a packing the bricks cannot resolve, or a parameter its brick
refuses, at the material's (`/materials/N`; glTF's default material: `/materials (default material)`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..lang import SourceError
from ..library.bricks import Library
from ..spec.permutation import Permutation, SpecError, canonical, parse_brdf, parse_spec
from ..spec.resolve import check_packing, resolve
from ..spec.surface import EMISSIVE_MAP, Surface
from . import texture_transform
from .gltf_names import free_name, unique_names
from .gltf_read import Reader
from .jsonpos import pointer
from .load import Material, Scene, surface_specs

BRDF = "lambert+microfacet(ndf=ggx,fresnel=schlick,vis=smith_ggx_height_correlated)"


@dataclass
class GltfMaterial(Material):
    """A Material with glTF's own alpha, sidedness and texture bindings (see the module docstring)."""

    alpha_mode: str = "OPAQUE"
    alpha_cutoff: float = 0.5
    double_sided: bool = False
    base_alpha: float = 1.0
    textures: dict = field(default_factory=dict)  # slot texture name -> {"texture": i, "image": j} or "white"
    source: str = ""  # the JSON pointer it came from


def textures_need_uv(m: GltfMaterial) -> bool:
    return any(v != "white" for v in m.textures.values())


@dataclass
class _Factors:
    """A glTF material's values as the mapping reads them: factors, textureInfos (None: absent), state."""

    pbr: dict  # pbrMetallicRoughness ({} without one)
    pptr: str  # its pointer
    base: list
    metallic: float
    roughness: float
    tex_base: dict | None
    tex_mr: dict | None
    tex_n: dict | None
    tex_o: dict | None
    tex_e: dict | None
    emissive: list
    strength: float
    alpha_mode: str
    cutoff: float
    double: bool


def _factors(rd: Reader, m: dict, ptr: str) -> _Factors:
    pbr = rd.get(m, "pbrMetallicRoughness", ptr, "obj", {})
    pptr = f"{ptr}/pbrMetallicRoughness"
    base = rd.nums(pbr, "baseColorFactor", pptr, 4, [1.0, 1.0, 1.0, 1.0], 0.0, 1.0)
    metallic = rd.num(pbr, "metallicFactor", pptr, 1.0, 0.0, 1.0)
    roughness = rd.num(pbr, "roughnessFactor", pptr, 1.0, 0.0, 1.0)
    tex_base = _texture_info(rd, pbr, "baseColorTexture", pptr)
    tex_mr = _texture_info(rd, pbr, "metallicRoughnessTexture", pptr)
    tex_n = _texture_info(rd, m, "normalTexture", ptr)
    tex_o = _texture_info(rd, m, "occlusionTexture", ptr)
    tex_e = _texture_info(rd, m, "emissiveTexture", ptr)
    emissive = rd.nums(m, "emissiveFactor", ptr, 3, [0.0, 0.0, 0.0], 0.0, 1.0)
    strength = _emissive_strength(rd, m, ptr)
    alpha_mode = rd.get(m, "alphaMode", ptr, "str", "OPAQUE")
    if alpha_mode not in ("OPAQUE", "MASK", "BLEND"):
        raise rd.err(f"{ptr}/alphaMode", f"'{alpha_mode}' is not an alpha mode", "use OPAQUE, MASK or BLEND")
    cutoff = rd.num(m, "alphaCutoff", ptr, 0.5, 0.0, None)
    double = rd.get(m, "doubleSided", ptr, "bool", False)
    return _Factors(pbr, pptr, base, metallic, roughness, tex_base, tex_mr, tex_n, tex_o, tex_e, emissive, strength,
                    alpha_mode, cutoff, double)


def _texture_info(rd: Reader, d: dict, key: str, ptr: str) -> dict | None:
    info = rd.get(d, key, ptr, "obj", None)
    if info is None:
        return None
    here = f"{ptr}/{key}"
    ti = rd.ref(info, "index", here, "textures")
    texture_transform.check_texcoord(rd, info, here)  # TEXCOORD_0 (KHR_texture_transform may choose the set)
    tex = rd.array("textures")[ti]
    src = rd.ref(tex, "source", pointer("textures", ti), "images", None)
    if "sampler" in tex:
        rd.ref(tex, "sampler", pointer("textures", ti), "samplers")
    out = {"texture": ti, "image": src}
    if src is not None:
        img = rd.array("images")[src]
        uri = rd.get(img, "uri", pointer("images", src), "str", None)
        if uri is not None and not uri.startswith("data:"):
            out["uri"] = uri
        if "bufferView" in img:
            out["bufferView"] = rd.ref(img, "bufferView", pointer("images", src), "bufferViews")
    return out


def _emissive_strength(rd: Reader, m: dict, ptr: str) -> float:
    """KHR_materials_emissive_strength's emissiveStrength (1 without it): it scales emissiveFactor."""
    ext = m.get("extensions")
    if not isinstance(ext, dict) or "KHR_materials_emissive_strength" not in ext:
        return 1.0
    eptr = f"{ptr}/extensions/KHR_materials_emissive_strength"
    e = rd.get(ext, "KHR_materials_emissive_strength", f"{ptr}/extensions", "obj")
    return rd.num(e, "emissiveStrength", eptr, 1.0, 0.0, None)


def _packing(f: _Factors, normal: str, uv: str) -> tuple[str, dict, dict]:
    """(packing spec, parameters, texture bindings) the textures present choose (the module docstring)."""
    r2 = f.roughness * f.roughness
    textures: dict = {}
    if f.tex_n is not None:
        textures["normal_map"] = f.tex_n
    if f.tex_base is None and f.tex_mr is None:
        packing = f"constants(normal={normal}{uv})"
        params = {"rho_d": [c * (1.0 - f.metallic) for c in f.base[:3]],
                  "f0": [0.04 + (c - 0.04) * f.metallic for c in f.base[:3]], "alpha": r2}
    elif f.tex_mr is None and f.metallic == 0.0:
        packing = f"albedo_texture(normal={normal}{uv})"
        params = {"rho_d": f.base[:3], "f0": [0.04, 0.04, 0.04], "alpha": r2}
        textures["albedo_map"] = f.tex_base
    else:
        packing = f"gltf_metallic_roughness(normal={normal}{uv})"
        params = {"base_color": f.base[:3], "metallic": f.metallic, "roughness": f.roughness}
        textures["base_color_map"] = f.tex_base or "white"
        textures["orm_map"] = f.tex_mr or "white"
    return packing, params, textures


class Materials:
    """The scene's glTF materials, each mapped once per (index, drawn with COLOR_0) into scene.materials."""

    def __init__(self, rd: Reader, lib: Library, scene: Scene, notes: list):
        self.rd, self.lib, self.scene, self.notes = rd, lib, scene, notes
        self.raw = rd.array("materials")
        self.names = unique_names([m.get("name") if isinstance(m.get("name"), str) else "" for m in self.raw],
                                  "material")
        self.mapped: dict[tuple, GltfMaterial] = {}

    def get(self, i, colors=False) -> GltfMaterial:
        """Material i (None: the glTF default material); colors: drawn on primitives with COLOR_0."""
        if (i, colors) not in self.mapped:
            name = self.names[i] if i is not None else free_name("default", self.names)
            if colors:  # another shader (vertex_color), so another material: "<name>+COLOR_0"
                name = free_name(f"{name}+COLOR_0", set(self.names) | set(self.scene.materials))
            self.mapped[(i, colors)] = self._map(i, self.raw[i] if i is not None else {}, name, colors)
            self.scene.materials[name] = self.mapped[(i, colors)]
        return self.mapped[(i, colors)]

    def _map(self, i, m: dict, name: str, colors: bool) -> GltfMaterial:
        """Material i (None: glTF's default material) mapped to a GltfMaterial; colors: the primitives drawn with it
        carry COLOR_0 (the vertex_color part of the surface state)."""
        rd, notes = self.rd, self.notes
        ptr = pointer("materials", i) if i is not None else "/materials (default material)"
        f = _factors(rd, m, ptr)
        if f.tex_n is not None:
            scale = rd.num(m["normalTexture"], "scale", f"{ptr}/normalTexture", 1.0)
            if scale != 1.0:
                notes.append(f"material '{name}': normalTexture.scale {scale} is not applied (normal_map has no scale)")
        if f.tex_o is not None:
            notes.append(f"material '{name}': occlusionTexture is not read (it scales indirect light; "
                         "the light loop has direct lights only)")
        normal = "normal_map" if f.tex_n is not None else "vertex"
        sampled = [(f.pbr, "baseColorTexture", f.pptr), (f.pbr, "metallicRoughnessTexture", f.pptr),
                   (m, "normalTexture", ptr)]
        sampled += [(m, "emissiveTexture", ptr)] if any(c * f.strength for c in f.emissive) else []
        uv, uv_params = texture_transform.of_material(rd, sampled)  # KHR_texture_transform: the packing's uv slot
        packing, params, textures = _packing(f, normal, uv)
        params.update(uv_params)
        # the surface state (spec/surface.py): each part only where it changes what the shader computes
        lit = [c * f.strength for c in f.emissive]
        surface = Surface(alpha=f.alpha_mode.lower(), double_sided=f.double, vertex_color=colors,
                          emissive="texture" if f.tex_e is not None and any(lit) else "factor" if any(lit) else "none")
        if f.alpha_mode != "OPAQUE":
            params["base_alpha"] = f.base[3]
        if f.alpha_mode == "MASK":
            params["alpha_cutoff"] = f.cutoff
        if surface.emissive != "none":
            params["emissive"] = lit
        if surface.emissive == "texture":
            textures[EMISSIVE_MAP] = f.tex_e
        elif f.tex_e is not None:
            notes.append(f"material '{name}': emissiveTexture is not sampled (emissiveFactor is 0)")
        brdf, packing = self._checked(ptr, packing, params, surface)
        return GltfMaterial(name, brdf, packing, params, surface, alpha_mode=f.alpha_mode, alpha_cutoff=f.cutoff,
                            double_sided=f.double, base_alpha=f.base[3], textures=textures, source=ptr)

    def _checked(self, ptr: str, packing: str, params: dict, surface: Surface) -> tuple:
        """(brdf, packing) in canonical form, once the bricks resolve them and take every parameter."""
        rd, lib = self.rd, self.lib
        try:
            brdf = canonical(parse_brdf(BRDF, lib))
            packing = canonical(parse_spec(packing, lib, ("packing",)))
            r = resolve(Permutation(brdf, (), packing, "linear", surface=surface), lib)
        except (SpecError, SourceError) as e:
            raise rd.err(ptr, f"the bricks this material maps to are missing: {e}",
                         "use the standard brick library (or --bricks with lambert, microfacet, ggx, …)") from None
        # outside the try: its own located error (a GltfError is a SourceError) is not "missing bricks"
        specs = surface_specs(r, lambda key, msg, todo: rd.err(ptr, msg, todo))
        for k, v in params.items():
            problem = specs[k].check(v) if k in specs else f"no parameter '{k}'"
            if problem:
                raise rd.err(ptr, f"maps to parameter '{k}' = {v}: {problem}", "fix the material's factors")
        problem, todo = check_packing(r)
        if problem:
            raise rd.err(ptr, problem, todo)
        return brdf, packing
