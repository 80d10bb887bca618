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

from .spirv import GLSL_STD_450, OPCODES, Instruction, Module

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
    name = GLSL_STD_450.get(ins.words[3])
    return name if name is not None else f"GLSL.std.450#{ins.words[3]}"


# The rule _ext() takes for a GLSL.std.450 name whose figures depend on its operand or are fixed.
_E_LENGTH, _E_REFRACT, _E_CROSS, _E_REFLECT, _E_FACEFORWARD, _E_DETERMINANT, _E_INVERSE = range(1, 8)
_EXT_RULE = {**dict.fromkeys(("Length", "Distance", "Normalize"), _E_LENGTH), "Refract": _E_REFRACT,
             "Cross": _E_CROSS, "Reflect": _E_REFLECT, "FaceForward": _E_FACEFORWARD,
             "Determinant": _E_DETERMINANT, "MatrixInverse": _E_INVERSE}
# The other names: their figures follow from the result's components n alone, (class, a, t) for
# a * max(n, 1) ALU operations and t * n transcendental ones.
_EXT_BY_RESULT = {n: ("transcendental", 0, 1) if n in TRANSCENDENTAL_EXT else ("alu", EXT_PER_COMPONENT.get(n, 1), 0)
                  for n in GLSL_STD_450.values() if n not in _EXT_RULE}
# by instruction number, for count_rows
_EXT_NUMBER_BY_RESULT = {number: (name, *_EXT_BY_RESULT[name])
                         for number, name in GLSL_STD_450.items() if name in _EXT_BY_RESULT}


def _ext(mod: Module, ins: Instruction, name: str, n_res: int) -> tuple[str, int, int]:
    """Class, ALU and transcendental counts of a GLSL.std.450 instruction."""
    rule = _EXT_RULE.get(name)
    if rule is None:  # one of _EXT_BY_RESULT, or an instruction number without a name
        cls, a, t = _EXT_BY_RESULT.get(name, ("alu", 1, 0))
        return cls, a * max(n_res, 1), t * n_res
    args = ins.words[4:]
    if rule == _E_CROSS:
        return "alu", 9, 0
    if rule == _E_DETERMINANT:
        return "alu", DETERMINANT.get(_matrix_shape(mod, args[0])[0], 40), 0
    if rule == _E_INVERSE:
        return "alu", INVERSE.get(_matrix_shape(mod, args[0])[0], 120), 0
    n = _operand_components(mod, args[0]) if args else n_res
    if rule == _E_LENGTH:
        if n == 1:
            return "alu", 2 if name == "Distance" else 1, 0
        alu = 2 * n - 1 if name == "Length" else 3 * n - 1
        return "transcendental", alu, 1
    if rule == _E_REFRACT:
        return "transcendental", 6 * n + 6, 1
    if rule == _E_REFLECT:
        return "alu", 4 * n, 0
    return "alu", 3 * n, 0  # FaceForward


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


# Which rule of counts() an instruction name takes (the sets above are disjoint); "other" when absent.
_ALU, _ALU_SHAPED, _EXT, _TEXTURE, _BRANCH, _LOAD, _STORE = range(1, 8)
_RULE = {**dict.fromkeys(ALU_OPS, _ALU),
         **dict.fromkeys(("Dot", "Any", "All", "MatrixTimesVector", "VectorTimesMatrix", "MatrixTimesMatrix"),
                         _ALU_SHAPED),
         "ExtInst": _EXT, **dict.fromkeys(TEXTURE_OPS, _TEXTURE), "BranchConditional": _BRANCH, "Switch": _BRANCH,
         **dict.fromkeys(LOAD_OPS, _LOAD), **dict.fromkeys(STORE_OPS, _STORE)}
_STORED_VALUE = {"Store": 1, "AtomicStore": 3, "ImageWrite": 2}   # operand word holding the value stored


def _fixed(name: str) -> tuple | None:
    """counts() of an instruction whose figures are its name's alone (others, textures), else None."""
    rule = _RULE.get(name)
    if rule is None:
        return "other", "Op" + name, 0, 0, 0, 0
    return ("texture", "Op" + name, 0, 0, 0, 0) if rule == _TEXTURE else None


