"""Types of the brick language: scalars, vectors, matrices, textures, structs, arrays and buffers."""
from __future__ import annotations

from dataclasses import dataclass

SCALARS = ("float", "int", "uint", "bool")


@dataclass(frozen=True)
class Type:
    """A brick-language type.

    kind: "scalar" | "vector" | "matrix" | "texture" | "struct" | "array" | "buffer".
    scalar: element scalar for scalar/vector/matrix ("float", "int", "uint", "bool").
    size: vector width or matrix order (mat3 → 3); 1 for scalars; the element count N of
        array[T, N]; a buffer's capacity (0: a runtime-sized storage buffer).
    name: the struct name for structs, the canonical spelling otherwise
        ("texture2d", "texturecube", "texture2d_shadow", "array[Lobe, 4]", "storage_buffer[Light]").
    fields: for structs, ((field, Type), ...).
    elem: the element type of an array or buffer (None otherwise).
    space: for buffers, "storage" (read-only storage buffer, runtime-sized array of
        structs) or "uniform" (uniform block holding array[elem, size]); "" otherwise.

    Construct arrays, buffers and textures with array(), storage_buffer(),
    uniform_buffer(), TEXTURE2D, TEXTURECUBE, TEXTURE2D_SHADOW and their arrays
    (texture_type(dim, compare)) below (a texture2d_shadow or texture2d_array_shadow
    is a depth texture read only through its comparison sampler, by sample_compare); buffers are global resources only (never parameters, locals
    or struct fields) and their element structs obey buffer_layout_error().
    """

    kind: str
    scalar: str = ""
    size: int = 1
    name: str = ""
    fields: tuple = ()
    elem: "Type | None" = None
    space: str = ""

    def __str__(self) -> str:
        return self.name

    @property
    def is_scalar(self) -> bool:
        return self.kind == "scalar"

    @property
    def is_vector(self) -> bool:
        return self.kind == "vector"

    @property
    def is_numeric(self) -> bool:
        return self.kind in ("scalar", "vector", "matrix") and self.scalar != "bool"

    @property
    def is_float_based(self) -> bool:
        return self.kind in ("scalar", "vector", "matrix") and self.scalar == "float"

    @property
    def dim(self) -> str:
        """A texture's dimension: "2d", "cube", "2d_array" or "cube_array" ("" for other types); a
        texture2d_shadow is "2d", a texture2d_array_shadow "2d_array"."""
        return _TEXTURE_DIMS.get(self.name, "") if self.kind == "texture" else ""

    @property
    def compare(self) -> bool:
        """A depth texture sampled through a comparison sampler (texture2d_shadow, texture2d_array_shadow)."""
        return self.kind == "texture" and self.name in _COMPARE_TEXTURES

    @property
    def arrayed(self) -> bool:
        """A texture array: its sampling calls take a layer after the coordinate (texture_type)."""
        return self.dim.endswith("_array")

    @property
    def components(self) -> int:
        """Number of 32-bit scalar components (for layouts and costs).

        An array or uniform buffer counts size × its element; a runtime-sized storage
        buffer counts 0 (its length is known only at run time).
        """
        if self.kind == "matrix":
            return self.size * self.size
        if self.kind == "struct":
            return sum(t.components for _, t in self.fields)
        if self.kind in ("array", "buffer"):
            return self.size * self.elem.components
        return self.size

    def field(self, name: str) -> "Type | None":
        for f, t in self.fields:
            if f == name:
                return t
        return None


def scalar(s: str) -> Type:
    return Type("scalar", s, 1, s)


_VEC_PREFIX = {"float": "vec", "int": "ivec", "uint": "uvec", "bool": "bvec"}


def vector(s: str, n: int) -> Type:
    if n == 1:
        return scalar(s)
    return Type("vector", s, n, f"{_VEC_PREFIX[s]}{n}")


def matrix(n: int) -> Type:
    return Type("matrix", "float", n, f"mat{n}")


def struct(name: str, fields) -> Type:
    return Type("struct", "", 1, name, tuple(fields))


FLOAT = scalar("float")
INT = scalar("int")
UINT = scalar("uint")
BOOL = scalar("bool")
VEC2, VEC3, VEC4 = vector("float", 2), vector("float", 3), vector("float", 4)
MAT3, MAT4 = matrix(3), matrix(4)
TEXTURE2D = Type("texture", "float", 1, "texture2d")
TEXTURECUBE = Type("texture", "float", 1, "texturecube")
# A depth image (D32_SFLOAT) and a comparison sampler (compareOp LESS_OR_EQUAL, linear): read only by
# sample_compare, which returns the filtered result of the depth compares (percentage-closer filtering in
# hardware: GLSL sampler2DShadow, HLSL SamplerComparisonState, WGSL texture_depth_2d + sampler_comparison).
TEXTURE2D_SHADOW = Type("texture", "float", 1, "texture2d_shadow")
# Arrays of layers of one size (VK_IMAGE_VIEW_TYPE_2D_ARRAY, CUBE_ARRAY): sample(t, uv, layer) and the others
# take an int or uint layer after the coordinate; a layer outside [0, L-1] reads the nearest layer (clamped),
# as Vulkan does to its rounded layer coordinate and WGSL to its integer index, so no target rounds.
TEXTURE2D_ARRAY = Type("texture", "float", 1, "texture2d_array")
TEXTURE2D_ARRAY_SHADOW = Type("texture", "float", 1, "texture2d_array_shadow")
TEXTURECUBE_ARRAY = Type("texture", "float", 1, "texturecube_array")
_TEXTURE_DIMS = {"texture2d": "2d", "texturecube": "cube", "texture2d_shadow": "2d",
                 "texture2d_array": "2d_array", "texturecube_array": "cube_array", "texture2d_array_shadow": "2d_array"}
