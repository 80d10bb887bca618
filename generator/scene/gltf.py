"""glTF 2.0 scenes (`.gltf`, `.glb`) → the same Scene a TOML scene gives (scene/load.py), through pygltflib.

load_gltf reads the file, checks what it uses and maps it; each part of the mapping is its own module:
  - the container (the .gltf's JSON, the .glb's chunks, buffers, accessors) and the checked reading of
    every value at its JSON pointer, GltfError: scene/gltf_read.py;
  - the extensions accepted and refused: scene/gltf_extensions.py;
  - materials → BRDF, packing, parameters, surface state: scene/gltf_materials.py, their texture images
    and samplers: scene/gltf_images.py, KHR_texture_transform: scene/texture_transform.py;
  - KHR_lights_punctual → lights and light sets: scene/gltf_lights.py;
  - the scenes' node trees and world matrices: scene/gltf_nodes.py;
  - a primitive → its mesh, generated tangents: scene/gltf_meshes.py;
  - the names everything takes: scene/gltf_names.py.
This module walks the glTF scenes and makes the objects and their permutations.

Objects. One per primitive of every node instance in every glTF scene, named from the node (else the
mesh, else `node<i>`), `#<primitive>` when the mesh has several, made unique with `~2`, `~3`, …; each
carries its mesh (runtime/meshes.Mesh: positions, normals, tangents, uvs, uint32 indices; TRIANGLES,
strips and fans unrolled; points and lines skipped with a note) and its world matrix (`model`, 4×4).
COLOR_0 is read into the mesh (Mesh.colors) and recorded on the object (`vertex_colors`). Every mesh
node of a glTF scene uses that scene's light set; the object's permutation is its material's BRDF,
packing and surface state with those lights.
Origins. Each permutation carries where its first object asked for it (spec/where.py), so an error
resolving or linking it names the glTF object to edit, found in the JSON text by scene/jsonpos.py:
the material (for glTF's default material, the primitive), the primitive's COLOR_0 for the vertex
colours, each light's KHR_lights_punctual definition. In a .gltf that is the object's line and column
with its pointer: `model.gltf:12:5: /materials/2: what is wrong — what to do`. A .glb has no lines to
go to, so its errors are at 1:1 and name the pointer and the object's byte offset in the file:
`model.glb:1:1: /materials/2 (byte 1234): …` (the pointer is what glTF tools and viewers show).
Checked on import: what the mapping reads (materials, textures, images, the scenes' node trees,
the primitives and accessors of the meshes they instance, buffers, lights); meshes no node instances
and animations, skins, cameras are not read, so not checked.
Scene.notes lists, one line each, the accepted extensions and what is not applied; Scene.extra holds
"extensions" (the accepted ones) and "gltf" (the pygltflib.GLTF2 document).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..library.bricks import Library
from ..spec.permutation import Permutation
from .gltf_extensions import ACCEPTED_EXTENSIONS, SHADING_EXTENSIONS, check_extensions
from .gltf_lights import LIGHTS, MAX_LIGHTS_PER_SET, SPOT_NO_RANGE, LightSets
from .gltf_materials import BRDF, GltfMaterial, Materials, textures_need_uv
from .gltf_meshes import MODES, generate_tangents, primitive_mesh
from .gltf_names import clean, free_name, unique_names
from .gltf_nodes import instances
from .gltf_read import MAX_GLTF_BYTES, GltfError, Reader, open_gltf, pygltf_document
from .gltf_sidecar import Sidecar
from .jsonpos import origins, pointer
from .light_sets import set_keys
from .load import Scene

__all__ = ["ACCEPTED_EXTENSIONS", "BRDF", "MAX_GLTF_BYTES", "MAX_LIGHTS_PER_SET", "SHADING_EXTENSIONS",
           "SPOT_NO_RANGE", "GltfError", "GltfMaterial", "generate_tangents", "load_gltf", "textures_need_uv"]


def load_gltf(path, lib: Library) -> Scene:
    """Read, check and map a glTF 2.0 file (.gltf or .glb) to a Scene (module docstring: the mapping)."""
    path = Path(path)
    rd, text, data = open_gltf(path)
    notes: list[str] = []
    accepted = check_extensions(rd, notes)
    rd.quantized = "KHR_mesh_quantization" in accepted
    g = pygltf_document(rd, data, text)

    # scene.notes: accepted extensions and what is not applied, one line each; scene.extra: "extensions"
    # (the accepted ones, sorted) and "gltf" (the pygltflib.GLTF2 document: images, samplers, animation, ...)
    scene = Scene(path, path.stem, "linear", "fp32", {}, {}, {}, [], head_at=(1, 1), notes=notes,
                  extra={"extensions": accepted, "gltf": g})
    for name in ("materials", "textures", "images", "samplers", "meshes", "nodes", "accessors", "bufferViews",
                 "buffers", "scenes"):
        rd.array(name)
    materials = Materials(rd, lib, scene, notes)
    for i in range(len(materials.raw)):  # every material is checked, used or not; unused ones build nothing
        materials.get(i)
    build = _Objects(rd, scene, materials, LightSets(rd, lib, scene))

    scenes = rd.array("scenes")
    if not scenes and rd.array("meshes"):
        notes.append("the file has no scenes: its meshes are not instanced, so no objects")
    set_names = unique_names([s.get("name") if isinstance(s.get("name"), str) else "" for s in scenes], "scene")
    lights_file = Sidecar(path, lib)  # SCENE.lights.toml: shadows and a dynamic set (scene/gltf_sidecar.py)
    for si, s in enumerate(scenes):
        placed = instances(rd, si, s)
        members = build.lights.of_scene(si, placed, limit=not lights_file.dynamic)
        lights_file.apply_lights(scene, members)
        scene.light_sets[set_names[si]] = members
        lights_file.apply_set(scene, set_names[si])
        for ni, world in placed:
            build.node(ni, world, set_names[si], members)
    lights_file.check_names(scene)
    if lights_file.found:
        scene.extra["inputs"] = [lights_file.path]  # read by every command: a build's depfile lists it
    for h, origin in origins(rd.shown, text, build.asks, rd.glb).items():
        scene.permutations[h] = replace(scene.permutations[h], origin=origin)
        scene.where.setdefault(h, (origin.parts[0][1].line, origin.parts[0][1].col))
    if build.skipped_modes:
        notes.append(f"primitives drawn as {', '.join(sorted(build.skipped_modes))} are not shaded: skipped")
    gen = sorted({o["name"] for o in scene.objects if o["tangents"] == "generated"})
    if gen:
        notes.append(f"tangents generated from UV gradients (Lengyel; not MikkTSpace-exact) for: {', '.join(gen)}")
    from .gltf_images import bind_images  # every material's texture images and samplers, read and checked
    bind_images(rd, lib, scene, text, rd.glb, notes)
    scene.notes = list(dict.fromkeys(notes))
    return scene


@dataclass
class _Placed:
    """A node instance of a mesh: where its primitives' objects are drawn, and with which lights."""

    node: int
    world: np.ndarray
    mesh: int
    name: str  # the node's name, else the mesh's, else node<i>
    several: bool  # the mesh has several primitives: its objects are named `<name>#<primitive>`
    light_set: str
    lights: list
    keys: tuple  # the lights' LightKeys


