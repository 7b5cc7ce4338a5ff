"""Lowering pass 1, the symbol check: the names a kernel's code may use, and which array slot
each input symbol reads.

Every free symbol of a spec is an input, a call's result or a step (KernelSpec checks that when
it is built); here the names are made safe for the printed code: a scalar named like an array
argument is renamed (theta -> theta_v), and no input or result may look like a CSE temporary
(t0, t1, ...).
"""

from __future__ import annotations

import sympy as sp

from ..ir import Arg, KernelSpec, Slots, bare


def _temporary(name: str) -> bool:
    return name.startswith("t") and name[1:].isdigit()


def local_names(spec: KernelSpec) -> dict[sp.Symbol, sp.Symbol]:
    """The renames {input symbol: local symbol} of the spec's code; a ValueError for a name that
    clashes with a temporary or an argument, and for a call the generated code cannot make."""
    arrays = {a.name for a in spec.inputs + spec.outputs}
    local = {}
    for a in spec.inputs:
        for s in a.symbols:
            if str(s) in arrays:
                local[s] = sp.Symbol(f"{s}_v", real=True)
            if _temporary(str(s)):
                raise ValueError(f"{spec.name}: input symbol {s} clashes with CSE temporaries")
    for c in spec.calls:
        for r in c.results:
            if _temporary(str(r)) or str(r) in arrays:
                raise ValueError(f"{spec.name}: result symbol {r} clashes with a temporary or an argument")
    for c in spec.calls:
        for name, a in zip(c.args, c.kernel.inputs):
            if a.design and name is None:
                raise ValueError(f"{spec.name}: {c.kernel.name}'s design input {a.name} cannot be zeros")
    return local


def slots(inputs: list[Arg], local: dict, used: set) -> Slots:
    """Each input with the (slot, name) pairs of its symbols in `used`."""
    out = []
    for a in inputs:
        syms = [local.get(s, s) for s in a.symbols]
        out.append((bare(a), [(k, str(s)) for k, s in enumerate(syms) if s in used]))
    return out
