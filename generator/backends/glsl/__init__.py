"""GLSL 4.50 for Vulkan (glslang): the emitter (emit.py: GlslTarget, GlslHalfTarget) and the words a brick identifier is renamed away from
(keywords.py).

Kept free of imports, so that the shared C-like walk can read keywords.py while the emitter that
subclasses it is still being imported."""
