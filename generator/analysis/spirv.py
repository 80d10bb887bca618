"""A SPIR-V binary reader: header, instructions by opcode and word count, functions and blocks.

It reads the module's 32-bit words (never disassembly text) and keeps only
what the cost analysis needs: names, types (for scalar widths), constants,
global variables, extended-instruction imports, entry points and, per
function, its basic blocks in order. Opcode numbers are those of the SPIR-V
1.6 unified grammar (the subset a shader compiler emits; any other opcode
keeps the name ``Op<number>`` and is still counted).
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field

MAGIC = 0x07230203

OPCODES = {
    0: "Nop", 1: "Undef", 2: "SourceContinued", 3: "Source", 4: "SourceExtension", 5: "Name",
    6: "MemberName", 7: "String", 8: "Line", 10: "Extension", 11: "ExtInstImport", 12: "ExtInst",
    14: "MemoryModel", 15: "EntryPoint", 16: "ExecutionMode", 17: "Capability",
    19: "TypeVoid", 20: "TypeBool", 21: "TypeInt", 22: "TypeFloat", 23: "TypeVector", 24: "TypeMatrix",
    25: "TypeImage", 26: "TypeSampler", 27: "TypeSampledImage", 28: "TypeArray", 29: "TypeRuntimeArray",
    30: "TypeStruct", 31: "TypeOpaque", 32: "TypePointer", 33: "TypeFunction", 39: "TypeForwardPointer",
    41: "ConstantTrue", 42: "ConstantFalse", 43: "Constant", 44: "ConstantComposite", 45: "ConstantSampler",
    46: "ConstantNull", 48: "SpecConstantTrue", 49: "SpecConstantFalse", 50: "SpecConstant",
    51: "SpecConstantComposite", 52: "SpecConstantOp",
    54: "Function", 55: "FunctionParameter", 56: "FunctionEnd", 57: "FunctionCall", 59: "Variable",
    60: "ImageTexelPointer", 61: "Load", 62: "Store", 63: "CopyMemory", 64: "CopyMemorySized",
    65: "AccessChain", 66: "InBoundsAccessChain", 67: "PtrAccessChain", 68: "ArrayLength",
    70: "InBoundsPtrAccessChain", 71: "Decorate", 72: "MemberDecorate", 73: "DecorationGroup",
    74: "GroupDecorate", 75: "GroupMemberDecorate", 77: "VectorExtractDynamic", 78: "VectorInsertDynamic",
    79: "VectorShuffle", 80: "CompositeConstruct", 81: "CompositeExtract", 82: "CompositeInsert",
    83: "CopyObject", 84: "Transpose", 86: "SampledImage",
    87: "ImageSampleImplicitLod", 88: "ImageSampleExplicitLod", 89: "ImageSampleDrefImplicitLod",
    90: "ImageSampleDrefExplicitLod", 91: "ImageSampleProjImplicitLod", 92: "ImageSampleProjExplicitLod",
    93: "ImageSampleProjDrefImplicitLod", 94: "ImageSampleProjDrefExplicitLod", 95: "ImageFetch",
    96: "ImageGather", 97: "ImageDrefGather", 98: "ImageRead", 99: "ImageWrite", 100: "Image",
    101: "ImageQueryFormat", 102: "ImageQueryOrder", 103: "ImageQuerySizeLod", 104: "ImageQuerySize",
    105: "ImageQueryLod", 106: "ImageQueryLevels", 107: "ImageQuerySamples",
    109: "ConvertFToU", 110: "ConvertFToS", 111: "ConvertSToF", 112: "ConvertUToF", 113: "UConvert",
    114: "SConvert", 115: "FConvert", 116: "QuantizeToF16", 124: "Bitcast",
    126: "SNegate", 127: "FNegate", 128: "IAdd", 129: "FAdd", 130: "ISub", 131: "FSub", 132: "IMul",
    133: "FMul", 134: "UDiv", 135: "SDiv", 136: "FDiv", 137: "UMod", 138: "SRem", 139: "SMod",
    140: "FRem", 141: "FMod", 142: "VectorTimesScalar", 143: "MatrixTimesScalar", 144: "VectorTimesMatrix",
    145: "MatrixTimesVector", 146: "MatrixTimesMatrix", 147: "OuterProduct", 148: "Dot",
    149: "IAddCarry", 150: "ISubBorrow", 151: "UMulExtended", 152: "SMulExtended",
    154: "Any", 155: "All", 156: "IsNan", 157: "IsInf", 158: "IsFinite", 159: "IsNormal",
    160: "SignBitSet", 161: "LessOrGreater", 162: "Ordered", 163: "Unordered",
    164: "LogicalEqual", 165: "LogicalNotEqual", 166: "LogicalOr", 167: "LogicalAnd", 168: "LogicalNot",
    169: "Select", 170: "IEqual", 171: "INotEqual", 172: "UGreaterThan", 173: "SGreaterThan",
    174: "UGreaterThanEqual", 175: "SGreaterThanEqual", 176: "ULessThan", 177: "SLessThan",
    178: "ULessThanEqual", 179: "SLessThanEqual", 180: "FOrdEqual", 181: "FUnordEqual",
    182: "FOrdNotEqual", 183: "FUnordNotEqual", 184: "FOrdLessThan", 185: "FUnordLessThan",
    186: "FOrdGreaterThan", 187: "FUnordGreaterThan", 188: "FOrdLessThanEqual",
    189: "FUnordLessThanEqual", 190: "FOrdGreaterThanEqual", 191: "FUnordGreaterThanEqual",
    194: "ShiftRightLogical", 195: "ShiftRightArithmetic", 196: "ShiftLeftLogical", 197: "BitwiseOr",
    198: "BitwiseXor", 199: "BitwiseAnd", 200: "Not", 201: "BitFieldInsert", 202: "BitFieldSExtract",
    203: "BitFieldUExtract", 204: "BitReverse", 205: "BitCount",
    207: "DPdx", 208: "DPdy", 209: "Fwidth", 210: "DPdxFine", 211: "DPdyFine", 212: "FwidthFine",
    213: "DPdxCoarse", 214: "DPdyCoarse", 215: "FwidthCoarse",
    224: "ControlBarrier", 225: "MemoryBarrier", 227: "AtomicLoad", 228: "AtomicStore",
    229: "AtomicExchange", 230: "AtomicCompareExchange", 232: "AtomicIIncrement",
    233: "AtomicIDecrement", 234: "AtomicIAdd", 235: "AtomicISub", 236: "AtomicSMin", 237: "AtomicUMin",
    238: "AtomicSMax", 239: "AtomicUMax", 240: "AtomicAnd", 241: "AtomicOr", 242: "AtomicXor",
    245: "Phi", 246: "LoopMerge", 247: "SelectionMerge", 248: "Label", 249: "Branch",
    250: "BranchConditional", 251: "Switch", 252: "Kill", 253: "Return", 254: "ReturnValue",
    255: "Unreachable",
    305: "ImageSparseSampleImplicitLod", 306: "ImageSparseSampleExplicitLod",
    307: "ImageSparseSampleDrefImplicitLod", 308: "ImageSparseSampleDrefExplicitLod",
    313: "ImageSparseFetch", 314: "ImageSparseGather", 315: "ImageSparseDrefGather",
    316: "ImageSparseTexelsResident", 317: "NoLine", 320: "ImageSparseRead", 330: "ModuleProcessed",
    331: "ExecutionModeId", 332: "DecorateId", 400: "CopyLogical",
    4416: "TerminateInvocation", 5380: "DemoteToHelperInvocation", 5632: "DecorateString",
    5633: "MemberDecorateString",
}

GLSL_STD_450 = {
    1: "Round", 2: "RoundEven", 3: "Trunc", 4: "FAbs", 5: "SAbs", 6: "FSign", 7: "SSign", 8: "Floor",
    9: "Ceil", 10: "Fract", 11: "Radians", 12: "Degrees", 13: "Sin", 14: "Cos", 15: "Tan", 16: "Asin",
    17: "Acos", 18: "Atan", 19: "Sinh", 20: "Cosh", 21: "Tanh", 22: "Asinh", 23: "Acosh", 24: "Atanh",
    25: "Atan2", 26: "Pow", 27: "Exp", 28: "Log", 29: "Exp2", 30: "Log2", 31: "Sqrt", 32: "InverseSqrt",
    33: "Determinant", 34: "MatrixInverse", 35: "Modf", 36: "ModfStruct", 37: "FMin", 38: "UMin",
    39: "SMin", 40: "FMax", 41: "UMax", 42: "SMax", 43: "FClamp", 44: "UClamp", 45: "SClamp",
    46: "FMix", 47: "IMix", 48: "Step", 49: "SmoothStep", 50: "Fma", 51: "Frexp", 52: "FrexpStruct",
    53: "Ldexp", 54: "PackSnorm4x8", 55: "PackUnorm4x8", 56: "PackSnorm2x16", 57: "PackUnorm2x16",
    58: "PackHalf2x16", 59: "PackDouble2x32", 60: "UnpackSnorm2x16", 61: "UnpackUnorm2x16",
    62: "UnpackHalf2x16", 63: "UnpackSnorm4x8", 64: "UnpackUnorm4x8", 65: "UnpackDouble2x32",
    66: "Length", 67: "Distance", 68: "Cross", 69: "Normalize", 70: "FaceForward", 71: "Reflect",
    72: "Refract", 73: "FindILsb", 74: "FindSMsb", 75: "FindUMsb", 76: "InterpolateAtCentroid",
    77: "InterpolateAtSample", 78: "InterpolateAtOffset", 79: "NMin", 80: "NMax", 81: "NClamp",
}

# Opcodes whose first two operands are <result type> <result id>. Instructions
# outside functions with a result but no type (types, labels, imports) are
# listed in RESULT_ONLY.
RESULT_ONLY = {"ExtInstImport", "String", "Label", "DecorationGroup"} | {n for n in OPCODES.values() if n.startswith("Type")}
NO_RESULT = {
    "Nop", "SourceContinued", "Source", "SourceExtension", "Name", "MemberName", "Line", "Extension",
    "MemoryModel", "EntryPoint", "ExecutionMode", "Capability", "TypeForwardPointer", "FunctionEnd", "Store",
    "CopyMemory", "CopyMemorySized", "Decorate", "MemberDecorate", "GroupDecorate", "GroupMemberDecorate",
    "ImageWrite", "ControlBarrier", "MemoryBarrier", "AtomicStore", "LoopMerge", "SelectionMerge", "Branch",
    "BranchConditional", "Switch", "Kill", "Return", "ReturnValue", "Unreachable", "NoLine",
    "ModuleProcessed", "ExecutionModeId", "DecorateId", "TerminateInvocation", "DemoteToHelperInvocation",
    "DecorateString", "MemberDecorateString",
}


class SpirvError(ValueError):
    """The bytes are not a well-formed SPIR-V module."""


class Instruction:
    """One instruction: opcode, name, operand words, result type and id (0 when none).

    A plain class with slots, its operands sliced once when made: the cost
    analysis reads them several times for each of a module's instructions."""

    __slots__ = ("opcode", "name", "words", "type_id", "result", "operands")

    def __init__(self, opcode: int, name: str, words: tuple, type_id: int = 0, result: int = 0):
        self.opcode = opcode
        self.name = name          # "FAdd", not "OpFAdd"; "Op<number>" when unknown
        self.words = words        # operand words (the opcode/word-count word excluded)
        self.type_id = type_id    # result type, 0 when none
        self.result = result      # result id, 0 when none
        # operand words after the result type and id
        self.operands = words[(1 if type_id else 0) + (1 if result else 0):]

    def _key(self) -> tuple:
        return self.opcode, self.name, self.words, self.type_id, self.result

    def __eq__(self, other) -> bool:
        return self._key() == other._key() if type(other) is Instruction else NotImplemented

    def __repr__(self) -> str:
        return (f"Instruction(opcode={self.opcode!r}, name={self.name!r}, words={self.words!r}, "
                f"type_id={self.type_id!r}, result={self.result!r})")


