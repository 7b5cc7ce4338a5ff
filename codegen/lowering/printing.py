"""Lowering pass 5, printing: the straight-line code as text of each target, by the backends'
printers (C and NumPy for every kernel, JavaScript for the browser viewer's kernels, CasADi for
the pair laws and the chain kernels)."""

from __future__ import annotations

from ..backends.c.printer import CPrinter
from ..backends.casadi.printer import CasadiPrinter
from ..backends.js.printer import JSPrinter
from ..backends.numpy.printer import NumpyPrinter
from ..ir import Code, KernelSpec, LoweredCall, bare

PRINTERS = {"c": CPrinter(), "py": NumpyPrinter()}  # every kernel
JS = JSPrinter()  # the kernels of backends/js (WEB_KERNELS)
CASADI = CasadiPrinter()  # the kernels of backends/casadi (SOURCES)


def print_assignments(printer, assignments: list) -> dict:
    """{symbol: its expression's text}."""
    return {s: printer.doprint(e) for s, e in assignments}


def code(printer, assignments: list, outputs: list, printed: dict | None = None) -> Code:
    """The assignments (`printed`: their text, if already at hand) and the outputs [(Arg, expressions)] as text."""
    printed = print_assignments(printer, assignments) if printed is None else printed
    return Code(
        [(str(s), printed[s]) for s, _ in assignments],
        [(bare(a), [printer.doprint(e) for e in es]) for a, es in outputs],
    )


def calls(spec: KernelSpec, used: set) -> list[LoweredCall]:
    """The spec's calls as the backends need them: the callee's name, its arguments, output shape,
    and the result entries the code uses."""
    return [
        LoweredCall(
            c.kernel.name,
            [(name, bare(a)) for name, a in zip(c.args, c.kernel.inputs)],
            bare(c.kernel.outputs[0]),
            [(i, str(r)) for i, r in enumerate(c.results) if r in used],
        )
        for c in spec.calls
    ]
