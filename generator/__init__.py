"""shadermatrix: compose shading bricks into a shader matrix (HLSL, GLSL, WGSL → SPIR-V)."""
__version__ = "0.1.0"

# Targets and dtypes of evaluate(), here so that the CLI's argument parser reads them without
# importing generator.eval (numpy, jinja2, the emitters).
EVAL_TARGETS = ("reference", "numpy", "glsl", "hlsl", "wgsl")  # what evaluate() runs on (backends.TARGETS: the emitters)
GPU_TARGETS = ("glsl", "hlsl", "wgsl")
DTYPES = ("float64", "float32", "float16")


def evaluate(spec, L, V, N, T=None, params=None, target="reference", dtype=None, lib=None, textures=None,
             session=None):
    """f_r (N, 3) float64 of a BRDF spec on samples; see generator.eval.evaluate.evaluate (session: the
    generator.runtime.eval_kernel.EvalSession a GPU target runs on; None: one for this call alone)."""
    from .eval.evaluate import evaluate as _evaluate  # lazy: numpy and the targets load on first use
    return _evaluate(spec, L, V, N, T=T, params=params, target=target, dtype=dtype, lib=lib, textures=textures,
                     session=session)