# counts() of the instructions whose figures are their name's alone, by name (structure declarations left out)
FIXED_COUNTS = {n: f for n in OPCODES.values() if (f := _fixed(n)) is not None and n not in NOT_EXECUTED}
_RULE_KEY = {n: (rule, "Op" + n) for n, rule in _RULE.items() if rule != _TEXTURE}


def counts(mod: Module, ins: Instruction) -> tuple[str, str, int, int, int, int]:
    """(class, histogram key, ALU, transcendental, load and store scalar counts) of one instruction inside
    a function: the figures of :func:`classify` as plain numbers (the cost analysis sums them for every
    instruction, without a dict for each)."""
    name = ins.name
    fixed = FIXED_COUNTS.get(name)
    if fixed is not None:
        return fixed
    rk = _RULE_KEY.get(name)
    if rk is None:  # an opcode without a name ("Op<number>")
        return _fixed(name)
    rule, key = rk
    type_id = ins.type_id
    if rule == _ALU:
        return "alu", key, mod.type_components[type_id] if type_id else 0, 0, 0, 0
    if rule == _ALU_SHAPED:
        return "alu", key, _alu_scalars(mod, ins, mod.type_components[type_id] if type_id else 0), 0, 0, 0
    if rule == _EXT:
        ext = ext_name(mod, ins)
        if ext is None:
            return "other", key, 0, 0, 0, 0
        cls, alu, transcendental = _ext(mod, ins, ext, mod.type_components[type_id] if type_id else 0)
        return cls, ext, alu, transcendental, 0, 0
    if rule == _BRANCH:
        return ("other" if mod.is_constant(ins.words[0]) else "branch"), key, 0, 0, 0, 0
    if rule == _LOAD:
        if name == "Load" and is_handle(mod, type_id):
            return "other", "OpLoad(handle)", 0, 0, 0, 0
        if name.startswith("CopyMemory"):
            width = mod.width(pointee(mod, ins.words[0]))
            return "load", key, 0, 0, width, width
        width = mod.width(type_id)
        return "load", key, 0, 0, width, (0 if name in ("Load", "AtomicLoad") else width)
    return "store", key, 0, 0, 0, mod.width(mod.value_types.get(ins.words[_STORED_VALUE[name]], 0))


_ALU_KEYS = {n: key for n, (rule, key) in _RULE_KEY.items() if rule == _ALU}


def count_rows(mod: Module, body: list[Instruction]) -> list[tuple[str, str, int, int, int, int]]:
    """:func:`counts` of each instruction, in order; the commonest kinds (an instruction whose figures are its
    name's, a component-wise ALU operation, a GLSL.std.450 one whose figures follow from its result) without
    a call each."""
    fixed, alu, components = FIXED_COUNTS, _ALU_KEYS, mod.type_components
    by_result = _EXT_NUMBER_BY_RESULT
    glsl = {i for i, name in mod.ext_imports.items() if name == "GLSL.std.450"}
    rows = []
    for ins in body:
        name = ins.name
        row = fixed.get(name)
        if row is None:
            key = alu.get(name)
            if key is not None:
                type_id = ins.type_id
                row = "alu", key, components[type_id] if type_id else 0, 0, 0, 0
            elif name == "ExtInst" and ins.words[2] in glsl and (ext := by_result.get(ins.words[3])) is not None:
                type_id = ins.type_id
                n = components[type_id] if type_id else 0
                ext_key, cls, a, t = ext
                row = cls, ext_key, a * (n if n > 1 else 1), t * n, 0, 0
            else:
                row = counts(mod, ins)
        rows.append(row)
    return rows


_SCALAR_CLASSES = ("alu", "transcendental", "load", "store")


def classify(mod: Module, ins: Instruction) -> tuple[str, str, dict]:
    """(class, histogram key, scalar counts by class) of one instruction inside a function (zero counts left
    out; a texture operation counts 1 texture).

    The histogram key is ``Op<name>`` for core instructions and the bare
    GLSL.std.450 name (``Exp``, ``FClamp``) for extended ones.
    """
    cls, key, *scalars = counts(mod, ins)
    out = {c: n for c, n in zip(_SCALAR_CLASSES, scalars) if n}
    if cls == "texture":
        out["texture"] = 1
    return cls, key, out


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