@dataclass
class Block:
    label: int
    body: list[Instruction] = field(default_factory=list)  # includes OpPhi and the terminator

    @property
    def terminator(self) -> Instruction:
        return self.body[-1]


@dataclass
class Function:
    id: int
    type_id: int
    params: list[Instruction] = field(default_factory=list)
    blocks: list[Block] = field(default_factory=list)


@dataclass
class Type:
    """A SPIR-V type reduced to what widths need."""

    op: str                       # "TypeFloat", "TypeVector", ...
    args: tuple                   # operand words after the result id


class _ByType(dict):
    """A property of types by type id, worked out on first use and kept. It holds the module's types and
    constants, not the module: no cycle keeps a module alive after its last use."""

    __slots__ = ("types", "constants", "rule")

    def __init__(self, types: dict, constants: dict, rule):
        super().__init__()
        self.types, self.constants, self.rule = types, constants, rule

    def __missing__(self, type_id: int) -> int:
        value = self[type_id] = self.rule(self, type_id)
        return value


def _width(memo: _ByType, type_id: int) -> int:
    t = memo.types.get(type_id)
    if t is None:
        return 0
    if t.op in ("TypeFloat", "TypeInt"):
        return 2 if t.args[0] == 64 else 1
    if t.op == "TypeBool":
        return 1
    if t.op == "TypeVector":
        return memo[t.args[0]] * t.args[1]
    if t.op == "TypeMatrix":
        return memo[t.args[0]] * t.args[1]
    if t.op == "TypeStruct":
        return sum(memo[m] for m in t.args)
    if t.op == "TypeArray":
        length = memo.constants.get(t.args[1])
        return memo[t.args[0]] * (length.operands[0] if length and length.name == "Constant" else 1)
    return 0


