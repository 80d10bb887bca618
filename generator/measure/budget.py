"""Per-shader budgets (`costs --budget`): the grammar, the check, and where an over-budget shader was asked for.

A budget is comma-separated items ``[SCOPE.]NAME=N``. SCOPE is an AMD family (RADV's name, or a gfx IP
name: ``gfx1030`` is ``navi21``) or ``spirv``; it applies to its own item and to every later item without a
scope, until the next one. Items before any scope are SPIR-V counts. So ``alu=60,navi21.vgprs=32,spills=0``
is SPIR-V ALU ≤ 60, navi21 VGPRs ≤ 32 and navi21 spills ≤ 0; ``navi21.vgprs=32,spirv.alu=60`` goes back to
the SPIR-V counts. Every limit is a most, but ``waves_per_simd`` (occupancy: more is better), which is a
least. A budget that names a family compiles for it on RADV's null device, as ``--gpu`` does.

An over-budget shader of a scene is one line located where the scene asks for it: a permutation at its first
material's ``brdf`` (the material whose objects draw with it; the others sharing it are named), the
ubershader at ``[scene]`` (every material feeds it). One line per shader and stage, the languages over
named when they are not all of them.
"""
from __future__ import annotations

import difflib
import re
from dataclasses import dataclass

from ..lang.errors import UsageError

# SPIR-V counts a budget (or a sort) names: the Markdown columns of measure/report.py
SPIRV_NAMES = ("texture", "alu", "transcendental", "alu_t", "branches", "registers", "instructions", "loads",
               "alu_scalar")
# RADV statistics a budget names -> the driver's statistics summed (runtime/gpu_stats.py SHOWN's keys, and spills)
RADV_NAMES = {"vgprs": ("VGPRs",), "sgprs": ("SGPRs",), "spills": ("Spilled VGPRs", "Spilled SGPRs"),
              "spilled_vgprs": ("Spilled VGPRs",), "spilled_sgprs": ("Spilled SGPRs",),
              "waves_per_simd": ("Subgroups per SIMD",), "instructions": ("Instructions",),
              "latency": ("Latency",), "inverse_throughput": ("Inverse Throughput",), "code_bytes": ("Code size",),
              "scratch_bytes": ("Scratch size",)}
AT_LEAST = frozenset({"waves_per_simd"})  # the statistics where more is better: the budget is a floor
EXAMPLE = "alu=60,texture=4,navi21.vgprs=32,spills=0"

# what to do, by what is over (the line names the material first: these say what to change in it)
_REGISTERS = "fewer values live at once"
HINTS = {"texture": "fewer textures in the material's packing", "registers": _REGISTERS, "vgprs": _REGISTERS,
         "sgprs": _REGISTERS, "spills": _REGISTERS, "spilled_vgprs": _REGISTERS, "spilled_sgprs": _REGISTERS,
         "scratch_bytes": _REGISTERS, "waves_per_simd": _REGISTERS}
_WORK = {"frag": "less work per pixel", "vert": "less work per vertex"}


@dataclass(frozen=True)
class Limit:
    """One item of a budget: a SPIR-V count (family None) or a RADV statistic of one family, and its bound."""

    family: str | None
    name: str
    bound: int

    @property
    def label(self) -> str:
        return f"{self.family} {self.name}" if self.family else self.name

    @property
    def at_least(self) -> bool:
        return self.family is not None and self.name in AT_LEAST

    def text(self) -> str:
        return f"{self.label} {'≥' if self.at_least else '≤'} {self.bound}"

    def breaks(self, v) -> bool:
        return v < self.bound if self.at_least else v > self.bound


def _usage(text: str, item: str, why: str) -> UsageError:
    return UsageError(f"--budget {text!r}: {item!r}: {why} — write e.g. --budget {EXAMPLE} "
                      "(docs/guide/costs.md, \"Budgets and diffs\")")


def _closest(name: str, names, what: str) -> str:
    near = difflib.get_close_matches(name, list(names), n=1, cutoff=0.5)
    return (f"did you mean '{near[0]}'? " if near else "") + f"{what}: {', '.join(names)}"


def parse(text: str) -> tuple[Limit, ...]:
    """`--budget` text -> its limits, in the order given (a bad item: one UsageError line naming the closest name)."""
    out: list[Limit] = []
    family: str | None = None
    for item in (x.strip() for x in text.split(",")):
        lhs, eq, value = (x.strip() for x in item.partition("="))
        if not eq or not re.fullmatch(r"[0-9]+", value):
            raise _usage(text, item, "not [FAMILY.]NAME=N with N a whole number")
        if "." in lhs:
            scope, _, lhs = (x.strip() for x in lhs.rpartition("."))
            if scope.lower() == "spirv":
                family = None
            else:
                from ..runtime.gpu_stats import check_families  # on use: the CLI's start stays light
                try:
                    family = check_families([scope])[0]
                except ValueError as e:
                    raise _usage(text, item, str(e)) from None
        names = RADV_NAMES if family else SPIRV_NAMES
        if lhs not in names:
            other = SPIRV_NAMES if family else RADV_NAMES
            if lhs in other:  # the right name in the wrong scope: say how the scope rule reads here
                why = (f"'{lhs}' is a SPIR-V count, and this item is in {family}'s scope (a family prefix holds "
                       f"until the next one) — write spirv.{lhs}={value}" if family else
                       f"'{lhs}' is a RADV statistic and needs a family — write navi21.{lhs}={value}")
                raise UsageError(f"--budget {text!r}: {item!r}: {why}")
            kind = f"{family}'s RADV statistics" if family else "SPIR-V counts (a RADV statistic needs FAMILY.)"
            raise _usage(text, item, f"unknown {'statistic' if family else 'count'} '{lhs}' — "
                                     + _closest(lhs, list(names), kind))
        if any(x.family == family and x.name == lhs for x in out):
            raise _usage(text, item, f"{(family + ' ') if family else ''}{lhs} is limited twice")
        out.append(Limit(family, lhs, int(value)))
    return tuple(out)


