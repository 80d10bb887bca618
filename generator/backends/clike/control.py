"""Switches and loops with a runtime bound in the C-like targets (a mixin of CLikeTarget).

    GLSL / HLSL                              WGSL
    switch (k) {                             switch k {
        case 1:                                  case 1i, 2i: {
        case 2: {                                    ...
            ...                                  }
            break;        (unless it returns)    default: {        (always present)
        }                                        }
        default: {                           }
            ...
        }
    }
    for (uint i = 0u; i < n; i++) {          for (var i: u32 = 0u; i < n; i++) {

Case bodies are braced, so their declarations stay local to the case. Case
lines carry no brick location (the IR's cases have none); the switch line does.
"""
from __future__ import annotations

from ...lang import ir
from ...lang.control import always_returns
from ...lang.types import Type
from .resources import ResourceMixin


class ControlMixin(ResourceMixin):
    DEFAULT_REQUIRED = False  # WGSL: every switch has a default clause
    CASE_BREAK = True         # GLSL/HLSL: a case body ends with break; (WGSL never falls through)

    def for_bound_head(self, var: str, t: Type, bound: str) -> str:
        """A loop head for a runtime int/uint bound (the loop variable has the bound's type)."""
        zero = self.literal(t, 0)
        return f"for ({self.type_name(t)} {var} = {zero}; {var} < {bound}; {var}++) {{"

    def switch(self, w, s: ir.Switch) -> None:
        """switch (x) { case 1: case 2: { ...; break; } default: { ... } } — no fallthrough."""
        values = [v for vs, _ in s.cases for v in vs]
        assert len(set(values)) == len(values) and all(type(v) is int for v in values), \
            f"{s.loc}: switch case values must be distinct ints, got {values}"
        w.line(self.switch_head(self.expr(s.selector)), s.loc)
        w.depth += 1
        arms = [(tuple(values), body) for values, body in s.cases]
        if s.default or self.DEFAULT_REQUIRED:
            arms.append((None, s.default))
        for values, body in arms:
            for label in self.case_labels(s.selector.ty, values):
                w.line(label)
            w.depth += 1
            self.block(w, body)
            if self.CASE_BREAK and not always_returns(body):
                w.line("break;")
            w.depth -= 1
            w.line("}")
        w.depth -= 1
        w.line("}")

    def switch_head(self, selector: str) -> str:
        return f"switch {wrap(selector)} {{"

    def case_label_value(self, t: Type, v: int) -> str:
        """A case value without parentheses (a negative int reads -3, not (-3))."""
        return f"{int(v)}{self.UINT_SUFFIX}" if t.scalar == "uint" else self.int_literal(int(v))

    def case_labels(self, t: Type, values: tuple[int, ...] | None) -> list[str]:
        """The lines opening one arm: `case 1:` per value, the last opening the body's brace."""
        if values is None:
            return ["default: {"]
        labels = [f"case {self.case_label_value(t, v)}:" for v in values]
        labels[-1] += " {"
        return labels


def wrap(s: str) -> str:
    """`s` in parentheses unless one pair already encloses all of it."""
    if s.startswith("(") and s.endswith(")"):
        depth = 0
        for i, c in enumerate(s):
            depth += c == "("
            depth -= c == ")"
            if depth == 0 and i < len(s) - 1:
                break
        else:
            return s
    return f"({s})"
