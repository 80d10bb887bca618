"""Instruction classes and scalarized operation counts.

Every instruction of an entry point falls in exactly one class (so the class
counts add up to ``instructions``); its *scalarized* count may feed several
classes (``normalize(vec3)`` is 8 ALU operations and 1 transcendental).

Classes: ``alu`` (float and integer arithmetic, dot and matrix products,
conversions, comparisons, logic, selects, min/max/clamp/mix and the other
GLSL.std.450 arithmetic), ``transcendental`` (GLSL.std.450 Pow Exp Exp2 Log
Log2 Sqrt InverseSqrt, the trigonometric and hyperbolic functions, and the
functions that contain a square root: Length, Distance, Normalize, Refract),
``texture`` (samples, fetches, gathers, image reads), ``branch`` (conditional
branches: OpBranchConditional and OpSwitch whose condition or selector is
not a constant), ``load`` and ``store`` (memory; atomics and copies count as
loads), ``other`` (moves and shuffles, composite construct/extract, phis,
access chains, unconditional branches, returns, calls, queries, and loads of
image or sampler handles: descriptors, not data, keyed ``OpLoad(handle)``).

Scalar rules (N = components of the operand vector; a matrix has columns x rows):
component-wise operations count the components of their result (a vec3
FAdd is 3, a bvec3 comparison 3); Dot is N multiplies + N-1 adds = 2N-1;
MatrixTimesVector (C columns, R rows) R(2C-1); VectorTimesMatrix C(2R-1);
MatrixTimesMatrix C2 R (2K-1); Any/All N-1 (at least 1); Cross 9;
Reflect 4N; FaceForward 3N; Fma 2 (a multiply and an add: spirv-opt -O
contracts an FMul feeding an FAdd into Fma, as SPIR-V allows unless
NoContraction, so this keeps scalar counts independent of it); FMix 3;
FClamp 2 (min and max); Step 2 (compare, select); SmoothStep 9; Fract 2;
Length 2N-1 ALU + 1 transcendental, Distance and Normalize 3N-1 + 1,
Refract 6N+6 + 1 (of a scalar, Length and Normalize are abs and sign: 1 ALU,
Distance 2); every other transcendental 1 per component (one operation of
the special-function unit, whatever its microcode). Division is ALU (1 per
component) although hardware does a reciprocal and a multiply. A texture
operation counts 1 however many components it returns; loads and stores
count the 32-bit components they move.
"""
from __future__ import annotations

from .spirv import GLSL_STD_450, Instruction, Module

ALU_OPS = {
    "SNegate", "FNegate", "IAdd", "FAdd", "ISub", "FSub", "IMul", "FMul", "UDiv", "SDiv", "FDiv", "UMod",
    "SRem", "SMod", "FRem", "FMod", "VectorTimesScalar", "MatrixTimesScalar", "OuterProduct",
    "IAddCarry", "ISubBorrow", "UMulExtended", "SMulExtended",
    "ConvertFToU", "ConvertFToS", "ConvertSToF", "ConvertUToF", "UConvert", "SConvert", "FConvert",
    "QuantizeToF16", "IsNan", "IsInf", "IsFinite", "IsNormal", "SignBitSet", "LessOrGreater", "Ordered",
    "Unordered", "LogicalEqual", "LogicalNotEqual", "LogicalOr", "LogicalAnd", "LogicalNot", "Select",
    "IEqual", "INotEqual", "UGreaterThan", "SGreaterThan", "UGreaterThanEqual", "SGreaterThanEqual",
    "ULessThan", "SLessThan", "ULessThanEqual", "SLessThanEqual", "FOrdEqual", "FUnordEqual",
    "FOrdNotEqual", "FUnordNotEqual", "FOrdLessThan", "FUnordLessThan", "FOrdGreaterThan",
    "FUnordGreaterThan", "FOrdLessThanEqual", "FUnordLessThanEqual", "FOrdGreaterThanEqual",
    "FUnordGreaterThanEqual", "ShiftRightLogical", "ShiftRightArithmetic", "ShiftLeftLogical",
    "BitwiseOr", "BitwiseXor", "BitwiseAnd", "Not", "BitFieldInsert", "BitFieldSExtract",
    "BitFieldUExtract", "BitReverse", "BitCount", "DPdx", "DPdy", "Fwidth", "DPdxFine", "DPdyFine",
    "FwidthFine", "DPdxCoarse", "DPdyCoarse", "FwidthCoarse",
    "Dot", "MatrixTimesVector", "VectorTimesMatrix", "MatrixTimesMatrix", "Any", "All",
}
TEXTURE_OPS = {
    "ImageSampleImplicitLod", "ImageSampleExplicitLod", "ImageSampleDrefImplicitLod",
    "ImageSampleDrefExplicitLod", "ImageSampleProjImplicitLod", "ImageSampleProjExplicitLod",
    "ImageSampleProjDrefImplicitLod", "ImageSampleProjDrefExplicitLod", "ImageFetch", "ImageGather",
    "ImageDrefGather", "ImageRead", "ImageSparseSampleImplicitLod", "ImageSparseSampleExplicitLod",
    "ImageSparseSampleDrefImplicitLod", "ImageSparseSampleDrefExplicitLod", "ImageSparseFetch",
    "ImageSparseGather", "ImageSparseDrefGather", "ImageSparseRead",
}
LOAD_OPS = {"Load", "AtomicLoad", "CopyMemory", "CopyMemorySized", "AtomicExchange", "AtomicCompareExchange",
            "AtomicIIncrement", "AtomicIDecrement", "AtomicIAdd", "AtomicISub", "AtomicSMin", "AtomicUMin",
            "AtomicSMax", "AtomicUMax", "AtomicAnd", "AtomicOr", "AtomicXor"}
