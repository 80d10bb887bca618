"""The renderer's image-based lighting inputs: what an environment brick's textures read, uploaded.

The renderer does not bake (runtime comes before eval): `EnvironmentInputs` is what assemble/environments.py
bake() computes from the scene — per environment its SH9 values and GGX-prefiltered radiance cube (levels
(6, s, s, 3), level k holding α = (k/(L − 1))²), per BRDF key its AmbientBRDF table (H, W, 4) — and the
renderer uploads it: each cube once with its whole mip chain (R32G32B32A32_SFLOAT, as baked) read through a
trilinear clamp-to-edge sampler (mipmapMode LINEAR, maxLod = L − 1; Vulkan filters seamlessly across cube faces),
each table once, read through the bilinear clamp-to-edge sampler at level 0. The radiance cube binds where a
draw's light set's environment is bound (set 0), the table where its material's is (set 1).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..lang.errors import UserError


@dataclass(frozen=True)
class BakedEnvironment:
    name: str
    sh: dict  # {sh0 … sh8: [r, g, b]}: the L_lm of its radiance (Â not folded)
    levels: list  # the prefiltered radiance cube: level k (6, s, s, 3) float64


@dataclass(frozen=True)
class EnvironmentInputs:
    """A scene's baked environments (by name) and AmbientBRDF tables (by BRDF key)."""

    environments: dict = field(default_factory=dict)
    tables: dict = field(default_factory=dict)

    def values(self) -> dict:
        """{environment: {sh0 … sh8}}: what link/values.uploads writes into a Lights block."""
        return {n: e.sh for n, e in self.environments.items()}


TRILINEAR = {"magFilter": "VK_FILTER_LINEAR", "minFilter": "VK_FILTER_LINEAR",
             "mipmapMode": "VK_SAMPLER_MIPMAP_MODE_LINEAR", "addressModeU": "VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE",
             "addressModeV": "VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE",
             "addressModeW": "VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE", "mipLodBias": 0.0, "anisotropyEnable": False,
             "maxAnisotropy": 1.0, "compareEnable": False, "compareOp": "VK_COMPARE_OP_ALWAYS", "minLod": 0.0,
             "maxLod": 1000.0}


def rgba32(level) -> np.ndarray:
    """A level (..., 3) as float32 RGBA, alpha 1."""
    a = np.asarray(level, np.float64)
    out = np.ones(a.shape[:-1] + (4,), np.float32)
    out[..., :a.shape[-1]] = a
    return out


class EnvironmentTextures:
    """The GPU images and samplers of a render's environments, made on first use, released by destroy()."""

    def __init__(self, device, inputs: EnvironmentInputs | None, scene):
        self.device, self.inputs, self.scene = device, inputs, scene
        self._images: dict = {}
        self._trilinear = None
        if scene.environment_of and inputs is None:
            first = sorted(set(scene.environment_of.values()))[0]
            raise UserError(f"environment '{first}' lights the scene's light sets, and the renderer draws it from "
                            "baked inputs: none were given — render with `shadermatrix render` (it bakes them) or "
                            "pass environments=assemble.environments.bake(scene, lib)")

    def radiance(self, light_set: str):
        """(image, sampler) of the radiance cube of the environment lighting `light_set`."""
        from .images import Image, Sampler
        name = self.scene.environment_of[light_set]
        key = ("cube", name)
        if key not in self._images:
            env = self.inputs.environments.get(name)
            if env is None:
                raise UserError(f"environment '{name}' was not baked — bake the scene's environments again "
                                "(assemble.environments.bake)")
            levels = [rgba32(x) for x in env.levels]
            self._images[key] = Image(self.device, levels[0], cube=True, mips=levels[1:])
        if self._trilinear is None:
            self._trilinear = Sampler(self.device, dict(TRILINEAR))
        return self._images[key], self._trilinear

    def table(self, brdf: str, sampler):
        """(image, sampler) of the AmbientBRDF table of BRDF key `brdf`: bilinear, clamp to edge, level 0."""
        from .images import Image
        key = ("table", brdf)
        if key not in self._images:
            texels = self.inputs.tables.get(brdf)
            if texels is None:
                raise UserError(f"no AmbientBRDF table was baked for brdf '{brdf}' — bake the scene's environments "
                                "again (assemble.environments.bake)")
            self._images[key] = Image(self.device, rgba32(np.asarray(texels)[..., :4]), cube=False)
        return self._images[key], sampler

    def destroy(self) -> None:
        for obj in [*self._images.values(), *([self._trilinear] if self._trilinear is not None else [])]:
            obj.destroy()
        self._images, self._trilinear = {}, None
