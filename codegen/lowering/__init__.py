"""Lowering: a KernelSpec -> straight-line code printed for each target (`lower`), in passes:

1. symbols.py  the symbol check (names safe for the printed code; which array slot each symbol reads);
2. cse.py      common-subexpression elimination over the steps and outputs, and the clean-up after it;
3. order.py    each CSE temporary placed just before its first use;
4. hoist.py    what depends on the design inputs alone, split off for the C backend's batches;
5. printing.py the code printed by the backends' printers (C, NumPy; JavaScript for the viewer;
   CasADi for the pair laws and chain kernels).

Lowering is the expensive part of code generation and is independent per kernel, so
codegen/__main__.py runs it in worker processes; its result (codegen/ir.py) is plain data.
"""

from __future__ import annotations

import sympy as sp

from ..backends.casadi import SOURCES as CASADI_SOURCES
from ..backends.js import WEB_KERNELS
from ..ir import KernelSpec, Lowered, Signature, bare
from . import printing
from .cse import straight_line
from .hoist import hoist
from .symbols import local_names, slots

__all__ = ["lower"]


def lower(spec: KernelSpec) -> Lowered:
    """Straight-line code for a spec: its steps and outputs after CSE, in dependency order, printed
    for C and NumPy (and JavaScript for a kernel of the browser viewer), with its design-only part
    split off for C."""
    local = local_names(spec)
    assignments, reduced = straight_line(spec, local)
    used = set()
    for _, e in assignments:
        used |= e.free_symbols
    for e in reduced:
        used |= sp.S(e).free_symbols
    outputs, pos = [], 0
    for a in spec.outputs:
        outputs.append((a, list(reduced[pos : pos + a.size])))
        pos += a.size
    ops = int(sp.count_ops([e for _, e in assignments] + list(reduced)))
    printed = {target: printing.print_assignments(p, assignments) for target, p in printing.PRINTERS.items()}
    code = {target: printing.code(p, assignments, outputs, printed[target]) for target, p in printing.PRINTERS.items()}
    signature = Signature(
        spec.name, spec.doc, spec.source, [bare(a) for a in spec.inputs], [bare(a) for a in spec.outputs], spec.wide
    )
    calls = printing.calls(spec, used)
    hoisted = hoist(spec, local, assignments, reduced, printed["c"])
    if spec.wide and (spec.calls or hoisted is None):
        raise ValueError(
            f"{spec.name}: a wide kernel needs a design-only part and calls no other kernel "
            "(the C backend emits its wide version from the hoisted core)"
        )
    js = None
    if spec.name in WEB_KERNELS:
        if spec.calls:
            raise ValueError(f"{spec.name}: a web kernel cannot call other kernels")
        js = printing.code(printing.JS, assignments, outputs)
    casadi = printing.code(printing.CASADI, assignments, outputs) if spec.source in CASADI_SOURCES else None
    return Lowered(
        signature,
        slots(spec.inputs, local, used),
        code["c"],
        code["py"],
        ops,
        spec.fingerprint(),
        hoisted,
        calls,
        js,
        casadi,
    )
