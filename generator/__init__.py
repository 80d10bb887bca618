"""shadermatrix: compose shading bricks into a shader matrix (HLSL, GLSL, WGSL → SPIR-V)."""
__version__ = "0.1.0"
