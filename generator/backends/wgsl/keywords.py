"""Words a brick identifier must not be spelled as in WGSL: keywords, reserved words, predeclared type
names and builtin function names (WGSL as accepted by naga).

Builtin functions are included because a brick function or local of that name would shadow or overload
the builtin the emitter or a template calls. The C-like back ends rename against the union of every
C-like language's table (clike/reserved.py), so one brick name is spelled the same in all of them.
"""
from __future__ import annotations

from ..clike.words import shapes, words


# WGSL keywords and reserved words (spec §15.1-15.2, as naga enforces them),
# predeclared types and aliases, and builtin functions.
KEYWORDS = words("""
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
""") | shapes(("vec",)) | shapes(("mat",), matrices=True) | frozenset(
    f"vec{n}{s}" for n in (2, 3, 4) for s in "fhiu") | frozenset(
    f"mat{c}x{r}{s}" for c in (2, 3, 4) for r in (2, 3, 4) for s in "fh")

BUILTINS = words("""
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

WORDS: frozenset[str] = KEYWORDS | BUILTINS
