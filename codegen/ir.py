"""What lowering hands to the backends: a kernel as straight-line code printed for each target.

These are plain data (cheap to pickle: codegen/__main__.py lowers in worker processes) with names,
shapes, docs and printed text only; no sympy expression survives lowering. `Arg`, `KernelSpec`
and `PolynomialSet` are the derivations' own types (derivations/spec.py), re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass

from . import derivation

_spec = derivation("spec")
Arg, KernelSpec, PolynomialSet = _spec.Arg, _spec.KernelSpec, _spec.PolynomialSet

Slots = list[tuple[Arg, list[tuple[int, str]]]]  # each input with the (slot, name) of the symbols it reads


@dataclass
class Signature:
    """What the templates need of a kernel spec: names, shapes and docs, without expressions."""

    name: str
    doc: str
    source: str
    inputs: list[Arg]
    outputs: list[Arg]
    wide: bool = False  # also emitted in extended precision (KernelSpec.wide)


@dataclass
class Code:
    """Straight-line code printed for one target: (name, expression) assignments, then outputs."""

    assignments: list[tuple[str, str]]
    outputs: list[tuple[Arg, list[str]]]


@dataclass
class Hoisted:
    """The C form of a kernel with its design-only part split off: `invariants` (assignments that
    depend on design inputs alone) fill inv[0..len(stored)), from which `core` evaluates one item.
    A batch whose design inputs all have stride 0 computes the invariants once."""

    inv_inputs: Slots
    invariants: list[tuple[str, str]]
    stored: list[str]
    core_inputs: Slots
    core: list[tuple[str, str]]
    core_ops: int  # operations per item of a batch that shares its design

    @property
    def loads(self) -> list[tuple[str, str]]:
        """The core's reads of the stored invariants: (name, "inv[k]")."""
        return [(name, f"inv[{k}]") for k, name in enumerate(self.stored)]


@dataclass
class LoweredCall:
    """A callee of a composite kernel: its name, the caller's argument for each of its inputs
    (None: zeros), its output's shape, and the (index, name) of each result entry the caller uses."""

    kernel: str
    args: list[tuple[str | None, Arg]]
    out: Arg
    results: list[tuple[int, str]]


@dataclass
class Lowered:
    """A kernel as printed straight-line code, ready for the backends (cheap to pickle)."""

    spec: Signature
    inputs: Slots  # each input with the (slot, name) it reads
    c: Code
    py: Code
    ops: int
    fingerprint: str
    hoisted: Hoisted | None  # None: nothing depends on design inputs alone
    calls: list[LoweredCall]  # kernels evaluated first (their own hoisting applies)
    js: Code | None = None  # for the JavaScript backend's kernels only (backends/js: WEB_KERNELS)
    casadi: Code | None = None  # for the CasADi backend's kernels only (backends/casadi: SOURCES)

    @property
    def name(self) -> str:
        return self.spec.name


def bare(a: Arg) -> Arg:
    """The argument without its symbols and expressions (names, shape, doc, design flag)."""
    return Arg(a.name, tuple(a.shape), a.doc, design=a.design)