_COMPARE_TEXTURES = ("texture2d_shadow", "texture2d_array_shadow")
TEXTURE_DIMS = ("2d", "cube", "2d_array", "cube_array")
_TEXTURES = {("2d", False): TEXTURE2D, ("cube", False): TEXTURECUBE, ("2d", True): TEXTURE2D_SHADOW,
             ("2d_array", False): TEXTURE2D_ARRAY, ("cube_array", False): TEXTURECUBE_ARRAY,
             ("2d_array", True): TEXTURE2D_ARRAY_SHADOW}


def texture_type(dim: str, compare: bool = False) -> Type:
    """The texture type of dimension `dim` (TEXTURE_DIMS) and, compare, a depth texture read through a
    comparison sampler (2d and 2d_array only: the language has no cube depth texture)."""
    try:
        return _TEXTURES[(dim, bool(compare))]
    except KeyError:
        raise ValueError(f"no texture of dimension {dim!r}{' with a comparison sampler' if compare else ''}: "
                         f"one of {', '.join(TEXTURE_DIMS)} (compare: 2d or 2d_array)") from None


def arrayed_texture(t: Type) -> Type:
    """The array of layers of texture type t (texture2d -> texture2d_array, texture2d_shadow ->
    texture2d_array_shadow, texturecube -> texturecube_array); an array stays itself."""
    return t if t.arrayed else texture_type(t.dim + "_array", t.compare)


BUILTIN_TYPES: dict[str, Type] = {
    "float": FLOAT, "int": INT, "uint": UINT, "bool": BOOL,
    "mat3": MAT3, "mat4": MAT4, "texture2d": TEXTURE2D, "texturecube": TEXTURECUBE,
    "texture2d_shadow": TEXTURE2D_SHADOW, "texture2d_array": TEXTURE2D_ARRAY,
    "texture2d_array_shadow": TEXTURE2D_ARRAY_SHADOW, "texturecube_array": TEXTURECUBE_ARRAY,
}
for _s, _p in _VEC_PREFIX.items():
    for _n in (2, 3, 4):
        BUILTIN_TYPES[f"{_p}{_n}"] = vector(_s, _n)


# ---------------------------------------------------------------- arrays and buffers

ARRAY_ELEMENT_KINDS = ("scalar", "vector", "matrix", "struct")


def array(elem: Type, n: int) -> Type:
    """array[elem, n]: a fixed-capacity array (elem a scalar, vector, matrix or struct; n ≥ 1)."""
    assert elem.kind in ARRAY_ELEMENT_KINDS, f"no arrays of {elem}"
    assert type(n) is int and n >= 1, f"array size {n!r}"
    return Type("array", "", n, f"array[{elem}, {n}]", (), elem)


def storage_buffer(elem: Type) -> Type:
    """A read-only storage buffer holding a runtime-sized array of elem (a struct)."""
    _check_layout(elem)
    return Type("buffer", "", 0, f"storage_buffer[{elem}]", (), elem, "storage")


def uniform_buffer(elem: Type, capacity: int) -> Type:
    """A uniform block holding array[elem, capacity] (elem a struct)."""
    _check_layout(elem)
    assert type(capacity) is int and capacity >= 1, f"uniform buffer capacity {capacity!r}"
    return Type("buffer", "", capacity, f"uniform_buffer[{elem}, {capacity}]", (), elem, "uniform")


BUFFER_LEAVES = ("vec4", "ivec4", "uvec4")


def buffer_layout_error(elem: Type) -> str | None:
    """Why `elem` cannot be a buffer element, or None.

    The rule: a buffer element is a struct whose every leaf member is a 4-component
    32-bit vector (vec4, ivec4, uvec4), directly, in nested structs or in fixed
    arrays of those. Every member then starts on a 16-byte boundary and has a
    16-byte-multiple size, so std430 (GLSL storage), std140 (GLSL uniform), HLSL
    structured buffers and cbuffers (through glslang) and WGSL storage/uniform
    layouts are byte-identical: member k of a flat struct sits at 16·k, the array
    stride is 16 × the number of leaves. Pack scalars into vec4 components and
    store a mat4 as four vec4 columns.
    """
    if elem.kind != "struct":
        return f"a buffer holds structs, not {elem}"

    def bad(t: Type, where: str) -> str | None:
        if t.kind == "struct":
            for f, ft in t.fields:
                found = bad(ft, f"{where}.{f}")
                if found:
                    return found
            return None
        if t.kind == "array":
            return bad(t.elem, f"{where}[]")
        if t.name in BUFFER_LEAVES:
            return None
        return f"buffer member {where} is {t}, not one of {', '.join(BUFFER_LEAVES)}"

    return bad(elem, elem.name)


def _check_layout(elem: Type) -> None:
    why = buffer_layout_error(elem)
    if why:
        raise ValueError(f"{why} (every buffer member must be a 16-byte vector so std140, std430, "
                         "HLSL and WGSL layouts agree; pack scalars into a vec4)")
