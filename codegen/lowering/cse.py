"""Lowering pass 2, common-subexpression elimination, and the clean-up after it.

The steps are kept as assignments (they are the derivation's own common subexpressions, so a
recursion stays linear in size); CSE runs over the step expressions and outputs with the step
symbols free. Steps that no output needs are dropped first; after CSE, a step that only renames a
symbol or a number is substituted away, what nothing uses any more is dropped, and every
intermediate is renamed t0, t1, ... in order of definition (short lines, small sources).
"""

from __future__ import annotations

import sympy as sp

from ..ir import KernelSpec
from .order import ordered


def needed(spec: KernelSpec, local: dict) -> tuple[list, list]:
    """(steps, outputs) with the local names: the output expressions, and the steps they need, in order."""
    outputs = [sp.S(e).xreplace(local) for a in spec.outputs for e in a.exprs]
    needed = set().union(*(e.free_symbols for e in outputs)) if outputs else set()
    steps = []
    for sym, expr in reversed(spec.steps):
        if sym in needed:
            expr = expr.xreplace(local)
            steps.append((sym, expr))
            needed |= expr.free_symbols
    steps.reverse()
    return steps, outputs


def eliminate(steps: list, outputs: list) -> tuple[list, list]:
    """(assignments, reduced outputs) after CSE over the steps and outputs, in dependency order."""
    exprs = [e for _, e in steps] + outputs
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"), order="canonical")
    assignments = ordered(replacements, [(s, e) for (s, _), e in zip(steps, reduced[: len(steps)])])
    return assignments, reduced[len(steps) :]


def drop_aliases(assignments: list, reduced: list) -> tuple[list, list]:
    """A step that is only another name (of a symbol or a number) is substituted away."""
    alias, kept = {}, []
    for s, e in assignments:
        e = e.xreplace(alias) if alias else e
        if e.is_Symbol or e.is_Number:
            alias[s] = e
        else:
            kept.append((s, e))
    return kept, [sp.S(e).xreplace(alias) for e in reduced]


def drop_unused(assignments: list, reduced: list) -> list:
    """The assignments that the outputs need, directly or not."""
    live = set().union(*(sp.S(e).free_symbols for e in reduced)) if reduced else set()
    kept = []
    for s, e in reversed(assignments):
        if s in live:
            kept.append((s, e))
            live |= e.free_symbols
    kept.reverse()
    return kept


def rename(assignments: list, reduced: list) -> tuple[list, list]:
    """Every intermediate renamed t0, t1, ... in order of definition."""
    names = {s: sp.Symbol(f"t{k}", real=True) for k, (s, _) in enumerate(assignments)}
    return [(names[s], e.xreplace(names)) for s, e in assignments], [sp.S(e).xreplace(names) for e in reduced]


def straight_line(spec: KernelSpec, local: dict) -> tuple[list, list]:
    """(assignments, reduced outputs): the spec's code after CSE and clean-up."""
    assignments, reduced = eliminate(*needed(spec, local))
    assignments, reduced = drop_aliases(assignments, reduced)
    return rename(drop_unused(assignments, reduced), reduced)
