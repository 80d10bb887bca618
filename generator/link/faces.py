"""A point light's shadow in six faces: the linker's side of the cube shadow (runtime/shadow_pass.py draws it).

A point or point_range light whose shadow filter samples a texture (shadow_map, pcf, pcf_hardware, vsm) reads a
map of FACES layers, one per cube face in Vulkan's order (+X, -X, +Y, -Y, +Z, -Z), each a 90° perspective
projection from the light with its own matrix. It is a texture2d_array, not a texturecube, for two reasons: the
shadow bricks stay as they are (they project P with a matrix and compare a depth; a cube would need a distance
compare and a brick of its own), and 2D arrays exist in every target, GLSL ES 3.00 and 3.10 included, where cube
arrays do not (so lights in a buffer can share one array later).

What the linker does, per such light i (:func:`faced_call`), not the bricks:

- the filter's entry is cloned as `<entry>_layers` (:func:`arrayed_entry`): each texture parameter retyped as
  its array (texture2d -> texture2d_array, texture2d_shadow -> texture2d_array_shadow), an int parameter
  SHADOW_LAYER added, and every sample / sample_level / sample_compare of those textures given the layer after
  its coordinate (lang/sampling.with_layer: the brick language's array form, typed by its one rule);
- the light gets FACE_MATRICES: `shadow_matrix` is face 0's (+X), `shadow_matrix_1` … `shadow_matrix_5` the
  others', six mat4 values of the light (six slots of the Lights block, or of its buffer element);
- the face is the major axis of r = -L (L the light brick's light_dir, so r points from the light to P), its
  sign the side: |r.z| >= |r.x|, |r.y| gives ±Z, else |r.y| >= |r.x| gives ±Y, else ±X (ties to z, then y; on
  such an edge both faces' rims hold the same depth), and the filter is called with that face's matrix and
  the face as layer.
"""
from __future__ import annotations

from ..lang import SourceError, ir
from ..lang.sampling import with_layer
from ..lang.types import BOOL, FLOAT, INT, MAT4, VEC3, arrayed_texture, texture_type
from ..scene.light_sets import CUBE_TYPES, MAX_SHADOW_LAYERS, shadow_layers  # noqa: F401 (re-exported)
from ..spec.params import ParamSpec, Params

FACES = 6
FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")  # layer k is face k (Vulkan's cube-face order)
FACE_MATRICES = ("shadow_matrix",) + tuple(f"shadow_matrix_{k}" for k in range(1, FACES))
SHADOW_LAYER = "shadow_layer"  # the arrayed filter's added parameter: the layer its samples read
FIRST_LAYER = "shadow_first_layer"  # a buffer light's value: its first layer in its pair's array (a float)
_SAMPLES = ("sample", "sample_level", "sample_compare")


def faced(light_type: str, textures) -> bool:
    """Whether a light of `light_type` whose filter samples `textures` is shadowed in six faces."""
    return light_type in CUBE_TYPES and bool(textures)


def face_params(lt) -> Params:
    """A LightPart's parameters as the shader reads them: its own, and for a faced light the five more face
    matrices after them (each like `shadow_matrix`: its default, the brick's identity, an engine overwrites)."""
    if not faced(lt.brick.id, lt.textures):
        return lt.params
    base = lt.params["shadow_matrix"]
    extra = {n: ParamSpec(n, base.ty, base.default, base.range, f"face {k} ({FACE_NAMES[k]}) of {base.doc}",
                          base.owners) for k, n in enumerate(FACE_MATRICES) if k}
    return Params({**dict(lt.params), **extra})


def buffer_params(lt) -> Params:
    """A dynamic (buffer) LightPart's parameters, as its element holds them: face_params, and for a shadowed pair
    FIRST_LAYER, the light's first layer in the pair's one array (a whole number; the build writes its ordinal in
    the pair × its layers)."""
    params = face_params(lt)
    if not lt.textures:
        return params
    spec = ParamSpec(FIRST_LAYER, FLOAT, 0.0, (0.0, float(MAX_SHADOW_LAYERS - 1)),
                     "the light's first layer in its pair's shadow-map array", ("generator/link/faces.py",))
    return Params({**dict(params), FIRST_LAYER: spec})


def first_layer(b, value: ir.Expr) -> ir.Expr:
    """int(<value>): a FIRST_LAYER value as a layer."""
    return ir.Construct(INT, b.here(), [b.copy(value)])


