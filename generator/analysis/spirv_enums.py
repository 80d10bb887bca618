"""SPIR-V enumerants that reflection reads: execution models and modes, storage classes,
decorations, built-ins, image dimensions and formats, and the pointer operands of instructions."""

MODELS = {0: ("Vertex", "vert"), 1: ("TessellationControl", "tesc"), 2: ("TessellationEvaluation", "tese"),
          3: ("Geometry", "geom"), 4: ("Fragment", "frag"), 5: ("GLCompute", "comp"), 6: ("Kernel", "kernel"),
          5267: ("TaskNV", "task"), 5268: ("MeshNV", "mesh"), 5364: ("TaskEXT", "task"), 5365: ("MeshEXT", "mesh"),
          5313: ("RayGenerationKHR", "rgen"), 5314: ("IntersectionKHR", "rint"), 5315: ("AnyHitKHR", "rahit"),
          5316: ("ClosestHitKHR", "rchit"), 5317: ("MissKHR", "rmiss"), 5318: ("CallableKHR", "rcall")}
EXECUTION_MODES = {7: "OriginUpperLeft", 8: "OriginLowerLeft", 9: "EarlyFragmentTests", 12: "DepthReplacing",
                   14: "DepthGreater", 15: "DepthLess", 16: "DepthUnchanged", 17: "LocalSize",
                   38: "LocalSizeId", 4446: "PostDepthCoverage"}
SC_UNIFORM_CONSTANT, SC_INPUT, SC_UNIFORM, SC_OUTPUT, SC_PUSH_CONSTANT, SC_STORAGE_BUFFER = 0, 1, 2, 3, 9, 12
(D_BLOCK, D_BUFFER_BLOCK, D_ROW_MAJOR, D_COL_MAJOR, D_ARRAY_STRIDE, D_MATRIX_STRIDE, D_BUILTIN) = 2, 3, 4, 5, 6, 7, 11
D_NON_WRITABLE, D_NON_READABLE, D_LOCATION, D_COMPONENT, D_BINDING, D_SET, D_OFFSET = 24, 25, 30, 31, 33, 34, 35
INTERPOLATION = {13: "noperspective", 14: "flat", 15: "patch", 16: "centroid", 17: "sample"}
BUILTINS = {0: "Position", 1: "PointSize", 3: "ClipDistance", 4: "CullDistance", 5: "VertexId", 6: "InstanceId",
            7: "PrimitiveId", 8: "InvocationId", 9: "Layer", 10: "ViewportIndex", 11: "TessLevelOuter",
            12: "TessLevelInner", 13: "TessCoord", 14: "PatchVertices", 15: "FragCoord", 16: "PointCoord",
            17: "FrontFacing", 18: "SampleId", 19: "SamplePosition", 20: "SampleMask", 22: "FragDepth",
            23: "HelperInvocation", 24: "NumWorkgroups", 25: "WorkgroupSize", 26: "WorkgroupId",
            27: "LocalInvocationId", 28: "GlobalInvocationId", 29: "LocalInvocationIndex", 36: "SubgroupSize",
            38: "NumSubgroups", 40: "SubgroupId", 41: "SubgroupLocalInvocationId", 42: "VertexIndex",
            43: "InstanceIndex", 4424: "BaseVertex", 4425: "BaseInstance", 4426: "DrawIndex",
            4438: "DeviceIndex", 4440: "ViewIndex", 5014: "FragStencilRefEXT"}
DIMS = {0: "1d", 1: "2d", 2: "3d", 3: "cube", 4: "rect", 5: "buffer", 6: "subpass"}
FORMATS = dict(enumerate(
    "- rgba32f rgba16f r32f rgba8 rgba8_snorm rg32f rg16f r11f_g11f_b10f r16f rgba16 rgb10_a2 rg16 rg8 r16 r8 "
    "rgba16_snorm rg16_snorm rg8_snorm r16_snorm r8_snorm rgba32i rgba16i rgba8i r32i rg32i rg16i rg8i r16i r8i "
    "rgba32ui rgba16ui rgba8ui r32ui rgb10_a2ui rg32ui rg16ui rg8ui r16ui r8ui r64ui r64i".split()))
OP_ACCELERATION_STRUCTURE = 5341

# Where an instruction inside a function can name a pointer to a global (logical addressing):
# operand positions after the result type/id. Atomics, calls, OpExtInst, OpPhi and unknown
# opcodes are handled in _Reader.references.
POINTER_OPERANDS = {"Load": (0,), "AccessChain": (0,), "InBoundsAccessChain": (0,), "PtrAccessChain": (0,),
                    "InBoundsPtrAccessChain": (0,), "ImageTexelPointer": (0,), "ArrayLength": (0,),
                    "CopyObject": (0,), "Select": (1, 2), "Store": (0,), "CopyMemory": (0, 1),
                    "CopyMemorySized": (0, 1), "AtomicStore": (0,)}
