"""A dynamic set's tiled light loops (culling = "tiles"): each pair's loop reads the fragment's screen tile's list
of indices into the pair's buffer, which the engine's light culling fills, instead of every element.

The one read-only storage buffer LightTiles is a flat array of uint32 words (declared as `uvec4 w` elements, the
layout rule of storage buffers, so GLSL std430, HLSL structured buffers and WGSL storage agree):

    words 0..3                     tiles_x, tiles_y, tile_size (pixels), pairs (the key's light count)
    words 4 + 2 (t · pairs + i)    the record of tile t = x + y · tiles_x, pair i: offset (a word index into
                                   this buffer), count
    from the records' end on       the index lists: count words from offset, each an element of pair i's buffer

The tile is (⌊x / tile_size⌋, ⌊y / tile_size⌋) of the fragment's pixel coordinate (gl_FragCoord, SV_Position,
@builtin(position): from the top left in Vulkan, D3D and WebGPU, from the bottom left in OpenGL), clamped to the
grid; a tile_size, tiles_x or tiles_y of 0 reads as 1 (the shader never divides by zero or reads past the grid).
The tile size lives in the buffer, not in the shader, so an engine picks it (and the grid) without a rebuild.
Why a list per (tile, pair) rather than one per tile: each pair keeps its own loop over its own buffer (loop
"types", the measured default), so each needs its own indices.
"""
from __future__ import annotations

from ..lang import ir
from ..lang.types import FLOAT, UINT, storage_buffer, struct, vector
from .irgen import Builder

UVEC4 = vector("uint", 4)
VEC2 = vector("float", 2)
TILES_BLOCK = "LightTiles"  # the interface's storage block (link.link_permutation binds it after the light buffers)
TILES_GLOBAL = "light_tiles"
FRAG_COORD = "frag_coord"  # shade()'s parameter: the fragment's pixel coordinate (the templates' local)
HEADER_WORDS = 4  # tiles_x, tiles_y, tile_size, pairs
RECORD_WORDS = 2  # offset, count
ELEMENT = "LightTileWords"


def tiles_global(prog) -> ir.Global:
    """The LightTiles storage buffer's global (its element struct added to prog)."""
    elem = struct(ELEMENT, (("w", UVEC4),))
    prog.structs.append(elem)
    return ir.Global(TILES_GLOBAL, storage_buffer(elem))


def _u(b: Builder, v: int) -> ir.Const:
    return ir.Const(UINT, b.here(), v)


def _word(b: Builder, g: ir.Global, w: ir.Expr) -> ir.Expr:
    """Word w of the buffer: component w % 4 of element w / 4."""
    elem = ir.Index(g.ty.elem, b.here(), ir.Var(g.ty, b.here(), g.name, "global"), b.arith("/", w, _u(b, 4)))
    return ir.Index(UINT, b.here(), ir.Member(UVEC4, b.here(), elem, "w"), b.arith("%", b.copy(w), _u(b, 4)))


def tile_record(b: Builder, g: ir.Global, pairs: int) -> list[ir.Stmt]:
    """`uint tile_rec`: the first word of the fragment's tile's records (its tile clamped to the header's grid)."""
    head = ir.Member(UVEC4, b.here(), ir.Index(g.ty.elem, b.here(), ir.Var(g.ty, b.here(), g.name, "global"),
                                              _u(b, 0)), "w")
    out = [b.decl("tile_head", head)]

    def h(c):
        return ir.Swizzle(UINT, b.here(), b.var("tile_head", UVEC4), c)

    def at_least_1(e):  # a header of zeros (an engine that filled nothing) reads tile 0, not past the buffer
        return b.intrinsic("max", UINT, e, _u(b, 1))

    for axis, n in (("x", "x"), ("y", "y")):  # min(uint(frag_coord.axis) / tile_size, tiles_axis - 1)
        pix = ir.Construct(UINT, b.here(), [ir.Swizzle(FLOAT, b.here(), b.var(FRAG_COORD, VEC2, "param"), axis)])
        out.append(b.decl(f"tile_{axis}0", b.arith("/", pix, at_least_1(h("z")))))
        t0 = b.var(f"tile_{axis}0", UINT)
        last = b.arith("-", at_least_1(h(n)), _u(b, 1))
        out.append(b.decl(f"tile_{axis}", ir.Select(UINT, b.here(), b.compare("<", t0, h(n)), b.copy(t0), last)))
    tile = b.arith("+", b.var("tile_x", UINT), b.arith("*", b.var("tile_y", UINT), h("x")))
    out.append(b.decl("tile_rec", b.arith("+", _u(b, HEADER_WORDS), b.arith("*", _u(b, RECORD_WORDS * pairs), tile))))
    return out


def tiled_loop(b: Builder, g: ir.Global, i: int, body: list[ir.Stmt]) -> list[ir.Stmt]:
    """Pair i's loop over its tile's list: `k<i>`, the element of its buffer the body reads, from the list."""
    rec = b.arith("+", b.var("tile_rec", UINT), _u(b, RECORD_WORDS * i))
    off = b.decl(f"tile_off{i}", _word(b, g, rec))
    cnt = b.decl(f"tile_cnt{i}", _word(b, g, b.arith("+", b.copy(rec), _u(b, 1))))
    k = b.decl(f"k{i}", _word(b, g, b.arith("+", b.var(f"tile_off{i}", UINT), b.var(f"t{i}", UINT))))
    return [off, cnt, ir.For(b.loc(), f"t{i}", 0, [k, *body], b.var(f"tile_cnt{i}", UINT))]


__all__ = ["FRAG_COORD", "HEADER_WORDS", "RECORD_WORDS", "TILES_BLOCK", "VEC2", "tile_record", "tiled_loop",
           "tiles_global"]
