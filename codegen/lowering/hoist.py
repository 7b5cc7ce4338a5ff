"""Lowering pass 4, hoisting of invariants: the assignments that depend on design inputs alone,
computed once for a batch that shares its design (the C backend's name_invariants / name_core)."""

from __future__ import annotations

import sympy as sp

from ..ir import Hoisted, KernelSpec
from .symbols import slots


def hoist(spec: KernelSpec, local: dict, assignments: list, reduced: list, printed: dict) -> Hoisted | None:
    """Split the assignments into those that depend on design inputs alone and the rest
    (`printed`: the C text of each assignment); None when no stored invariant would remain."""
    design = {local.get(s, s) for a in spec.inputs if a.design for s in a.symbols}
    if not design:
        return None
    invariant = set()
    for sym, e in assignments:
        if e.free_symbols <= design | invariant:
            invariant.add(sym)
    inv = [(sym, e) for sym, e in assignments if sym in invariant]
    core = [(sym, e) for sym, e in assignments if sym not in invariant]
    needed = set().union(*(e.free_symbols for _, e in core), *(sp.S(e).free_symbols for e in reduced))
    stored = [sym for sym, _ in inv if sym in needed]
    if not stored:
        return None
    used_inv = set().union(*(e.free_symbols for _, e in inv))
    return Hoisted(
        slots(spec.inputs, local, used_inv),
        [(str(s), printed[s]) for s, _ in inv],
        [str(s) for s in stored],
        slots(spec.inputs, local, needed),
        [(str(s), printed[s]) for s, _ in core],
        int(sp.count_ops([e for _, e in core] + [sp.S(e) for e in reduced])),
    )