STORE_OPS = {"Store", "AtomicStore", "ImageWrite"}
NOT_EXECUTED = {"SelectionMerge", "LoopMerge"}  # structure declarations, not instructions

TRANSCENDENTAL_EXT = {"Sin", "Cos", "Tan", "Asin", "Acos", "Atan", "Sinh", "Cosh", "Tanh", "Asinh", "Acosh",
                      "Atanh", "Atan2", "Pow", "Exp", "Log", "Exp2", "Log2", "Sqrt", "InverseSqrt"}
# ALU operations per component for GLSL.std.450 instructions that are not one per component.
EXT_PER_COMPONENT = {"Fma": 2, "FMix": 3, "IMix": 3, "FClamp": 2, "UClamp": 2, "SClamp": 2, "NClamp": 2,
                     "Step": 2, "SmoothStep": 9, "Fract": 2, "Modf": 2, "ModfStruct": 2, "Frexp": 2,
                     "FrexpStruct": 2}
DETERMINANT = {2: 3, 3: 14, 4: 40}      # multiplies and adds of the cofactor expansion
INVERSE = {2: 8, 3: 36, 4: 120}         # adjugate and scaling, rough


def _operand_components(mod: Module, id_: int) -> int:
    return mod.components(mod.value_types.get(id_, 0))


def _matrix_shape(mod: Module, id_: int) -> tuple[int, int]:
    """(columns, rows) of a matrix value."""
    t = mod.types[mod.value_types[id_]]
    return t.args[1], mod.components(t.args[0])


def ext_name(mod: Module, ins: Instruction) -> str | None:
    """The GLSL.std.450 instruction name of an OpExtInst, None for other sets."""
    if mod.ext_imports.get(ins.words[2]) != "GLSL.std.450":
        return None
    return GLSL_STD_450.get(ins.words[3], f"GLSL.std.450#{ins.words[3]}")


def _ext(mod: Module, ins: Instruction, n_res: int) -> tuple[str, dict]:
    """Class and scalar counts of a GLSL.std.450 instruction."""
    name = ext_name(mod, ins)
    args = ins.words[4:]
    n = _operand_components(mod, args[0]) if args else n_res
    if name in TRANSCENDENTAL_EXT:
        return "transcendental", {"transcendental": n_res}
    if name in ("Length", "Distance", "Normalize"):
        if n == 1:
            return "alu", {"alu": 2 if name == "Distance" else 1}
        alu = 2 * n - 1 if name == "Length" else 3 * n - 1
        return "transcendental", {"alu": alu, "transcendental": 1}
    if name == "Refract":
        return "transcendental", {"alu": 6 * n + 6, "transcendental": 1}
    if name == "Cross":
        return "alu", {"alu": 9}
    if name == "Reflect":
        return "alu", {"alu": 4 * n}
    if name == "FaceForward":
        return "alu", {"alu": 3 * n}
    if name == "Determinant":
        return "alu", {"alu": DETERMINANT.get(_matrix_shape(mod, args[0])[0], 40)}
    if name == "MatrixInverse":
        return "alu", {"alu": INVERSE.get(_matrix_shape(mod, args[0])[0], 120)}
    return "alu", {"alu": EXT_PER_COMPONENT.get(name, 1) * max(n_res, 1)}