def _components(memo: _ByType, type_id: int) -> int:
    t = memo.types.get(type_id)
    if t is None:
        return 0
    if t.op == "TypeVector":
        return t.args[1]
    if t.op == "TypeMatrix":
        return memo[t.args[0]] * t.args[1]
    return 1 if t.op in ("TypeFloat", "TypeInt", "TypeBool") else 0


@dataclass
class Module:
    version: tuple[int, int]
    bound: int
    names: dict[int, str] = field(default_factory=dict)
    types: dict[int, Type] = field(default_factory=dict)
    constants: dict[int, Instruction] = field(default_factory=dict)   # incl. spec constants and OpUndef
    globals: dict[int, Instruction] = field(default_factory=dict)     # module-scope OpVariable
    ext_imports: dict[int, str] = field(default_factory=dict)
    entry_points: dict[str, tuple[str, int]] = field(default_factory=dict)  # name -> (model, function id)
    functions: dict[int, Function] = field(default_factory=dict)
    value_types: dict[int, int] = field(default_factory=dict)        # any result id -> its type id
    # width() and components() by type id, each worked out on first use (the analysis asks for every value's)
    type_widths: dict[int, int] = field(init=False, repr=False, compare=False)
    type_components: dict[int, int] = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        self.type_widths = _ByType(self.types, self.constants, _width)
        self.type_components = _ByType(self.types, self.constants, _components)

    def name(self, id_: int) -> str:
        """The debug name of an id (OpName) or ``%<id>``."""
        return self.names.get(id_) or f"%{id_}"

    def width(self, type_id: int) -> int:
        """32-bit scalar components of a value of this type (0 for pointers and opaque handles)."""
        return self.type_widths[type_id]

    def components(self, type_id: int) -> int:
        """Scalar components of a type (a vec3 has 3, a mat4 16), ignoring bit width."""
        return self.type_components[type_id]

    def is_constant(self, id_: int) -> bool:
        return id_ in self.constants