def families(limits) -> tuple[str, ...]:
    """The AMD families a budget names, in order (each compiled for on RADV's null device)."""
    return tuple(dict.fromkeys(x.family for x in limits if x.family))


def radv_value(stats: dict | None, name: str):
    """A budget statistic from a row's RADV figures of one family ({driver name: value}); None when absent."""
    if not stats or not all(k in stats for k in RADV_NAMES[name]):
        return None
    return sum(stats[k] for k in RADV_NAMES[name])


def value(row, limit: Limit):
    """The row's figure for a limit (None: not measured, e.g. RADV could not take the shader)."""
    from .report import _value
    if row.cost is None:
        return None
    if limit.family is None:
        return _value(row, limit.name)
    return radv_value((row.gpu or {}).get(limit.family), limit.name)


def _num(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _over_text(limit: Limit, by_lang: dict, languages) -> str | None:
    """'navi21 vgprs 40 > 32' (with the languages in parentheses when not every one is over), or None."""
    over = {lang: v for lang, r in by_lang.items() if (v := value(r, limit)) is not None and limit.breaks(v)}
    if not over:
        return None
    sign = "<" if limit.at_least else ">"
    parts = []
    for v in sorted(set(over.values()), key=lambda v: -v if not limit.at_least else v):
        langs = [lang for lang in languages if over.get(lang) == v]
        parts.append(f"{_num(v)} {sign} {limit.bound}" + ("" if len(over) == len(by_lang) == len(langs)
                                                           else f" ({', '.join(langs)})"))
    return f"{limit.label} " + ", ".join(parts)


def _hint(over_limits, table: str, stage: str) -> str:
    whats = " and ".join(dict.fromkeys(HINTS.get(x.name, _WORK.get(stage, "less work")) for x in over_limits))
    fams = list(dict.fromkeys(x.family for x in over_limits if x.family))
    rank = f"`shadermatrix costs --per-brick{' --gpu ' + ','.join(fams) if fams else ''}` ranks the bricks"
    if table == "ubershader":
        return (f"{whats} in the ubershader, which carries every material's worst case: a cheaper brick in the "
                "costliest material (the lines above, or `shadermatrix costs SCENE --gpu`, name it), or raise the "
                "budget")
    if table == "permutation":
        return f"{whats}: a cheaper brick or fewer lights for this material ({rank}), or raise the budget"
    return f"{whats}, or raise the budget"


@dataclass(frozen=True)
class Over:
    """One shader over its budget: the line to print, and the limits it breaks."""

    line: str
    limits: tuple[Limit, ...]


def check(rows, limits, scene=None) -> tuple[list[Over], int]:
    """The shaders over a budget (one per subject and stage, located in the scene when there is one) and how
    many shaders were measured."""
    from .plans import REPORT_LANGUAGES
    from .report import group
    out, measured = [], 0
    for (table, subject, stage, _), by_lang in group(rows).items():
        have = {lang: r for lang, r in by_lang.items() if r.cost is not None}
        if not have:
            continue
        measured += 1
        texts, broken = [], []
        for limit in limits:
            t = _over_text(limit, have, REPORT_LANGUAGES)
            if t is not None:
                texts.append(t)
                broken.append(limit)
        if texts:
            first = next(iter(have.values()))
            where, who = _where(scene, table, subject, first, stage)
            out.append(Over(f"{where}{who}: {', '.join(texts)} — {_hint(broken, table, stage)}", tuple(broken)))
    return out, measured


def _where(scene, table: str, subject: str, row, stage: str) -> tuple[str, str]:
    """('path:line:col: ', what the shader is) for a scene's shader; ('', what it is) for a per-brick row."""
    objects = f"; objects {', '.join(row.objects)}" if row.objects else ""
    if scene is not None and table == "permutation" and subject in scene.permutations:
        perm = scene.permutations[subject]
        mats = list(row.materials)
        at = perm.origin.at("brdf") if perm.origin is not None and perm.origin.parts else None
        where = f"{at.path}:{at.line}:{at.col}: " if at is not None else _at(scene, scene.where.get(subject))
        also = f" (and {', '.join(repr(m) for m in mats[1:])}, drawn with the same shader)" if len(mats) > 1 else ""
        name = f"material '{mats[0]}'{also}" if mats else "permutation"
        return where, f"{name} (permutation {subject}, {stage}{objects})"
    if scene is not None and table == "ubershader":
        return _at(scene, scene.head_at), f"the ubershader of every material ({stage})"
    what = table if table == subject else f"{table} {subject}"
    return "", f"over budget: {what} ({stage}{objects})"


def _at(scene, where) -> str:
    line, col = where or (1, 1)
    return f"{scene.path}:{line}:{col}: "
