"""Words a brick identifier must not be spelled as, per C-like target.

Each table is keywords + reserved words + predeclared type names + builtin
function names of one language (GLSL 4.60 with Vulkan types, HLSL as accepted
by FXC/DXC/glslang, WGSL as accepted by naga). Builtin functions are included
because a brick function or local of that name would shadow or overload the
builtin the emitter or a template calls. Every C-like target renames against
`ALL`, so one brick name is spelled the same in GLSL, HLSL and WGSL.
"""
from __future__ import annotations


def _words(text: str) -> frozenset[str]:
    return frozenset(text.split())


def _shapes(prefixes, sizes=(2, 3, 4), matrices=False) -> frozenset[str]:
    out = set()
    for p in prefixes:
        for n in sizes:
            out.add(f"{p}{n}")
            if matrices:
                out.update(f"{p}{n}x{m}" for m in sizes)
    return frozenset(out)


def _image_types() -> frozenset[str]:
    """GLSL's i/u prefixed texture and image types in every dimension (itexture3D, uimageCubeArray, ...)."""
    dims = ("1D", "2D", "3D", "Cube", "2DRect", "Buffer", "1DArray", "2DArray", "CubeArray", "2DMS", "2DMSArray")
    return frozenset(f"{p}{kind}{d}" for p in ("i", "u") for kind in ("texture", "image") for d in dims)


# GLSL 4.60 §3.6 keywords and reserved words, GL_KHR_vulkan_glsl types, and
# glslang extension type keywords (float16_t, f16vec3, ...).
_GLSL_KEYWORDS = _words("""
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
""") | _image_types() | _shapes(("vec", "ivec", "uvec", "bvec", "dvec", "hvec", "fvec", "f16vec", "f32vec",
                "f64vec", "i8vec", "i16vec", "i32vec", "i64vec", "u8vec", "u16vec", "u32vec",
                "u64vec")) | _shapes(("mat", "dmat", "f16mat", "f32mat", "f64mat"), matrices=True)

