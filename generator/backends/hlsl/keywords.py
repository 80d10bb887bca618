"""Words a brick identifier must not be spelled as in HLSL: keywords, reserved words, predeclared type
names and builtin function names (HLSL as accepted by FXC, DXC and glslang).

Builtin functions are included because a brick function or local of that name would shadow or overload
the builtin the emitter or a template calls. The C-like back ends rename against the union of every
C-like language's table (clike/reserved.py), so one brick name is spelled the same in all of them.
"""
from __future__ import annotations

from ..clike.words import shapes, words


# HLSL keywords and reserved words (FXC and DXC), intrinsics, and the object
# and vector/matrix type names (float3, half4x4, min16float2, ...).
KEYWORDS = words("""
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
""") | shapes(("float", "half", "double", "int", "uint", "bool", "dword", "min16float",
                "min10float", "min16int", "min12int", "min16uint", "float16_t", "float32_t",
                "int16_t", "uint16_t", "int64_t", "uint64_t"),
               sizes=(1, 2, 3, 4), matrices=True)

BUILTINS = words("""
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

WORDS: frozenset[str] = KEYWORDS | BUILTINS
