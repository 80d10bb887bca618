"""Words a brick identifier must not be spelled as in GLSL: keywords, reserved words, predeclared type
names and builtin function names (GLSL 4.60 with Vulkan types).

Builtin functions are included because a brick function or local of that name would shadow or overload
the builtin the emitter or a template calls. The C-like back ends rename against the union of every
C-like language's table (clike/reserved.py), so one brick name is spelled the same in all of them.
"""
from __future__ import annotations

from ..clike.words import shapes, words


def _image_types() -> frozenset[str]:
    """GLSL's i/u prefixed texture and image types in every dimension (itexture3D, uimageCubeArray, ...)."""
    dims = ("1D", "2D", "3D", "Cube", "2DRect", "Buffer", "1DArray", "2DArray", "CubeArray", "2DMS", "2DMSArray")
    return frozenset(f"{p}{kind}{d}" for p in ("i", "u") for kind in ("texture", "image") for d in dims)


# GLSL 4.60 §3.6 keywords and reserved words, GL_KHR_vulkan_glsl types, and
# glslang extension type keywords (float16_t, f16vec3, ...).
KEYWORDS = words("""
    const uniform buffer shared attribute varying coherent volatile restrict readonly writeonly
    atomic_uint layout centroid flat smooth noperspective patch sample invariant precise
    break continue do for while switch case default if else subroutine in out inout
    int void bool true false float double uint discard return demote terminateInvocation
    lowp mediump highp precision struct
    mat2 mat3 mat4 dmat2 dmat3 dmat4
    sampler sampler1D sampler2D sampler3D samplerCube sampler2DRect samplerBuffer
    sampler1DShadow sampler2DShadow samplerCubeShadow sampler2DRectShadow samplerShadow
    sampler1DArray sampler2DArray samplerCubeArray sampler1DArrayShadow sampler2DArrayShadow
    samplerCubeArrayShadow sampler2DMS sampler2DMSArray
    isampler1D isampler2D isampler3D isamplerCube isampler2DRect isamplerBuffer isampler1DArray
    isampler2DArray isamplerCubeArray isampler2DMS isampler2DMSArray
    usampler1D usampler2D usampler3D usamplerCube usampler2DRect usamplerBuffer usampler1DArray
    usampler2DArray usamplerCubeArray usampler2DMS usampler2DMSArray
    texture1D texture2D texture3D textureCube texture2DRect textureBuffer texture1DArray
    texture2DArray textureCubeArray texture2DMS texture2DMSArray
    itexture2D utexture2D subpassInput subpassInputMS isubpassInput usubpassInput
    image1D image2D image3D imageCube image2DRect imageBuffer image1DArray image2DArray
    imageCubeArray image2DMS image2DMSArray iimage2D uimage2D
    common partition active asm class union enum typedef template this resource goto
    inline noinline public static extern external interface long short half fixed unsigned
    superp input output filter sizeof cast namespace using sampler3DRect
    float16_t float32_t float64_t int8_t int16_t int32_t int64_t
    uint8_t uint16_t uint32_t uint64_t main
    subpassInputMS isubpassInputMS usubpassInputMS shadercallcoherent pervertexEXT pervertexNV
""") | _image_types() | shapes(("vec", "ivec", "uvec", "bvec", "dvec", "hvec", "fvec", "f16vec", "f32vec",
                "f64vec", "i8vec", "i16vec", "i32vec", "i64vec", "u8vec", "u16vec", "u32vec",
                "u64vec")) | shapes(("mat", "dmat", "f16mat", "f32mat", "f64mat"), matrices=True)

BUILTINS = words("""
    radians degrees sin cos tan asin acos atan sinh cosh tanh asinh acosh atanh
    pow exp log exp2 log2 sqrt inversesqrt abs sign floor trunc round roundEven ceil fract mod
    modf min max clamp mix step smoothstep isnan isinf floatBitsToInt floatBitsToUint
    intBitsToFloat uintBitsToFloat fma frexp ldexp packUnorm2x16 packSnorm2x16 packUnorm4x8
    packSnorm4x8 unpackUnorm2x16 unpackSnorm2x16 unpackUnorm4x8 unpackSnorm4x8 packHalf2x16
    unpackHalf2x16 packDouble2x32 unpackDouble2x32 length distance dot cross normalize
    faceforward reflect refract matrixCompMult outerProduct transpose determinant inverse
    lessThan lessThanEqual greaterThan greaterThanEqual equal notEqual any all not
    uaddCarry usubBorrow umulExtended imulExtended bitfieldExtract bitfieldInsert
    bitfieldReverse bitCount findLSB findMSB
    textureSize textureQueryLod textureQueryLevels textureSamples texture textureProj
    textureLod textureOffset texelFetch texelFetchOffset textureProjOffset textureLodOffset
    textureProjLod textureProjLodOffset textureGrad textureGradOffset textureProjGrad
    textureProjGradOffset textureGather textureGatherOffset textureGatherOffsets
    texture1DLod texture2DLod texture2DProj texture3DLod textureCubeLod shadow2D
    dFdx dFdy dFdxFine dFdyFine dFdxCoarse dFdyCoarse fwidth fwidthFine fwidthCoarse
    interpolateAtCentroid interpolateAtSample interpolateAtOffset noise1 noise2 noise3 noise4
    EmitVertex EndPrimitive EmitStreamVertex EndStreamPrimitive barrier memoryBarrier
    memoryBarrierAtomicCounter memoryBarrierBuffer memoryBarrierShared memoryBarrierImage
    groupMemoryBarrier imageLoad imageStore imageSize imageSamples imageAtomicAdd
    atomicAdd atomicMin atomicMax atomicAnd atomicOr atomicXor atomicExchange atomicCompSwap
    atomicCounter atomicCounterIncrement atomicCounterDecrement subpassLoad
""")

WORDS: frozenset[str] = KEYWORDS | BUILTINS