def _string(words) -> str:
    raw = struct.pack(f"<{len(words)}I", *words)
    return raw.split(b"\0", 1)[0].decode("utf-8", errors="replace")


def _string_words(words) -> int:
    """How many words a nul-terminated literal string occupies at the start of `words`."""
    for i, w in enumerate(words):
        if (w >> 24) == 0 or (w & 0xFF) == 0 or ((w >> 8) & 0xFF) == 0 or ((w >> 16) & 0xFF) == 0:
            return i + 1
    return len(words)


def instructions(data: bytes):
    """Yield (opcode, operand words) for every instruction after the 5-word header."""
    if len(data) < 20 or len(data) % 4:
        raise SpirvError(f"not SPIR-V: {len(data)} bytes is not a whole number of 32-bit words after a header")
    endian = "<" if struct.unpack_from("<I", data)[0] == MAGIC else ">"
    if struct.unpack_from(endian + "I", data)[0] != MAGIC:
        raise SpirvError("not SPIR-V: bad magic number")
    words = struct.unpack(f"{endian}{len(data) // 4}I", data)
    i = 5
    while i < len(words):
        count, opcode = words[i] >> 16, words[i] & 0xFFFF
        if count == 0 or i + count > len(words):
            raise SpirvError(f"malformed instruction at word {i}: word count {count}")
        yield opcode, words[i + 1:i + count]
        i += count


# What read does with each opcode besides making its Instruction (0: keep it in the current block, if any).
_NAME, _EXT_IMPORT, _ENTRY_POINT, _TYPE, _CONSTANT, _VARIABLE, _FUNCTION, _PARAMETER, _FUNCTION_END, _LABEL, \
    _DEBUG_LINE = range(1, 12)


def _action(name: str) -> int:
    if name in ("Name", "ExtInstImport", "EntryPoint"):
        return {"Name": _NAME, "ExtInstImport": _EXT_IMPORT, "EntryPoint": _ENTRY_POINT}[name]
    if name.startswith("Type"):
        return _TYPE
    if name.startswith(("Constant", "SpecConstant")) or name == "Undef":
        return _CONSTANT
    return {"Variable": _VARIABLE, "Function": _FUNCTION, "FunctionParameter": _PARAMETER,
            "FunctionEnd": _FUNCTION_END, "Label": _LABEL, "Line": _DEBUG_LINE, "NoLine": _DEBUG_LINE}.get(name, 0)


