"""Types of the brick language: scalars, vectors, matrices, textures and structs."""
from __future__ import annotations

from dataclasses import dataclass

SCALARS = ("float", "int", "uint", "bool")


@dataclass(frozen=True)
class Type:
    """A brick-language type.

    kind: "scalar" | "vector" | "matrix" | "texture" | "struct" | "void".
    scalar: element scalar for scalar/vector/matrix ("float", "int", "uint", "bool").
    size: vector width or matrix order (mat3 → 3); 1 for scalars.
    name: the struct name for structs, the canonical spelling otherwise.
    fields: for structs, ((field, Type), ...).
    """

    kind: str
    scalar: str = ""
    size: int = 1
    name: str = ""
    fields: tuple = ()

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
    def components(self) -> int:
        """Number of 32-bit scalar components (for layouts and costs)."""
        if self.kind == "matrix":
            return self.size * self.size
        if self.kind == "struct":
            return sum(t.components for _, t in self.fields)
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
VOID = Type("void", "", 0, "void")

BUILTIN_TYPES: dict[str, Type] = {
    "float": FLOAT, "int": INT, "uint": UINT, "bool": BOOL,
    "mat3": MAT3, "mat4": MAT4, "texture2d": TEXTURE2D,
}
for _s, _p in _VEC_PREFIX.items():
    for _n in (2, 3, 4):
        BUILTIN_TYPES[f"{_p}{_n}"] = vector(_s, _n)


def with_scalar(t: Type, s: str) -> Type:
    """The same shape with another element scalar (vec3 → bvec3)."""
    return vector(s, t.size) if t.kind in ("scalar", "vector") else t
