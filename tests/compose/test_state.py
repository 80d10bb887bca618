"""What composition keeps between units (the Jinja environment, the emitters' records of linked functions)
belongs to the library it composes for: another library, as another build or a build worker has, starts from
nothing and composes the same bytes."""
from __future__ import annotations

import pytest

from generator.spec.permutation import LightKey, Permutation

PERM = Permutation("lambert+microfacet(ndf=ggx)", (LightKey("point", "none"),), "constants")
OTHER = Permutation("lambert+blinn_phong_normalized", (LightKey("point", "none"),), "constants")


def _texts(c) -> list[tuple[str, str, str]]:
    return [(s.language, s.stage, s.text) for s in c.sources + c.dialects]


def test_each_library_composes_with_its_own_templates_and_records():
    from generator.compose import composing, compose_permutation
    from generator.library.bricks import load_library

    a, b = load_library(), load_library()
    first = compose_permutation(PERM, a, dialects=("gl", "essl"))
    state = composing(a)
    assert len(state.records) > 0  # the emitters recorded the linked functions, in a's state
    assert not any(k[:1] == ("compose",) for k in b.memo)  # b has composed nothing: it holds no state at all
    again = compose_permutation(PERM, b, dialects=("gl", "essl"))
    assert composing(b) is not state and composing(b).templates.env is not state.templates.env
    assert _texts(again) == _texts(first)  # the same bytes from a state of its own


def test_a_library_replays_what_it_emitted_and_the_bytes_stay_the_same():
    from generator.compose import composing, compose_permutation
    from generator.library.bricks import load_library

    lib = load_library()
    once = compose_permutation(PERM, lib)
    recorded = len(composing(lib).records)
    compose_permutation(OTHER, lib)  # shares lambert and the light's functions with PERM
    twice = compose_permutation(PERM, lib)
    assert len(composing(lib).records) > recorded  # OTHER's own functions were added
    assert _texts(twice) == _texts(once)
    fresh = load_library()
    assert _texts(compose_permutation(PERM, fresh)) == _texts(once)


def test_the_templates_render_strictly_from_the_back_ends():
    import jinja2

    from generator.compose import Templates

    t = Templates()
    assert t.env.get_template("glsl/fragment.glsl.j2").filename.endswith("backends/glsl/templates/fragment.glsl.j2")
    with pytest.raises(jinja2.UndefinedError):
        t.render("glsl/eval.glsl.j2")  # a value the template reads and nobody gave is an error
