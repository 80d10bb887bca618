"""What the renderer reads of a build, written for a render that has no build: the scene's texture artifacts.

The renderer (runtime/renderer.py) draws a material's textures only from a build's outputs, as an engine
does (runtime/material_textures.py). `scene_textures` writes the texture part of a build into a folder (the
render's own output): the KTX2 artifacts under ``textures/``, made and listed by the build's own
`write_textures`, so the files, their names and the manifest fields (``materials.<name>.textures``,
``textures``, ``samplers``) are exactly what `shadermatrix build` writes for the scene — only without the
shaders, which the renderer composes itself. With the library given, ``tables`` lists every texture a brick
declares as a baked table by its ``texture`` name and ``sampler`` only (the renderer bakes the texels itself),
so that a table is read through the sampler row a build names for it.
"""
from __future__ import annotations

from pathlib import Path

from ..runtime.material_textures import BuildOutputs
from ..scene.load import Scene
from .texture_outputs import write_textures


def scene_textures(scene: Scene, out, lib=None) -> BuildOutputs:
    """The scene's texture artifacts written under `out` (textures/), and the manifest fields that list them
    (with `lib`, the samplers of its baked tables too)."""
    out = Path(out)
    manifest = {"platforms": ["vulkan"], "materials": {name: {} for name in scene.materials}}
    if lib is not None and lib.tables():
        manifest["tables"] = [{"texture": name} for name in sorted(lib.tables())]
    write_textures(out, scene, manifest)
    return BuildOutputs(manifest, out)