_GLSL_BUILTINS = _words("""
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

# HLSL keywords and reserved words (FXC and DXC), intrinsics, and the object
# and vector/matrix type names (float3, half4x4, min16float2, ...).
_HLSL_KEYWORDS = _words("""
    AppendStructuredBuffer SubpassInput SubpassInputMS TextureBuffer asm asm_fragment BlendState bool break Buffer ByteAddressBuffer case
    cbuffer centroid class column_major compile compile_fragment CompileShader const continue
    ComputeShader ConsumeStructuredBuffer default DepthStencilState DepthStencilView discard do
    double DomainShader dword else export extern false float for fxgroup GeometryShader
    groupshared half Hullshader HullShader if in inline inout InputPatch int interface line
    lineadj linear LineStream matrix min16float min10float min16int min12int min16uint
    namespace nointerpolation noperspective NULL out OutputPatch packoffset pass pixelfragment
    PixelShader point PointStream precise RasterizerState RenderTargetView return register
    row_major RWBuffer RWByteAddressBuffer RWStructuredBuffer RWTexture1D RWTexture1DArray
    RWTexture2D RWTexture2DArray RWTexture3D sample sampler SamplerState
    SamplerComparisonState shared snorm stateblock stateblock_state static string struct
    switch StructuredBuffer tbuffer technique technique10 technique11 texture Texture1D
    Texture1DArray Texture2D Texture2DArray Texture2DMS Texture2DMSArray Texture3D TextureCube
    TextureCubeArray true typedef triangle triangleadj TriangleStream uint uniform unorm
    unsigned vector vertexfragment VertexShader void volatile while
    auto catch char const_cast delete dynamic_cast enum explicit friend goto long mutable new
    operator private protected public reinterpret_cast short signed sizeof static_cast
    template this throw try typename union using virtual
    center globallycoherent sampler_state indices vertices primitives payload
    sampler1D sampler2D sampler3D samplerCUBE ConstantBuffer RasterizerOrderedBuffer
    float16_t float32_t float64_t int16_t int32_t int64_t uint16_t uint32_t uint64_t
    and or main
""") | _shapes(("float", "half", "double", "int", "uint", "bool", "dword", "min16float",
                "min10float", "min16int", "min12int", "min16uint", "float16_t", "float32_t",
                "int16_t", "uint16_t", "int64_t", "uint64_t"),
               sizes=(1, 2, 3, 4), matrices=True)

_HLSL_BUILTINS = _words("""
    abort abs acos all AllMemoryBarrier AllMemoryBarrierWithGroupSync any asdouble asfloat
    asfloat16 asin asint asint16 asuint asuint16 atan atan2 ceil CheckAccessFullyMapped clamp
    clip cos cosh countbits cross D3DCOLORtoUBYTE4 ddx ddx_coarse ddx_fine ddy ddy_coarse
    ddy_fine degrees determinant DeviceMemoryBarrier DeviceMemoryBarrierWithGroupSync distance
    dot dst errorf EvaluateAttributeCentroid EvaluateAttributeAtSample EvaluateAttributeSnapped
    exp exp2 f16tof32 f32tof16 faceforward firstbithigh firstbitlow floor fma fmod frac frexp
    fwidth GetRenderTargetSampleCount GetRenderTargetSamplePosition GroupMemoryBarrier
    GroupMemoryBarrierWithGroupSync InterlockedAdd InterlockedAnd InterlockedCompareExchange
    InterlockedCompareStore InterlockedExchange InterlockedMax InterlockedMin InterlockedOr
    InterlockedXor isfinite isinf isnan ldexp length lerp lit log log10 log2 mad max min modf
    msad4 mul noise normalize pow printf radians rcp reflect refract reversebits round rsqrt
    saturate select sign sin sincos sinh smoothstep sqrt step tan tanh transpose trunc
    tex1D tex1Dbias tex1Dgrad tex1Dlod tex1Dproj tex2D tex2Dbias tex2Dgrad tex2Dlod tex2Dproj
    tex3D tex3Dbias tex3Dgrad tex3Dlod tex3Dproj texCUBE texCUBEbias texCUBEgrad texCUBElod
    texCUBEproj NonUniformResourceIndex WaveIsFirstLane WaveGetLaneIndex WaveGetLaneCount
    WaveActiveSum WaveActiveMin WaveActiveMax QuadReadAcrossX QuadReadAcrossY IsHelperLane
""")

# WGSL keywords and reserved words (spec §15.1-15.2, as naga enforces them),
# predeclared types and aliases, and builtin functions.
_WGSL_KEYWORDS = _words("""
    array atomic bool f32 f16 i32 i64 u32 u64 ptr sampler sampler_comparison
    texture_1d texture_2d texture_2d_array texture_3d texture_cube texture_cube_array
    texture_multisampled_2d texture_storage_1d texture_storage_2d texture_storage_2d_array
    texture_storage_3d texture_depth_2d texture_depth_2d_array texture_depth_cube
    texture_depth_cube_array texture_depth_multisampled_2d texture_external binding_array
    alias bitcast break case const const_assert continue continuing default diagnostic discard
    else enable false fn for if let loop override requires return static_assert struct switch
    true type var while
    CompileShader ComputeShader DomainShader GeometryShader Hullshader NULL Self abstract
    active alignas alignof as asm asm_fragment async attribute auto await become cast catch
    class co_await co_return co_yield coherent column_major common compile compile_fragment
    concept const_cast consteval constexpr constinit crate debugger decltype delete demote
    demote_to_helper do dynamic_cast enum explicit export extends extern external fallthrough
    filter final finally friend from fxgroup get goto groupshared handle highp impl implements
    import inline inout instanceof interface layout lowp macro macro_rules match mediump meta
    mod module move mut mutable namespace new nil noexcept noinline nointerpolation
    noperspective null nullptr of operator package packoffset partition pass patch
    pixelfragment precise precision premerge priv protected pub public readonly ref regardless
    register reinterpret_cast resource restrict self set shared signed sizeof smooth snorm
    static static_cast std subroutine super target template this thread_local throw trait try
    typedef typeid typename typeof union unless unorm unsafe unsized use using varying virtual
    volatile wgsl where with writeonly yield
""") | _shapes(("vec",)) | _shapes(("mat",), matrices=True) | frozenset(
    f"vec{n}{s}" for n in (2, 3, 4) for s in "fhiu") | frozenset(
    f"mat{c}x{r}{s}" for c in (2, 3, 4) for r in (2, 3, 4) for s in "fh")

_WGSL_BUILTINS = _words("""
    abs acos acosh all any arrayLength asin asinh atan atanh atan2 ceil clamp cos cosh
    countLeadingZeros countOneBits countTrailingZeros cross degrees determinant distance dot
    dot4U8Packed dot4I8Packed exp exp2 extractBits faceForward firstLeadingBit firstTrailingBit
    floor fma fract frexp insertBits inverseSqrt ldexp length log log2 max min mix modf
    normalize pow quantizeToF16 radians reflect refract reverseBits round saturate select sign
    sin sinh smoothstep sqrt step tan tanh transpose trunc
    pack4x8snorm pack4x8unorm pack2x16snorm pack2x16unorm pack2x16float unpack4x8snorm
    unpack4x8unorm unpack2x16snorm unpack2x16unorm unpack2x16float
    dpdx dpdxCoarse dpdxFine dpdy dpdyCoarse dpdyFine fwidth fwidthCoarse fwidthFine
    textureDimensions textureGather textureGatherCompare textureLoad textureNumLayers
    textureNumLevels textureNumSamples textureSample textureSampleBias textureSampleCompare
    textureSampleCompareLevel textureSampleGrad textureSampleLevel textureSampleBaseClampToEdge
    textureStore atomicLoad atomicStore atomicAdd atomicSub atomicMax atomicMin atomicAnd
    atomicOr atomicXor atomicExchange atomicCompareExchangeWeak storageBarrier
    workgroupBarrier textureBarrier workgroupUniformLoad main
""")

GLSL: frozenset[str] = _GLSL_KEYWORDS | _GLSL_BUILTINS
HLSL: frozenset[str] = _HLSL_KEYWORDS | _HLSL_BUILTINS
WGSL: frozenset[str] = _WGSL_KEYWORDS | _WGSL_BUILTINS
ALL: frozenset[str] = GLSL | HLSL | WGSL

# GLSL reserves every identifier that starts with this prefix.
RESERVED_PREFIXES: tuple[str, ...] = ("gl_",)
# A reserved brick identifier is spelled with this prefix in every target. Brick
# identifiers never start with '_' (generator/lang/exprs.py), so a renamed name
# cannot meet a brick's own name; the same holds for SAMPLER_PREFIX.
PREFIX = "_r_"
SAMPLER_PREFIX = "_smp_"
# Generated names for buffers: the GLSL block / HLSL cbuffer of buffer NAME, and
# HLSL's length helper of a storage buffer (see clike_resources.py).
BLOCK_PREFIX = "_blk_"
LENGTH_PREFIX = "_len_"
