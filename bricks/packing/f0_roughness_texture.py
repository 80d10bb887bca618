"""Textured f0 and roughness: f0 from an sRGB texture's RGB, perceptual roughness from its alpha (α = r²).

For specular-only microfacet BRDFs (a textured metal: microfacet(ndf=ggx, …)), where
`albedo_texture` and `gltf_metallic_roughness` are refused because the BRDF reads no rho_d.
One texture `f0_map`:
  RGB  f0 = R_F(0), sRGB-encoded ("gamma space useful for textures containing non-radiance
       values such as ρ_d and R_F(0)", Hoffman & Baker 2006; as glTF KHR_materials_specular's
       specularColorTexture), times the material's constant f0;
  A    perceptual roughness r (linear: sRGB formats decode RGB only), times this packing's
       `roughness` factor; α = r² (Burley 2012, "Physically-Based Shading at Disney", §5.4;
       glTF 2.0 Appendix B).
Provides f0 and alpha. No guards here: the NDFs floor α at 1e-4 (docs/design/accuracy.md).
"""
BRICK = {
    "kind": "packing",
    "cite": "Hoffman & Baker 2006 (R_F(0) in textures, gamma space); Burley 2012 alpha = roughness^2",
    "params": {"roughness": {"type": "float", "range": [0.0, 1.0], "default": 1.0, "doc": "roughness factor (perceptual; alpha = (factor * A)^2)"}},
    "textures": {"f0_map": {"srgb": True, "doc": "sRGB RGB: f0; A (linear): perceptual roughness"}},
    "slots": {"normal": {"kind": "normal", "default": "vertex"}},
}


def get_f0(uv: vec2, f0_map: texture2d, f0: vec3) -> vec3:
    return f0 * sample(f0_map, uv).xyz


def get_alpha(uv: vec2, f0_map: texture2d, roughness: float) -> float:
    r = roughness * sample(f0_map, uv).w
    return r * r
