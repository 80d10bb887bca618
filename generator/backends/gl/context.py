"""The GL dialects' templates (templates/*.gl.j2, shared by both dialects, with the Vulkan GLSL's macros) and
their part of the template context: the Vulkan GLSL's spelling of built-in types, and an emitter per
program binding its resources OpenGL's way (gl_bindings)."""
from __future__ import annotations

from ..language import Language
from .emit import DIALECTS as _EMITTERS, gl_bindings


class Dialect(Language):
    def target(self, precision: str = "fp32", iface=None):
        """GlTarget or EsslTarget binding `iface`'s blocks and textures; GL's arithmetic stays 32-bit, the
        ES dialect's default precision follows `precision` (emit.py)."""
        if iface is None:
            raise ValueError(f"the {self.name} dialect binds a program's resources: pass its Interface")
        return _EMITTERS[self.name](gl_bindings(iface.blocks, iface.textures), precision)


DIALECTS = {name: Dialect(name, __package__, "gl", imports=("gl/macros.gl.j2", "glsl/macros.glsl.j2"),
                          spelling="glsl") for name in _EMITTERS}  # "gl", "essl"