class _Objects:
    """The scene's objects and permutations, made one primitive at a time (the module docstring: Objects)."""

    def __init__(self, rd: Reader, scene: Scene, materials: Materials, lights: LightSets):
        self.rd, self.scene, self.materials, self.lights = rd, scene, materials, lights
        self.names: set[str] = set()
        self.asks: dict[str, tuple] = {}  # permutation hash -> (part, pointer) pairs: where its first object asked
        self.hashes: dict[Permutation, str] = {}
        self.skipped_modes: set[str] = set()
        self.meshes: dict[tuple, tuple] = {}  # (mesh, primitive) -> primitive_mesh's answer

    def node(self, ni: int, world: np.ndarray, lset: str, members: list) -> None:
        """The objects of node ni's mesh (none without one), drawn at `world` with light set lset."""
        rd, scene = self.rd, self.scene
        node = rd.array("nodes")[ni]
        mi = rd.ref(node, "mesh", pointer("nodes", ni), "meshes", None)
        if mi is None:
            return
        mesh = rd.array("meshes")[mi]
        mptr = pointer("meshes", mi)
        prims = rd.get(mesh, "primitives", mptr, "arr")
        if not prims:
            raise rd.err(f"{mptr}/primitives", "a mesh has at least one primitive", "remove the mesh or add one")
        nname = node.get("name") if isinstance(node.get("name"), str) and node.get("name") else \
            mesh.get("name") if isinstance(mesh.get("name"), str) and mesh.get("name") else f"node{ni}"
        keys = set_keys(scene, lset)  # a dynamic set's model, or its lights
        at = _Placed(ni, world, mi, nname, len(prims) > 1, lset, members, keys)
        for pi, prim in enumerate(prims):
            self._primitive(at, pi, prim)

    def _light_ptr(self, at: _Placed, k: int) -> str:
        """Where light k of the key was asked for: a static set's light k, a dynamic set's first light of pair k."""
        if at.light_set not in self.scene.dynamic_sets:
            return self.lights.ptrs[at.lights[k]]
        pair = at.keys[k]
        dyn = self.scene.dynamic_sets[at.light_set]
        first = next((n for n in at.lights if dyn.key(self.scene.lights[n].type, self.scene.lights[n].shadow)
                      == pair), None)
        return self.lights.ptrs[first] if first else LIGHTS

    def _primitive(self, at: _Placed, pi: int, prim) -> None:
        rd, scene = self.rd, self.scene
        pptr = f"{pointer('meshes', at.mesh)}/primitives/{pi}"
        if not isinstance(prim, dict):
            raise rd.err(pptr, "must be a JSON object", "each primitive is an object")
        mode = rd.get(prim, "mode", pptr, "int", 4)
        if mode not in MODES:
            raise rd.err(f"{pptr}/mode", f"{mode} is not a primitive mode", "use 0 … 6 (4: TRIANGLES)")
        mat_i = rd.ref(prim, "material", pptr, "materials", None)
        attrs = prim.get("attributes")
        m = self.materials.get(mat_i, isinstance(attrs, dict) and "COLOR_0" in attrs)
        if mode < 4:
            self.skipped_modes.add(MODES[mode])
            return
        key = (at.mesh, pi)
        if key not in self.meshes:
            self.meshes[key] = primitive_mesh(rd, prim, pptr, mode, m)
        mesh_obj, tangents, colors = self.meshes[key]
        oname = free_name(clean(at.name + (f"#{pi}" if at.several else "")), self.names)
        self.names.add(oname)
        perm = Permutation(m.brdf, at.keys, m.packing, scene.output, scene.precision, m.surface)
        h = self.hashes.get(perm)
        if h is None:
            h = self.hashes[perm] = perm.hash
            scene.permutations.setdefault(h, perm)
            self.asks[h] = ((("brdf", m.source if mat_i is not None else pptr),)
                            + ((("vertex_color", f"{pptr}/attributes/COLOR_0"),) if m.surface.vertex_color else ())
                            + tuple((f"light{k}", self._light_ptr(at, k)) for k in range(len(at.keys))))
        scene.users.setdefault(h, []).append(oname)
        scene.objects.append({"name": oname, "material": m.name, "light_set": at.light_set, "lights": list(at.lights),
                              "permutation": h, "node": at.node, "mesh_index": at.mesh, "primitive": pi,
                              "source": pptr, "mesh": mesh_obj, "model": at.world.tolist(),
                              "alpha_mode": m.alpha_mode, "alpha_cutoff": m.alpha_cutoff,
                              "double_sided": m.double_sided, "tangents": tangents, "vertex_colors": colors})
