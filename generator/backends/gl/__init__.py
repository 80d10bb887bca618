"""The `gl` platform's dialects of GLSL: 4.50 core for OpenGL and ES 3.10 (emit.py: GlTarget, EsslTarget,
gl_bindings), emitted by the Vulkan GLSL walk with OpenGL's binding model.

Kept free of imports, as the language packages are."""