def _alu_scalars(mod: Module, ins: Instruction, n_res: int) -> int:
    ops = ins.operands
    if ins.name == "Dot":
        return 2 * _operand_components(mod, ops[0]) - 1
    if ins.name in ("Any", "All"):
        return max(_operand_components(mod, ops[0]) - 1, 1)
    if ins.name == "MatrixTimesVector":
        cols, rows = _matrix_shape(mod, ops[0])
        return rows * (2 * cols - 1)
    if ins.name == "VectorTimesMatrix":
        cols, rows = _matrix_shape(mod, ops[1])
        return cols * (2 * rows - 1)
    if ins.name == "MatrixTimesMatrix":
        k = _matrix_shape(mod, ops[0])[0]
        return n_res * (2 * k - 1)
    return n_res


def classify(mod: Module, ins: Instruction) -> tuple[str, str, dict]:
    """(class, histogram key, scalar counts by class) of one instruction inside a function.

    The histogram key is ``Op<name>`` for core instructions and the bare
    GLSL.std.450 name (``Exp``, ``FClamp``) for extended ones.
    """
    n_res = mod.components(ins.type_id) if ins.type_id else 0
    key = "Op" + ins.name
    if ins.name in ALU_OPS:
        return "alu", key, {"alu": _alu_scalars(mod, ins, n_res)}
    if ins.name == "ExtInst":
        name = ext_name(mod, ins)
        if name is None:
            return "other", key, {}
        cls, scalars = _ext(mod, ins, n_res)
        return cls, name, scalars
    if ins.name in TEXTURE_OPS:
        return "texture", key, {"texture": 1}
    if ins.name in ("BranchConditional", "Switch"):
        return ("other" if mod.is_constant(ins.words[0]) else "branch"), key, {}
    if ins.name == "Load" and is_handle(mod, ins.type_id):
        return "other", "OpLoad(handle)", {}
    if ins.name in LOAD_OPS:
        if ins.name.startswith("CopyMemory"):
            width = mod.width(pointee(mod, ins.words[0]))
            return "load", key, {"load": width, "store": width}
        width = mod.width(ins.type_id)
        return "load", key, ({"load": width} if ins.name in ("Load", "AtomicLoad") else {"load": width, "store": width})
    if ins.name in STORE_OPS:
        value = {"Store": 1, "AtomicStore": 3, "ImageWrite": 2}[ins.name]
        return "store", key, {"store": mod.width(mod.value_types.get(ins.words[value], 0))}
    return "other", key, {}


STORAGE_CLASSES = {0: "UniformConstant", 1: "Input", 2: "Uniform", 3: "Output", 4: "Workgroup",
                   5: "CrossWorkgroup", 6: "Private", 7: "Function", 8: "Generic", 9: "PushConstant",
                   10: "AtomicCounter", 11: "Image", 12: "StorageBuffer"}


def is_handle(mod: Module, type_id: int) -> bool:
    """An image, sampler or sampled-image type: a descriptor, not data."""
    t = mod.types.get(type_id)
    return t is not None and t.op in ("TypeImage", "TypeSampler", "TypeSampledImage")


def pointee(mod: Module, pointer: int) -> int:
    """The type a pointer value points to (0 when unknown)."""
    t = mod.types.get(mod.value_types.get(pointer, 0))
    return t.args[1] if t is not None and t.op == "TypePointer" else 0


def storage_class(mod: Module, pointer: int) -> str:
    """The storage class of a pointer value ("Uniform", "Input", ...)."""
    t = mod.types.get(mod.value_types.get(pointer, 0))
    if t is None or t.op != "TypePointer":
        return "unknown"
    return STORAGE_CLASSES.get(t.args[0], f"StorageClass{t.args[0]}")
