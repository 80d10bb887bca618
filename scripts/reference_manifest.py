"""What every field of manifest.json means: the descriptions docs/reference/manifest.md is generated from.

The manifest is written by generator/assemble/ (`_build` puts the top level together; `write_platforms`,
`scene_tables`, `write_tables`, `write_packs` and the link stage's `Interface.as_dict` fill their parts). It
is described here as nested shapes: a shape is a JSON object whose fixed keys each have a description, and
possibly any number of keys that are names (`any`: a material's name, a stage, a tool). A field's `of` is
the shape of its value, or of each element when the value is a list. A field that a build of
scenes/example.toml with --pack does not write says `when` it is there.

`check(manifest)` walks a real manifest against the shapes: every key must be described, and every field
described without a `when` must appear (in the shapes the manifest reaches), so the page can neither miss
a field nor keep one the build no longer writes.
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class F:
    desc: str
    of: str = ""     # the shape of the value (an object), or of each element (a list)
    when: str = ""   # absent from the example build: when it is written


@dataclass
class Shape:
    title: str
    doc: str
    fields: dict[str, F]
    any: tuple[str, F] | None = None  # (placeholder, field): keys that are names


STAGE = ("<stage>", F("`vert` or `frag`"))
S: dict[str, Shape] = {}


def shape(name: str, title: str, doc: str, fields: dict[str, F], any: tuple[str, F] | None = None) -> None:
    S[name] = Shape(title, doc, fields, any)


shape("manifest", "The top level", "What `shadermatrix build SCENE --out DIR` writes as DIR/manifest.json. Paths "
      "in it are relative to DIR; files are named by their content, so a rebuild never overwrites a file an "
      "earlier manifest names. No times and no absolute paths: two builds of the same inputs write the same bytes.", {
          "generator": F("`shadermatrix X.Y.Z`: the generator and its version"),
          "scene": F("the scene's name (`[scene] name`)"),
          "tools": F("the exact version of each compiler and validator the build ran", "tools"),
          "languages": F("the shading languages built and validated through SPIR-V: `glsl`, `hlsl`, `wgsl`"),
          "platforms": F("the platforms written (`--platform`): `vulkan`, `d3d12`, `gl`, `webgpu`, each a tree "
                         "DIR/<platform>/"),
          "permutations": F("one entry per permutation of the scene, sorted by hash", "entry"),
          "ubershader": F("the scene's fallback ubershader: one program for every permutation (an entry without "
                          "`id`, `objects`, `bricks`, `uploads`, `platforms`; `{}` for a scene with no objects)",
                          "entry"),
          "materials": F("the scene's materials that objects draw with, by name", "materials"),
          "lights": F("the scene's lights that objects are lit by, by name", "lights"),
          "light_sets": F("each light set's light names in order", "light_sets"),
          "objects": F("the scene's objects in file order", "object"),
          "removed": F("entries of permutations that left the scene, their files kept; shaped as `permutations`' "
                       "entries with status `removed`", "entry",
                       when="`build --keep-removed`, after a permutation left the scene"),
          "tables": F("the baked lookup tables the shaders sample, one per texture", "table",
                      when="a permutation or the ubershader samples a baked table (a factored, painted or measured "
                           "brick)"),
          "packs": F("one shader pack per platform", "pack", when="`build --pack`"),
      })
shape("tools", "Tool versions", "", {}, ("<tool>", F("its exact version (`glslc`, `glslang`, `spirv-tools`, "
                                                     "`naga`; `dxc` for d3d12)")))
shape("entry", "A permutation entry", "One shader permutation: what it is, what it reads, its files per language "
      "and per platform, what an engine binds and uploads. The ubershader's entry has the same shape (the fields it "
      "has say so).", {
          "id": F("the permutation key as text: `brdf=…;lights=…;packing=…;output=…;precision=…` and the surface "
                  "state where it is not the default"),
          "hash": F("12 hex digits of the key's sha256: the name of its files (the ubershader's: of its own key)"),
          "input_key": F("sha256 of everything its outputs depend on (its key, every brick it reads, the scene "
                         "values of its objects, the generator's code and templates, the tools' versions, the "
                         "languages); an unchanged key is not rebuilt"),
          "objects": F("the names of the objects drawn with it"),
          "languages": F("its compiled sources and SPIR-V, per language", "languages"),
          "bricks": F("every brick it reads, by path", "bricks"),
          "interface": F("the reflection: what the engine binds, per stage", "interface"),
          "uploads": F("per (material, light set) drawn with it: the uniform blocks ready to upload", "upload"),
          "platforms": F("what each platform's tree holds for it", "platforms"),
          "tables": F("the ubershader's tables: its variants and the layout of its buffer entries (ubershader only)",
                      "uber_tables"),
          "status": F("`ok`; `stale` (it failed: its last good files and entry are kept); `failed` (it failed and "
                      "has no earlier outputs); `removed` (under `removed`)"),
          "errors": F("the located errors that failed it", when="status `stale` or `failed`"),
          "failed_sources": F("the sources that failed, written beside, by `<language>.<stage>` (or `gl.<stage>`)",
                              "failed_sources", when="status `stale` or `failed`"),
      })
shape("failed_sources", "Failed sources", "", {}, ("<language>.<stage>", F("the path of the failing source")))
shape("languages", "Languages", "", {}, ("<language>", F("`glsl`, `hlsl` or `wgsl`: its stages", "stages")))
shape("stages", "Stages of a language", "", {}, (STAGE[0], F(STAGE[1].desc + ": its compiled source", "compiled")))
shape("compiled", "A compiled stage", "One source and the optimized SPIR-V made from it, both under "
      "DIR/vulkan/<language>/.", {
          "source": F("the source's path (`vulkan/<language>/<hash>.<stage>.<sha12>.<language>`)",
                      when="the vulkan platform is built"),
          "source_sha256": F("the source's sha256"),
          "spirv": F("the SPIR-V's path (`vulkan/<language>/<sha16>.<stage>.spv`: identical modules are one file)",
                     when="the vulkan platform is built"),
          "spirv_sha256": F("the SPIR-V's sha256"),
          "cost": F("the static cost of the optimized SPIR-V", "cost"),
      })
shape("cost", "Static cost", "Counted on the SPIR-V after `spirv-opt -O` (generator/analysis/): each instruction "
      "once wherever it sits in the control flow; the class counts add up to `instructions`.", {
          "instructions": F("every instruction executed as code"),
          "alu": F("arithmetic, comparisons, conversions, logic, selects, dot and matrix products"),
          "transcendental": F("pow, exp, log, square roots, trigonometry, and what contains a square root "
                              "(length, normalize)"),
          "texture": F("samples, fetches, gathers, image reads"),
          "branches": F("conditional branches whose condition is not a constant"),
          "loads": F("memory loads (atomics and copies included)"),
          "stores": F("memory stores"),
          "other": F("moves, shuffles, composites, phis, access chains, jumps, returns, handle loads"),
          "alu_scalar": F("ALU operations counted per component (a vec3 add is 3, a dot of vec3 is 5)"),
          "transcendental_scalar": F("transcendental operations per component"),
          "loads_scalar": F("32-bit components loaded"),
          "stores_scalar": F("32-bit components stored"),
          "registers": F("peak live 32-bit scalars: an estimate of register pressure"),
          "calls": F("function calls left after optimization (0 when fully inlined)"),
      })
shape("bricks", "Bricks read", "", {}, ("<brick path>", F("the sha256 of the brick's source (`bricks/…` for the "
                                                          "shipped ones)")))
shape("interface", "Interface", "The reflection of one program (generator/link/interface.py): blocks with members, "
      "offsets, sizes and types, textures with set, binding, dimension and color space, vertex inputs and "
      "interpolants with locations, and where every parameter lives.", {
          "shading_inputs": F("the rows of the [shading inputs](language.md#shading-inputs) table the BRDF reads"),
          "frag": F("the fragment stage", "stage_interface"),
          "vert": F("the vertex stage", "stage_interface"),
      })
shape("stage_interface", "Interface of a stage", "", {
    "entry_point": F("the entry point's name (`main`)"),
    "uniform_blocks": F("its uniform blocks (`Frame`, `Object` in the vertex stage; `Frame`, `Material`, `Lights`, "
                        "… in the fragment stage)", "block"),
    "storage_blocks": F("its read-only storage blocks (fragment stage; the ubershader's light and material "
                        "buffers)", "block"),
    "textures": F("its textures (fragment stage), each an image and its sampler", "texture"),
    "inputs": F("vertex inputs (vertex stage) or interpolants (fragment stage)", "location"),
    "outputs": F("interpolants (vertex stage) or colour outputs (fragment stage)", "location"),
})
shape("block", "Block", "A uniform or storage block.", {
    "name": F("the block's name as the sources declare it"),
    "set": F("descriptor set"),
    "binding": F("binding in the set"),
    "kind": F("`uniform` or `storage`"),
    "size": F("bytes (0 for a runtime-sized storage block)"),
    "members": F("the members as declared", "member"),
    "parameters": F("where each parameter of the material or lights lives in it", "parameter"),
})
shape("member", "Block member", "", {
    "name": F("the member's name"),
    "type": F("its type (`mat4`, `vec4`, `vec4[9]`, `LightEntry[]`)"),
    "offset": F("byte offset in the block (or in its struct)"),
    "size": F("bytes (0 for a runtime-sized array)"),
    "array_stride": F("bytes between array elements", when="an array member"),
    "matrix_stride": F("bytes between matrix columns", when="a matrix member"),
    "members": F("the members of the struct an array holds", "member", when="an array of structs"),
})
shape("parameter", "Parameter slot", "A parameter's place in a block's vec4 array, packed: a vec3 at .xyz, a vec2 at "
      ".xy or .zw, a scalar in any component, a vec4 whole, a mat4 in four vec4s (docs/design/link.md, "
      "\"Uniform layout\").", {
    "name": F("the parameter (`name[i]` for an element of an array parameter)"),
    "type": F("its brick-language type"),
    "offset": F("byte offset in the block (in each element, for a storage block of light entries); "
                "16 · vec4 + 4 · component"),
    "size": F("bytes it occupies"),
    "light": F("the index of the light it belongs to", when="a light's parameter"),
    "default": F("its default value"),
    "range": F("its valid range `[min, max]`, or null"),
})
shape("texture", "Texture", "An image at `binding` and its sampler at `sampler_binding`.", {
    "name": F("the brick's texture name"),
    "set": F("descriptor set (0: a light's, 1: the material's)"),
    "binding": F("the image's binding"),
    "sampler_binding": F("the sampler's binding (`binding + 1`)"),
    "dimension": F("`2d` or `cube`"),
    "color_space": F("`srgb` or `linear`"),
    "light": F("the index of the light it belongs to", when="a light's texture (a shadow map)"),
    "format": F("`depth`", when="a texture2d_shadow (a hardware depth compare)"),
    "sampler": F("`comparison`", when="a texture2d_shadow"),
    "compare_op": F("`less_or_equal`", when="a texture2d_shadow"),
})
shape("location", "Location", "A vertex input, an interpolant or an output.", {
    "location": F("its location"),
    "name": F("its name in the sources (`a_position`, `v_normal`, `out_color`)"),
    "type": F("its type"),
    "format": F("the vertex format (`R32G32B32_SFLOAT`)", when="a vertex input"),
})
shape("upload", "Upload", "The values of one (material, light set) laid out by the permutation's Interface: "
      "little-endian float32, as hex.", {
          "material": F("the material's name"),
          "light_set": F("the light set's name"),
          "objects": F("the objects drawn with this pair"),
      }, ("<Block>", F("a block's bytes, ready to upload, by block name (`Material`, `Lights`)")))
shape("platforms", "Platforms of an entry", "", {
    "vulkan": F("the vulkan tree", "vulkan"),
    "d3d12": F("the d3d12 tree", "d3d12"),
    "gl": F("the gl tree", "gl"),
    "webgpu": F("the webgpu tree", "webgpu"),
})
shape("artifact", "Artifact", "", {"path": F("the file's path"), "sha256": F("its sha256")})
shape("stage_costs", "Costs by stage", "", {}, (STAGE[0], F(STAGE[1].desc + ": its cost", "cost")))
shape("platform_tools", "Tools of a platform", "", {}, ("<tool>", F("the exact version of a tool that made or "
                                                                    "checked its artifacts")))
shape("vulkan", "Platform vulkan", "SPIR-V of the GLSL, and every language's source with its SPIR-V.", {
    "stages": F("per stage, its artifacts", "vulkan_stages"),
    "spirv_from": F("the language whose SPIR-V is the platform's (`glsl`)"),
    "cost": F("per stage, the cost of that SPIR-V", "stage_costs"),
    "reflection": F("descriptors and vertex inputs in Vulkan's binding model", "vulkan_reflection"),
    "tools": F("the tools' versions", "platform_tools"),
})
shape("vulkan_stages", "Vulkan stages", "", {}, (STAGE[0], F(STAGE[1].desc, "vulkan_stage")))
shape("vulkan_stage", "A vulkan stage", "", {
    "spirv": F("the SPIR-V the platform ships", "artifact"),
}, ("<language>", F("a language's source (`path`, `sha256`) and the path of its SPIR-V (`spirv`)", "vulkan_source")))
shape("vulkan_source", "A vulkan source", "", {
    "path": F("the source's path"), "sha256": F("its sha256"), "spirv": F("the path of the SPIR-V made from it")})
shape("vulkan_reflection", "Vulkan reflection", "", {
    "descriptors": F("every descriptor, in (set, binding) order", "descriptor"),
    "vertex_inputs": F("the vertex inputs", "vertex_input"),
    "push_constants": F("push-constant ranges (none: every value is in a block)"),
})
shape("descriptor", "Descriptor", "", {
    "set": F("descriptor set"), "binding": F("binding"),
    "type": F("`uniform_buffer`, `storage_buffer`, `sampled_image` or `sampler`"),
    "name": F("the name the sources declare"), "stages": F("the stages that read it"),
    "dimension": F("an image's or sampler's texture dimension", when="an image or sampler"),
    "compare": F("a depth texture with a comparison sampler", when="an image or sampler"),
    "parameter": F("the brick's texture name", when="an image or sampler"),
})
shape("vertex_input", "Vertex input", "", {
    "location": F("its location"), "name": F("its name (`a_position`)"), "format": F("its Vulkan format")})
shape("d3d12", "Platform d3d12", "HLSL for Shader Model 6 (the vulkan tree's text: `register(xN, spaceM)`), and DXIL "
      "where a `dxc` is on PATH.", {
          "stages": F("per stage, `hlsl` (and `dxil`)", "d3d12_stages"),
          "profiles": F("per stage, the shader model profile (`vs_6_0`, `ps_6_0`; `_6_2` at fp16)", "profiles"),
          "dxil": F("`built`, or why not (no dxc on PATH)"),
          "cost": F("per stage, the cost of the HLSL's SPIR-V", "stage_costs"),
          "cost_from": F("what the cost was measured on"),
          "reflection": F("registers and the input layout", "d3d12_reflection"),
          "tools": F("the tools' versions", "platform_tools"),
      })
shape("profiles", "Profiles", "", {}, (STAGE[0], F(STAGE[1].desc + ": its profile")))
shape("d3d12_stages", "D3D12 stages", "", {}, (STAGE[0], F(STAGE[1].desc, "d3d12_stage")))
shape("d3d12_stage", "A d3d12 stage", "", {
    "hlsl": F("the HLSL source", "artifact"),
    "dxil": F("the DXIL module", "artifact", when="a `dxc` is on PATH"),
})
shape("d3d12_reflection", "D3D12 reflection", "", {
    "resources": F("every resource, in (space, register) order", "d3d12_resource"),
    "input_layout": F("the input layout", "input_element"),
})
shape("d3d12_resource", "D3D12 resource", "", {
    "name": F("the name the HLSL declares"), "type": F("`CBV`, `SRV` or `Sampler`"),
    "register": F("`bN`, `tN` or `sN`"), "space": F("the register space"),
    "visibility": F("the stages that read it"),
    "dimension": F("a texture's dimension", when="a texture or sampler"),
    "compare": F("a depth texture with a comparison sampler", when="a texture or sampler"),
    "parameter": F("the brick's texture name", when="a texture or sampler"),
})
shape("input_element", "Input element", "", {
    "semantic": F("`POSITION`, `NORMAL`, `TANGENT`, `TEXCOORD`, `COLOR`"), "semantic_index": F("its index"),
    "format": F("its DXGI format"), "name": F("the vertex input's name")})
shape("gl", "Platform gl", "GLSL 4.50 core, and GLSL ES 3.10 where the bricks allow.", {
    "stages": F("per stage, `glsl` (and `essl`)", "gl_stages"),
    "versions": F("the `#version` of each dialect", "gl_versions"),
    "essl": F("`ok`, or `{\"unsupported\": [errors]}` when the ES source does not validate (the permutation still "
              "builds)", "essl"),
    "reflection": F("binding points and texture units", "gl_reflection"),
    "tools": F("the tools' versions", "platform_tools"),
})
shape("essl", "ES verdict", "", {"unsupported": F("glslangValidator's errors", when="the ES source does not validate")})
shape("gl_versions", "GL versions", "", {"glsl": F("`450 core`"), "essl": F("`310 es`")})
shape("gl_stages", "GL stages", "", {}, (STAGE[0], F(STAGE[1].desc, "gl_stage")))
shape("gl_stage", "A gl stage", "", {
    "glsl": F("the GLSL 4.50 core source", "artifact"),
    "essl": F("the GLSL ES 3.10 source", "artifact"),
})
shape("gl_reflection", "GL reflection", "Vulkan's (set, binding) pairs flattened per namespace.", {
    "uniform_blocks": F("uniform-block binding points", "gl_block"),
    "storage_blocks": F("storage-block binding points", "gl_block"),
    "samplers": F("texture units", "gl_sampler"),
    "vertex_inputs": F("vertex input locations", "gl_vertex_input"),
})
shape("gl_block", "GL block", "", {"name": F("the block's name"), "binding": F("its binding point"),
                                   "stages": F("the stages that read it")})
shape("gl_sampler", "GL sampler", "", {
    "name": F("the sampler's name in the GLSL"), "unit": F("its texture unit"),
    "type": F("`sampler2D`, `samplerCube` or `sampler2DShadow`"), "dimension": F("`2d` or `cube`"),
    "compare": F("a depth texture with a comparison sampler"), "parameter": F("the brick's texture name")})
shape("gl_vertex_input", "GL vertex input", "", {"location": F("its location"), "name": F("its name")})
shape("webgpu", "Platform webgpu", "WGSL, the vulkan tree's text.", {
    "stages": F("per stage, `wgsl`", "webgpu_stages"),
    "cost": F("per stage, the cost of the WGSL's SPIR-V", "stage_costs"),
    "cost_from": F("what the cost was measured on"),
    "reflection": F("bind groups and vertex inputs", "webgpu_reflection"),
    "tools": F("the tools' versions", "platform_tools"),
})
shape("webgpu_stages", "WebGPU stages", "", {}, (STAGE[0], F(STAGE[1].desc, "webgpu_stage")))
shape("webgpu_stage", "A webgpu stage", "", {"wgsl": F("the WGSL source", "artifact")})
shape("webgpu_reflection", "WebGPU reflection", "", {
    "bind_groups": F("every binding, as a GPUBindGroupLayoutEntry", "bind_entry"),
    "vertex_inputs": F("the vertex inputs", "webgpu_vertex_input"),
})
shape("bind_entry", "Bind group entry", "", {
    "group": F("bind group"), "binding": F("binding"), "name": F("the name the WGSL declares"),
    "visibility": F("`VERTEX`, `FRAGMENT`"),
    "buffer": F("`{\"type\": \"uniform\"}` or `{\"type\": \"read-only-storage\"}`", "buffer_layout",
                when="a block"),
    "texture": F("`sampleType` (`float` or `depth`) and `viewDimension`", "texture_layout", when="a texture"),
    "sampler": F("`{\"type\": \"filtering\"}` or `{\"type\": \"comparison\"}`", "sampler_layout", when="a sampler"),
})
shape("buffer_layout", "Buffer binding layout", "", {"type": F("`uniform` or `read-only-storage`")})
shape("texture_layout", "Texture binding layout", "", {"sampleType": F("`float` or `depth`"),
                                                       "viewDimension": F("`2d` or `cube`")})
shape("sampler_layout", "Sampler binding layout", "", {"type": F("`filtering` or `comparison`")})
shape("webgpu_vertex_input", "WebGPU vertex input", "", {
    "shaderLocation": F("its location"), "name": F("its name"), "format": F("its GPUVertexFormat (`float32x3`)")})
shape("uber_tables", "Ubershader tables", "How the ubershader selects a material variant and a light's code, and "
      "where their values sit in its storage buffers.", {
          "variants": F("one per material variant (brdf, packing, output) of the scene", "variant"),
          "light_types": F("the light types it handles, by index"),
          "shadows": F("the shadow filters it handles, by index"),
          "shadow_maps": F("how many shadow maps it binds"),
          "material_entry": F("a material buffer entry's layout", "material_entry"),
          "light_entry": F("a light buffer entry's layout", "light_entry"),
      })
shape("variant", "Variant", "", {
    "id": F("its index (the `ids.x` of a material entry)"), "brdf": F("its BRDF key"),
    "packing": F("its packing key"), "output": F("its output brick"),
    "parameters": F("where its parameters sit in a material entry's `data`", "parameter"),
})
shape("material_entry", "Material entry", "", {"ids": F("what its `ivec4 ids` holds"),
                                               "data_vec4s": F("the vec4s of its `data`")})
shape("light_entry", "Light entry", "", {"ids": F("what its `ivec4 ids` holds"),
                                         "data_vec4s": F("the vec4s of its `data`"),
                                         "shadow_parameters_at": F("the vec4 where the shadow filter's parameters start")})
shape("materials", "Materials", "", {}, ("<material>", F("one material", "material")))
shape("material", "Material", "", {
    "brdf": F("its BRDF key"), "packing": F("its packing key"),
    "params": F("its named values, defaults filled in", "values"),
})
shape("lights", "Lights", "", {}, ("<light>", F("one light", "light")))
shape("light", "Light", "", {
    "type": F("its light brick (`point`, `directional`, …)"), "shadow": F("its shadow filter (`none`, `shadow_map`, …)"),
    "params": F("its named values, defaults filled in", "values"),
})
shape("values", "Values", "", {}, ("<parameter>", F("a number or a list of numbers")))
shape("light_sets", "Light sets", "", {}, ("<light set>", F("its lights' names, in order")))
shape("object", "Object", "", {
    "name": F("its name"), "material": F("its material's name"), "light_set": F("its light set's name"),
    "permutation": F("the `hash` of the permutation it is drawn with"),
})
shape("table", "Table", "A baked lookup table, a KTX2 file under DIR/tables/.", {
    "texture": F("the texture name the shaders bind"), "table": F("the table's name"),
    "brick": F("the brick that declares it"), "path": F("the file's path"), "sha256": F("the file's sha256"),
    "texels_sha256": F("the texels' sha256"), "format": F("`unorm8`, `fp16` or `fp32`"),
    "size": F("`[W, H]`"), "dimension": F("`2d` or `cube`"), "bytes": F("the file's size"),
    "reference": F("the reference it is baked from"),
    "error": F("the filtered table's error against that reference (`max_abs`, `max_rel`, `worst`), or for a "
               "painted or fitted table the tolerance its brick declares (`measured_on`, `brick_tolerance`)"),
    "used_by": F("the hashes of the permutations (and `ubershader`) that sample it"),
    "input_key": F("sha256 of its inputs: an unchanged key is not baked again"),
})
shape("pack", "Pack", "A shader pack, DIR/packs/<platform>.<key16>.smpack (its format: generator/assemble/pack.py).", {
    "platform": F("the platform"), "language": F("the dialect of its artifacts"),
    "blob": F("what its blobs are (`spirv`, `dxil`, `hlsl`, `glsl`, `wgsl`)"),
    "path": F("the pack's path"), "sha256": F("the pack's sha256"), "key": F("the pack key (sha256 hex)"),
    "entries": F("its index entries (permutation, stage)"), "size": F("bytes"),
})


# -------------------------------------------------------------------------------------------- checking

def check(manifest: dict) -> list[str]:
    """What the descriptions miss in `manifest` (undocumented keys), and what they describe that it lacks."""
    problems: list[str] = []
    seen: dict[str, set[str]] = {}

    def walk(value, name: str, where: str) -> None:
        if isinstance(value, list):
            for x in value:
                walk(x, name, where + "[]")
            return
        if not isinstance(value, dict):
            return
        sh = S[name]
        mine = seen.setdefault(name, set())
        for k, v in value.items():
            f = sh.fields.get(k)
            key = k
            if f is None and sh.any is not None:
                key, f = sh.any
            if f is None:
                problems.append(f"manifest.json {where}.{k}: not described — add it to shape '{name}' in "
                                "scripts/reference_manifest.py, then run `make reference`")
                continue
            mine.add(key)
            if f.of:
                walk(v, f.of, f"{where}.{k}")

    walk(manifest, "manifest", "")
    for name in sorted(seen):
        sh = S[name]
        for k, f in sh.fields.items():
            if not f.when and k not in seen[name]:
                problems.append(f"shape '{name}' describes '{k}', which the example build does not write — say "
                                "`when` it is written, or remove it, in scripts/reference_manifest.py")
    for name, sh in S.items():
        for f in [*sh.fields.values(), *([sh.any[1]] if sh.any else [])]:
            if f.of and f.of not in S:
                problems.append(f"shape '{name}' names shape '{f.of}', which is not defined")
    return problems


def example_manifest(out: Path) -> dict:
    """Build scenes/example.toml with --pack into `out` (the pinned tools needed) and read its manifest."""
    cmd = [sys.executable, "-m", "generator.cli", "build", str(REPO / "scenes" / "example.toml"), "--out", str(out),
           "--pack", "-q"]
    r = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"building scenes/example.toml failed (exit {r.returncode}):\n{r.stderr[-3000:]}")
    return json.loads((out / "manifest.json").read_text())


def check_example_build() -> list[str]:
    with tempfile.TemporaryDirectory(prefix="shadermatrix-reference-") as tmp:
        return check(example_manifest(Path(tmp)))


# ------------------------------------------------------------------------------------------- rendering

def _anchor(title: str) -> str:
    return re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


def _cell(text: str) -> str:
    """Text in a table cell: newlines joined, pipes escaped, `<` outside code spans kept literal."""
    parts = " ".join(text.split()).split("`")
    return "`".join(p if i % 2 else p.replace("<", "&lt;") for i, p in enumerate(parts)).replace("|", "\\|")


def _reachable() -> list[str]:
    """The shapes in the order a reader meets them (depth first from the top level)."""
    order: list[str] = []

    def visit(name: str) -> None:
        if name in order:
            return
        order.append(name)
        sh = S[name]
        for f in [*sh.fields.values(), *([sh.any[1]] if sh.any else [])]:
            if f.of:
                visit(f.of)

    visit("manifest")
    return order


def render(head: str) -> str:
    out = [head, "What a build writes to DIR/manifest.json, field by field. A field's value is described in the "
                 "section it links to; a list's section describes each element. `<name>` stands for a key that "
                 "is a name (a material's, a stage, a tool). A field marked *only when* is written only then.\n"]
    for name in _reachable():
        sh = S[name]
        out.append(f"\n## {sh.title}\n\n" + (f"{_cell(sh.doc)}\n\n" if sh.doc else ""))
        out.append("| field | meaning |\n|---|---|\n")
        items = list(sh.fields.items()) + ([sh.any] if sh.any else [])
        for k, f in items:
            desc = _cell(f.desc)
            if f.of:
                desc += f" — see [{S[f.of].title}](#{_anchor(S[f.of].title)})"
            if f.when:
                desc += f" *(only when: {_cell(f.when)})*"
            out.append(f"| `{k}` | {desc} |\n")
    unreached = sorted(set(S) - set(_reachable()))
    if unreached:
        raise SystemExit(f"scripts/reference_manifest.py: shapes {', '.join(unreached)} are not reachable from the "
                         "top level — link them from a field or remove them")
    return "".join(out)