# opcode -> (name, shape: 0 no result, 1 result only, 2 type and result, action)
_OPCODE_INFO = {op: (n, 0 if n in NO_RESULT else 1 if n in RESULT_ONLY else 2, _action(n)) for op, n in OPCODES.items()}


def read(data: bytes) -> Module:
    """Parse a SPIR-V module from its bytes (either endianness)."""
    endian = "<" if data[:4] == struct.pack("<I", MAGIC) else ">"
    header = struct.unpack_from(endian + "5I", data) if len(data) >= 20 else ()
    if not header or header[0] != MAGIC:
        raise SpirvError("not SPIR-V: bad magic number")
    mod = Module(((header[1] >> 16) & 0xFF, (header[1] >> 8) & 0xFF), header[3])
    if len(data) % 4:
        raise SpirvError(f"not SPIR-V: {len(data)} bytes is not a whole number of 32-bit words after a header")
    fn: Function | None = None
    block: Block | None = None
    body: list | None = None  # block.body
    value_types, info = mod.value_types, _OPCODE_INFO
    # One pass over the words (decoded at once), in the order instructions() yields them: an instruction
    # is made only when something keeps it, a value's type is noted for every instruction that has one.
    words_all = struct.unpack(f"{endian}{len(data) // 4}I", data)
    end, i = len(words_all), 5
    while i < end:
        first = words_all[i]
        count, opcode = first >> 16, first & 0xFFFF
        if count == 0 or i + count > end:
            raise SpirvError(f"malformed instruction at word {i}: word count {count}")
        words = words_all[i + 1:i + count]
        i += count
        known = info.get(opcode)
        if known is None:  # unknown: assume <type> <id> when inside a block (the common shape of value instructions)
            name = f"Op{opcode}"
            ins = Instruction(opcode, name, words, *(words[:2] if block is not None and len(words) >= 2 else (0, 0)))
            if ins.type_id:
                value_types[ins.result] = ins.type_id
            if body is not None:
                body.append(ins)
            continue
        name, shape, action = known
        if action == 0:  # the common case: an instruction of a block, or one nothing keeps
            if body is None:
                if shape == 2:
                    type_id, result = words[0], words[1]
                    if type_id:
                        value_types[result] = type_id
                elif shape == 1:
                    words[0]  # a result-only instruction without words fails as before (IndexError)
                continue
            if shape == 2:
                ins = Instruction(opcode, name, words, words[0], words[1])
                if ins.type_id:
                    value_types[ins.result] = ins.type_id
            elif shape == 1:
                ins = Instruction(opcode, name, words, 0, words[0])
            else:
                ins = Instruction(opcode, name, words)
            body.append(ins)
            continue
        if shape == 0:
            ins = Instruction(opcode, name, words)
        elif shape == 1:
            ins = Instruction(opcode, name, words, 0, words[0])
        else:
            ins = Instruction(opcode, name, words, words[0], words[1])
            if ins.type_id:
                value_types[ins.result] = ins.type_id
        if action == _NAME:
            mod.names[words[0]] = _string(words[1:])
        elif action == _EXT_IMPORT:
            mod.ext_imports[words[0]] = _string(words[1:])
        elif action == _ENTRY_POINT:
            n = _string_words(words[2:])
            mod.entry_points[_string(words[2:2 + n])] = (words[0], words[1])
        elif action == _TYPE:
            mod.types[words[0]] = Type(name, tuple(words[1:]))
        elif action == _CONSTANT:
            # OpUndef inside a function is no computation either: treated like a constant.
            mod.constants[ins.result] = ins
        elif action == _VARIABLE and fn is None:
            mod.globals[ins.result] = ins
        elif action == _FUNCTION:
            fn = Function(ins.result, ins.type_id)
            mod.functions[fn.id] = fn
        elif action == _PARAMETER and fn is not None:
            fn.params.append(ins)
        elif action == _FUNCTION_END:
            fn, block, body = None, None, None
        elif action == _LABEL and fn is not None:
            block = Block(ins.result)
            body = block.body
            fn.blocks.append(block)
        elif body is not None and action != _DEBUG_LINE:
            body.append(ins)
    return mod


def successors(mod: Module, block: Block) -> list[int]:
    """Labels a block's terminator can branch to (merge declarations are not edges)."""
    t = block.terminator
    if t.name == "Branch":
        return [t.words[0]]
    if t.name == "BranchConditional":
        return list(dict.fromkeys(t.words[1:3]))
    if t.name == "Switch":
        # (literal, label) pairs; a literal takes two words for a 64-bit selector
        step = 1 + max(1, mod.width(mod.value_types.get(t.words[0], 0)))
        return list(dict.fromkeys([t.words[1], *t.words[2 + step - 1::step]]))
    return []
