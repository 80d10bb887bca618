"""The intrinsics table: one row per intrinsic, its typing rule and its cost class.

Spellings per target live with each target (generator/backends/*/emit.py), keyed by
the names here, so a new intrinsic is one row here plus one entry per target.

Typing rules (`sig`):
  gen        f(T) -> T                    T a float scalar or vector
  gen2       f(T, T) -> T
  gen3       f(T, T, T) -> T              (clamp, smoothstep)
  mix        f(T, T, T or float) -> T
  minmax     f(T, T) -> T                 T float or int, scalar or vector
  absign     f(T) -> T                    T float or int
  dot        f(vN, vN) -> float
  length     f(vN) -> float
  cross      f(vec3, vec3) -> vec3
  normalize  f(vN) -> vN
  reflect    f(vN, vN) -> vN
  step       f(T, T) -> T
  select     f(bool, T, T) -> T           select(cond, if_true, if_false)
  sample     f(texture2d, vec2) -> vec4       also f(texturecube, vec3 direction) -> vec4,
                                          f(texture2d_array, vec2, int layer) -> vec4 and
                                          f(texturecube_array, vec3, int layer) -> vec4; a layer
                                          (int or uint) is clamped to [0, layers - 1] in every
                                          target: GLSL texture on a sampler2DArray or
                                          samplerCubeArray with the layer as float(layer) in the
                                          last coordinate, HLSL Texture2DArray / TextureCubeArray
                                          Sample with a float3 / float4, WGSL textureSample(t, s,
                                          coord, layer) on a texture_2d_array / texture_cube_array
  sample_lod f(texture2d, vec2, float) -> vec4  also f(texturecube, vec3, float) -> vec4 and the
                                          arrays with int layer before the lod: GLSL textureLod,
                                          HLSL SampleLevel, WGSL textureSampleLevel
  sample_compare f(texture2d_shadow, vec2 uv, float ref) -> float
                                          the hardware depth compare (ref <= stored depth: 1,
                                          else 0) of each texel of the bilinear 2×2 footprint,
                                          weighted by the bilinear weights, at LOD 0 (valid in
                                          non-uniform control flow): GLSL textureLod on a
                                          sampler2DShadow, HLSL SampleCmpLevelZero, WGSL
                                          textureSampleCompareLevel; also f(texture2d_array_shadow,
                                          vec2 uv, int layer, float ref) -> float: GLSL textureGrad
                                          with zero gradients on a sampler2DArrayShadow (GLSL has
                                          no textureLod for it), HLSL SampleCmpLevelZero with a
                                          float3, WGSL textureSampleCompareLevel(t, s, uv, layer,
                                          ref) on a texture_depth_2d_array
  buffer_length f(buffer) -> uint         elements in a storage buffer (run time),
                                          a uniform buffer's capacity (constant)

Where a rule takes T, a float scalar given for a vector T is splatted explicitly
in the IR (clamp(v, 0.0, 1.0) becomes clamp(v, vec3(0.0), vec3(1.0))), because
WGSL has no implicit splat.
"""

INTRINSICS: dict[str, dict] = {
    # name: sig, cost class
    "abs": {"sig": "absign", "cls": "alu"},
    "sign": {"sig": "absign", "cls": "alu"},
    "floor": {"sig": "gen", "cls": "alu"},
    "fract": {"sig": "gen", "cls": "alu"},
    "saturate": {"sig": "gen", "cls": "alu"},
    "sqrt": {"sig": "gen", "cls": "transcendental"},
    "rsqrt": {"sig": "gen", "cls": "transcendental"},
    "exp": {"sig": "gen", "cls": "transcendental"},
    "exp2": {"sig": "gen", "cls": "transcendental"},
    "log": {"sig": "gen", "cls": "transcendental"},
    "log2": {"sig": "gen", "cls": "transcendental"},
    "sin": {"sig": "gen", "cls": "transcendental"},
    "cos": {"sig": "gen", "cls": "transcendental"},
    "tan": {"sig": "gen", "cls": "transcendental"},
    "asin": {"sig": "gen", "cls": "transcendental"},
    "acos": {"sig": "gen", "cls": "transcendental"},
    "atan": {"sig": "gen", "cls": "transcendental"},
    "atan2": {"sig": "gen2", "cls": "transcendental"},
    "pow": {"sig": "gen2", "cls": "transcendental"},
    "step": {"sig": "step", "cls": "alu"},
    "min": {"sig": "minmax", "cls": "alu"},
    "max": {"sig": "minmax", "cls": "alu"},
    "clamp": {"sig": "gen3", "cls": "alu"},
    "smoothstep": {"sig": "gen3", "cls": "alu"},
    "mix": {"sig": "mix", "cls": "alu"},
    "dot": {"sig": "dot", "cls": "alu"},
    "length": {"sig": "length", "cls": "transcendental"},
    "cross": {"sig": "cross", "cls": "alu"},
    "normalize": {"sig": "normalize", "cls": "transcendental"},
    "reflect": {"sig": "reflect", "cls": "alu"},
    "select": {"sig": "select", "cls": "alu"},
    "sample": {"sig": "sample", "cls": "texture"},
    "sample_level": {"sig": "sample_lod", "cls": "texture"},
    "sample_compare": {"sig": "sample_compare", "cls": "texture"},
    "buffer_length": {"sig": "buffer_length", "cls": "alu"},
}

# Named constants usable in every brick (float64 values; emitted with 9+ digits).
CONSTANTS: dict[str, float] = {
    "PI": 3.14159265358979323846,
    "TWO_PI": 6.28318530717958647692,
    "INV_PI": 0.31830988618379067154,
    "INV_TWO_PI": 0.15915494309189533577,
    "HALF_PI": 1.57079632679489661923,
    # Largest finite fp16 value: the saturation limit for mediump results (Filament's MEDIUMP_FLT_MAX).
    "FP16_MAX": 65504.0,
}
