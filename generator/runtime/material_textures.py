"""A scene's material textures in the renderer, read as an engine reads them: from a build's outputs.

The renderer draws no image of its own for a material: every texture a material binds (the image the scene
names, or the generated one where it names none: both are texture artifacts) is the KTX2 file the build wrote,
found through the fields an engine reads (assemble/texture_outputs.py writes them):

- ``materials.<name>.textures.<texture>``: the artifact's ``path`` (relative to the build's folder),
  ``sha256``, ``format``, ``width``, ``height``, ``levels``, and ``sampler.index``, its row in ``samplers``;
  where the build reflected the permutation, the ``set``/``binding`` of the image (and under ``ubershader``
  the ubershader's), which the renderer checks against the bindings of the shaders it draws with;
- ``samplers[index].platforms.vulkan``: the sampler state in VkSamplerCreateInfo's words;
- ``tables[i].sampler.index``: the row of ``samplers`` a baked table is read with (the renderer bakes the
  table's texels itself, the same bytes as the build's file: reference/tables.py).

Each file is read once, its sha256 checked against the manifest's, decoded with all its levels
(io/ktx2.decode_levels), checked against the row (format, size, levels) and uploaded as one
:class:`~.images.Image` with its mip chain, in the format the file states (R8G8B8A8_SRGB for colour: the
sampler decodes sRGB before it filters; UNORM for data and normal maps; the float formats as they are). Each
distinct sampler state is one :class:`~.images.Sampler`; what the device cannot do (anisotropy without the
samplerAnisotropy feature, past maxSamplerAnisotropy; a LOD bias past maxSamplerLodBias) is clamped and said in
:attr:`MaterialTextures.notes`, which the render report carries.

The rows are checked against the scene first: every texture a drawn material binds must be listed, from the
same source (the scene's path, the glTF pointer, or ``generated``) and with the same neutral sampler state,
so that a build of another scene or an older one is an error, not a wrong picture.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from ..io import ktx2, sha256
from ..lang.errors import UserError

MANIFEST = "manifest.json"
REBUILD = "build the scene into that folder again (`shadermatrix build SCENE --out DIR`)"


@dataclass(frozen=True)
class BuildOutputs:
    """What the renderer reads of a build: its manifest and the folder its paths are relative to."""

    manifest: dict
    root: Path

    @classmethod
    def read(cls, folder) -> "BuildOutputs":
        """The build written into `folder` (its manifest.json)."""
        path = Path(folder) / MANIFEST
        try:
            manifest = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise UserError(f"{path}: no manifest — {REBUILD}") from None
        except (OSError, UnicodeDecodeError, ValueError) as e:
            raise UserError(f"{path}: not a readable manifest ({e}) — {REBUILD}") from None
        if not isinstance(manifest, dict):
            raise UserError(f"{path}: not a manifest (a JSON object) — {REBUILD}")
        return cls(manifest, Path(folder))

    def rows(self, material: str) -> dict:
        """{texture name: row} the manifest lists for `material`."""
        entry = (self.manifest.get("materials") or {}).get(material) or {}
        return entry.get("textures") or {}

    def sampler_state(self, index) -> dict | None:
        """Row `index` of the manifest's samplers in Vulkan's words, or None."""
        rows = self.manifest.get("samplers") or []
        if not isinstance(index, int) or not 0 <= index < len(rows):
            return None
        return ((rows[index] or {}).get("platforms") or {}).get("vulkan")


class MaterialTextures:
    """The images and samplers of the materials a render draws, from `build` (module docstring).

    `bindings`: {material: {texture name: scene/textures.TextureBinding}} of the drawn materials. A render
    whose materials bind no texture needs no build; one whose materials do refuses to draw without it.
    Images and samplers are made on first use and released by :meth:`destroy`.
    """

    def __init__(self, device, build: BuildOutputs | None, bindings: dict):
        self.device, self.build = device, build
        self.bindings = {m: b for m, b in bindings.items() if b}
        self.notes: list[str] = []
        self._images: dict = {}    # artifact path -> Image
        self._samplers: dict = {}  # the state, as sorted items -> Sampler
        if self.bindings and build is None:
            first = next(iter(self.bindings))
            raise UserError(f"material '{first}' binds textures ({', '.join(self.bindings[first])}), and the "
                            "renderer draws them from a build's KTX2 artifacts: none was given — render with "
                            "`shadermatrix render` (it writes them) or pass build= the outputs of `shadermatrix "
                            "build` (runtime/material_textures.BuildOutputs)")
        for m, names in self.bindings.items():
            for name, b in names.items():
                self._check_row(m, name, b)

    # ---------------------------------------------------------------- the manifest's rows

    def _where(self) -> str:
        return str(self.build.root / MANIFEST)

    def _check_row(self, material: str, name: str, b) -> None:
        row = self.build.rows(material).get(name)
        at = f"{self._where()}: materials.{material}.textures.{name}"
        if not isinstance(row, dict):
            raise UserError(f"{self._where()}: material '{material}' lists no texture '{name}', which the scene binds "
                            f"— {REBUILD}")
        missing = [k for k in ("path", "sha256", "format", "width", "height", "levels", "sampler") if k not in row]
        if missing:
            raise UserError(f"{at}: no {', '.join(missing)} — {REBUILD}")
        if row.get("source") != b.source:
            raise UserError(f"{at}: the build's image is {row.get('source')!r}, the scene's {b.source!r} — {REBUILD}")
        state = {k: v for k, v in (row["sampler"] or {}).items() if k != "index"}
        if state != b.sampler.as_dict():
            raise UserError(f"{at}: the build's sampler {state} is not the scene's {b.sampler.as_dict()} — {REBUILD}")
        if self.build.sampler_state(row["sampler"].get("index")) is None:
            raise UserError(f"{at}: sampler index {row['sampler'].get('index')!r} names no row of samplers spelled "
                            "for vulkan — build for the vulkan platform too")

    def row(self, material: str, name: str) -> dict | None:
        """The manifest's row of texture `name` of `material`, or None where the material binds no such image."""
        if name not in self.bindings.get(material, {}):
            return None
        return self.build.rows(material)[name]

    def check_binding(self, material: str, t, ubershader: bool = False) -> None:
        """Texture `t` of a shader this render draws is where the manifest says the build's shader binds it."""
        row = self.row(material, t.param) or {}
        at = row.get("ubershader") if ubershader else row
        if isinstance(at, dict) and "set" in at and (at.get("set"), at.get("binding")) != (t.set, t.binding):
            shader = "the ubershader" if ubershader else "the permutation"
            raise UserError(f"{self._where()}: materials.{material}.textures.{t.param} is at set {at.get('set')}, "
                            f"binding {at.get('binding')} of {shader}; the shader drawn binds it at set {t.set}, "
                            f"binding {t.binding} — {REBUILD}")

    # ---------------------------------------------------------------- GPU objects

    def image(self, material: str, name: str):
        """The Image of texture `name` of `material`: its artifact with every level, uploaded once per file."""
        row = self.build.rows(material)[name]
        if row["path"] not in self._images:
            self._images[row["path"]] = self._upload(row)
        return self._images[row["path"]]

    def _upload(self, row: dict):
        from .images import Image

        path = self.build.root / row["path"]
        try:
            data = path.read_bytes()
        except OSError as e:
            raise UserError(f"{path}: the manifest's texture cannot be read ({e.strerror or e}) — {REBUILD}") from None
        if sha256(data) != row["sha256"]:
            raise UserError(f"{path}: sha256 {sha256(data)[:12]}… is not the manifest's {str(row['sha256'])[:12]}… "
                            f"(the file changed after the build) — {REBUILD}")
        levels, fmt, cube = ktx2.decode_levels(data, str(path))
        h, w = levels[0].shape[-3:-1]
        got = (ktx2.VK_NAMES[fmt], w, h, len(levels))
        want = (row["format"], row["width"], row["height"], row["levels"])
        if got != want:
            raise UserError(f"{path}: the file is {got[0]} {w}x{h}, {len(levels)} levels; the manifest says "
                            f"{want[0]} {want[1]}x{want[2]}, {want[3]} levels — {REBUILD}")
        return Image(self.device, levels[0], srgb=fmt == "srgb8", cube=cube, mips=levels[1:])

    def sampler(self, material: str, name: str):
        """The Sampler of texture `name` of `material`: its manifest state, one Sampler per distinct state."""
        index = self.build.rows(material)[name]["sampler"]["index"]
        return self._sampler(index, self.build.sampler_state(index), f"{material}/{name}")

    def table_sampler(self, name: str):
        """The Sampler of baked table `name`: the state its row of the build's ``tables`` names, or None where no
        build was given or it lists no such table (the renderer's default sampler then: the same state)."""
        if self.build is None:
            return None
        for i, row in enumerate(self.build.manifest.get("tables") or []):
            if isinstance(row, dict) and row.get("texture") == name:
                index = (row.get("sampler") or {}).get("index")
                state = self.build.sampler_state(index)
                if state is None:
                    raise UserError(f"{self._where()}: tables[{i}] ({name}): sampler index {index!r} names no row of "
                                    f"samplers spelled for vulkan — {REBUILD}")
                return self._sampler(index, state, f"table {name}")
        return None

    def _sampler(self, index: int, state: dict, what: str):
        """One Sampler per distinct state (what the device cannot do clamped, said in notes)."""
        from .images import Sampler

        key = tuple(sorted(state.items()))
        if key not in self._samplers:
            s = self._samplers[key] = Sampler(self.device, state)
            self.notes += [f"samplers[{index}] ({what}): {n}" for n in s.notes]
        return self._samplers[key]

    def report(self) -> dict:
        """{material: {texture: {path, levels, sampler}}}: what each drawn material's textures were drawn from."""
        return {m: {n: {"path": self.build.rows(m)[n]["path"], "levels": self.build.rows(m)[n]["levels"],
                        "sampler": self.build.rows(m)[n]["sampler"]["index"]} for n in names}
                for m, names in sorted(self.bindings.items())}

    @property
    def sampler_count(self) -> int:
        return len(self._samplers)

    def destroy(self) -> None:
        for obj in [*self._images.values(), *self._samplers.values()]:
            obj.destroy()
        self._images, self._samplers = {}, {}
