"""shadermatrix: compose shading bricks into a shader matrix (HLSL, GLSL, WGSL → SPIR-V)."""
__version__ = "0.1.0"


def evaluate(spec, L, V, N, T=None, params=None, target="reference", dtype=None, lib=None):
    """f_r (N, 3) float64 of a BRDF spec on samples; see generator.evaluate.evaluate."""
    from .evaluate import evaluate as _evaluate  # lazy: numpy and the targets load on first use
    return _evaluate(spec, L, V, N, T=T, params=params, target=target, dtype=dtype, lib=lib)