def arrayed_entry(prog, node) -> ir.Function:
    """The filter entry of shadow node `node` reading arrays (the module docstring), added to `prog` once."""
    f = prog.entry(node, node.brick.entries[0].name)
    name = f"{f.name}_layers"
    if name in prog.by_name:
        return prog.by_name[name]
    g = ir.clone(f)
    g.name = name
    textures = {p.name: arrayed_texture(p.ty) for p in g.params if p.ty.kind == "texture"}
    for p in g.params:
        if p.name in textures:
            p.ty = textures[p.name]
    g.params.append(ir.Param(SHADOW_LAYER, INT, g.loc))
    for n in ir.walk_body(g.body):
        if isinstance(n, ir.Var) and n.name in textures and n.scope == "param":
            n.ty = textures[n.name]
        elif isinstance(n, ir.Call) and any(isinstance(a, ir.Var) and a.name in textures for a in n.args):
            b = node.brick
            raise SourceError(b.display_path, n.loc.line, n.loc.col,
                              f"shadow filter '{b.id}' passes its texture to '{n.func}', so the linker cannot make "
                              "it read one layer of a point light's six faces",
                              "sample the texture in the filter's entry itself")
        elif isinstance(n, ir.Intrinsic) and n.name in _SAMPLES and isinstance(n.args[0], ir.Var) \
                and n.args[0].name in textures:  # in place: the call's parent keeps pointing at it
            t = n.args[0]
            single = _single(t.ty) if t.ty.arrayed else t.ty  # the walk may have retyped the Var already
            call = ir.Intrinsic(n.ty, n.loc, n.name, [ir.Var(single, t.loc, t.name, t.scope), *n.args[1:]])
            new = with_layer(call, ir.Var(textures[t.name], t.loc, t.name, t.scope),
                             ir.Var(INT, n.loc, SHADOW_LAYER, "param"))
            n.args, n.ty = new.args, new.ty
    return prog.add(g, node.brick)


def _single(t):
    """The texture type an array type is the array of (texture2d_array -> texture2d)."""
    return texture_type(t.dim[:-len("_array")], t.compare)


def face_select(b, r: ir.Expr, face: str) -> list[ir.Stmt]:
    """`int <face>` = the cube face of direction r (the module docstring's rule), as statements."""
    ax = b.intrinsic("abs", VEC3, r)

    def comp(e, c):
        return ir.Swizzle(FLOAT, b.here(), b.copy(e), c)

    def side(c, k):  # face k where r.c >= 0, else face k + 1
        return ir.Select(INT, b.here(), b.compare(">=", comp(r, c), b.const(0.0)), _int(b, k), _int(b, k + 1))

    fv = b.var(face, INT)
    z_major = ir.Binary(BOOL, b.here(), "and", b.compare(">=", comp(ax, "z"), comp(ax, "x")),
                        b.compare(">=", comp(ax, "z"), comp(ax, "y")))
    y_major = b.compare(">=", comp(ax, "y"), comp(ax, "x"))
    return [b.decl(face, side("x", 0)),
            b.if_(z_major, [b.assign(fv, side("z", 4))], [b.if_(y_major, [b.assign(b.copy(fv), side("y", 2))])])]


def faced_call(b, bind, prog, node, i: int, L: ir.Expr, matrices: list[ir.Expr], call,
               first: ir.Expr | None = None) -> list[ir.Stmt]:
    """Statements declaring `face<i>`, `shadow_m<i>` (that face's matrix of `matrices`, FACE_MATRICES' values)
    and ending with `s<i>` = the arrayed filter called with them (layer: first + the face, `first` an int
    expression or None for 0); `call(fn, args)` makes the call the way the glue binds the filter's other
    parameters."""
    face, m = f"face{i}", f"shadow_m{i}"
    stmts = face_select(b, ir.Unary(VEC3, b.here(), "-", b.copy(L)), face)
    stmts.append(b.decl(m, b.copy(matrices[0])))
    for k in range(1, FACES):
        stmts.append(b.if_(b.compare("==", b.var(face, INT), _int(b, k)),
                           [b.assign(b.var(m, MAT4), b.copy(matrices[k]))]))
    fn = arrayed_entry(prog, node)
    layer = b.var(face, INT) if first is None else ir.Binary(INT, b.here(), "+", first, b.var(face, INT))
    stmts.append(b.decl(f"s{i}", call(fn, {"shadow_matrix": b.var(m, MAT4), SHADOW_LAYER: layer})))
    return stmts


def _int(b, k: int) -> ir.Const:
    return ir.Const(INT, b.here(), int(k))
