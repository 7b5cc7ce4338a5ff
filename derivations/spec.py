"""What a derivation hands to code generation: kernel specs and sets of derived polynomials.

A `KernelSpec` is a pure function from named input arrays to named output arrays, given as sympy
expressions. Large results are built as an ordered list of `steps` (intermediate symbol = expression),
the way a recursion is written by hand, so the expanded expression tree is never formed; `outputs`
may refer to step symbols. `PolynomialSet` carries the human-readable results of a derivation.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import sympy as sp


@dataclass(frozen=True)
class Arg:
    """A named array argument: `symbols` fill it in row-major (C) order. A `design` input is a
    constant of the mechanism (DH parameters, inertias, gravity), usually shared by a whole batch:
    the C batch functions compute what depends on design inputs alone once per shared design."""

    name: str
    shape: tuple[int, ...]
    doc: str
    symbols: tuple[sp.Symbol, ...] = ()
    exprs: tuple[sp.Expr, ...] = ()
    design: bool = False

    @property
    def size(self) -> int:
        n = 1
        for s in self.shape:
            n *= s
        return n


@dataclass(frozen=True)
class Call:
    """Another kernel evaluated inside this one, so that its code exists once: `kernel` is the
    callee's spec (one output), `args` names, for each of its inputs, the caller's input passed
    (same shape), "r<k>" for the output of the caller's k-th call (an earlier one, same size), or
    None for zeros, and `results` are the caller's symbols for the callee's output, row-major."""

    kernel: KernelSpec
    args: tuple[str | None, ...]
    results: tuple[sp.Symbol, ...]


def _result_index(arg) -> int | None:
    """k for a Call argument "r<k>" (the output of the caller's k-th call), else None."""
    if isinstance(arg, str) and arg[:1] == "r" and arg[1:].isdigit():
        return int(arg[1:])
    return None


@dataclass
class KernelSpec:
    """One generated function: inputs (symbol arrays) -> outputs (expression arrays). `calls`
    are kernels it evaluates first; their results are symbols the steps and outputs may use."""

    name: str
    doc: str
    source: str  # the derivation module that produced it
    inputs: list[Arg]
    outputs: list[Arg]
    steps: list[tuple[sp.Symbol, sp.Expr]] = field(default_factory=list)
    calls: list[Call] = field(default_factory=list)
    wide: bool = (
        False  # also emitted in extended precision (C, apair_wide): see codegen/backends/c/templates/kernels.c.j2
    )

    def __post_init__(self):
        for a in self.inputs:
            if len(a.symbols) != a.size:
                raise ValueError(f"{self.name}: input {a.name} has {len(a.symbols)} symbols for shape {a.shape}")
        for a in self.outputs:
            if len(a.exprs) != a.size:
                raise ValueError(f"{self.name}: output {a.name} has {len(a.exprs)} exprs for shape {a.shape}")
        known = {s for a in self.inputs for s in a.symbols}
        mine = {a.name: a for a in self.inputs}
        for k, c in enumerate(self.calls):
            callee = c.kernel
            if len(callee.outputs) != 1 or len(c.results) != callee.outputs[0].size or c.kernel.calls:
                raise ValueError(
                    f"{self.name}: a call of {callee.name} needs one result symbol per output entry "
                    "of a callee with one output and no calls of its own"
                )
            if len(c.args) != len(callee.inputs):
                raise ValueError(f"{self.name}: {callee.name} takes {len(callee.inputs)} inputs")
            for name, a in zip(c.args, callee.inputs):
                earlier = _result_index(name)
                if earlier is not None:
                    if earlier >= k or self.calls[earlier].kernel.outputs[0].size != a.size:
                        raise ValueError(f"{self.name}: {callee.name}'s input {a.name} cannot be {name}")
                elif name is not None and (name not in mine or tuple(mine[name].shape) != tuple(a.shape)):
                    raise ValueError(f"{self.name}: {callee.name}'s input {a.name} {a.shape} cannot be {name}")
            known |= set(c.results)
        for sym, expr in self.steps:
            if sym in known:
                raise ValueError(f"{self.name}: step {sym} is defined twice (or shadows an input)")
            missing = expr.free_symbols - known
            if missing:
                raise ValueError(f"{self.name}: step {sym} uses undefined {sorted(map(str, missing))}")
            known.add(sym)
        for a in self.outputs:
            for e in a.exprs:
                missing = sp.S(e).free_symbols - known
                if missing:
                    raise ValueError(f"{self.name}: output {a.name} uses undefined {sorted(map(str, missing))}")

    def flattened(self) -> KernelSpec:
        """The same function without calls: each callee's steps inlined (renamed), its inputs
        replaced by the caller's symbols (or zeros) and its outputs bound to the result symbols."""
        if not self.calls:
            return self
        mine = {a.name: a for a in self.inputs}
        steps = []
        for k, c in enumerate(self.calls):
            sub = {}
            for name, a in zip(c.args, c.kernel.inputs):
                earlier = _result_index(name)
                given = (
                    self.calls[earlier].results
                    if earlier is not None
                    else mine[name].symbols
                    if name is not None
                    else [0] * a.size
                )
                for s, t in zip(a.symbols, given):
                    sub[s] = sp.S(t)
            for sym, e in c.kernel.steps:
                new = sp.Symbol(f"c{k}_{sym.name}", real=True)
                steps.append((new, e.xreplace(sub)))
                sub[sym] = new
            steps += [(r, sp.S(e).xreplace(sub)) for r, e in zip(c.results, c.kernel.outputs[0].exprs)]
        return KernelSpec(self.name, self.doc, self.source, self.inputs, self.outputs, steps + list(self.steps))

    def expanded_outputs(self) -> list[sp.Expr]:
        """All output expressions with the steps substituted (a DAG: shared subtrees stay shared)."""
        if self.calls:
            return self.flattened().expanded_outputs()
        env: dict = {}
        for sym, expr in self.steps:
            env[sym] = expr.xreplace(env)
        return [sp.S(e).xreplace(env) for a in self.outputs for e in a.exprs]

    def fingerprint(self) -> str:
        """Content hash of the spec: names, shapes, symbols and expressions (srepr is canonical)."""
        h = hashlib.sha256()
        h.update(self.name.encode())
        if self.wide:
            h.update(b"wide")
        for c in self.calls:
            h.update(f"call {c.kernel.fingerprint()} {c.args} {[str(r) for r in c.results]}".encode())
        for a in self.inputs:
            h.update(f"in {a.name} {a.shape} {[str(s) for s in a.symbols]}{' design' if a.design else ''}".encode())
        for sym, expr in self.steps:
            h.update(f"step {sym} {sp.srepr(expr)}".encode())
        for a in self.outputs:
            h.update(f"out {a.name} {a.shape} {[sp.srepr(sp.S(e)) for e in a.exprs]}".encode())
        return h.hexdigest()


@dataclass(frozen=True)
class Entry:
    """A derived result: `expr` (an expression or an equation `lhs = rhs`) and its variables."""

    label: str
    expr: sp.Expr
    variables: tuple[sp.Symbol, ...] = ()
    note: str = ""
    rhs: sp.Expr | None = None  # when set, the entry reads  expr = rhs


@dataclass
class PolynomialSet:
    """A named set of derived equations, written to generated/polynomials/ by codegen."""

    name: str
    title: str
    source: str
    description: str
    entries: list[Entry]
