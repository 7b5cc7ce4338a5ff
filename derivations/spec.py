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


@dataclass
class KernelSpec:
    """One generated function: inputs (symbol arrays) -> outputs (expression arrays)."""

    name: str
    doc: str
    source: str  # the derivation module that produced it
    inputs: list[Arg]
    outputs: list[Arg]
    steps: list[tuple[sp.Symbol, sp.Expr]] = field(default_factory=list)

    def __post_init__(self):
        for a in self.inputs:
            if len(a.symbols) != a.size:
                raise ValueError(f"{self.name}: input {a.name} has {len(a.symbols)} symbols for shape {a.shape}")
        for a in self.outputs:
            if len(a.exprs) != a.size:
                raise ValueError(f"{self.name}: output {a.name} has {len(a.exprs)} exprs for shape {a.shape}")
        known = {s for a in self.inputs for s in a.symbols}
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

    def expanded_outputs(self) -> list[sp.Expr]:
        """All output expressions with the steps substituted (a DAG: shared subtrees stay shared)."""
        env: dict = {}
        for sym, expr in self.steps:
            env[sym] = expr.xreplace(env)
        return [sp.S(e).xreplace(env) for a in self.outputs for e in a.exprs]

    def fingerprint(self) -> str:
        """Content hash of the spec: names, shapes, symbols and expressions (srepr is canonical)."""
        h = hashlib.sha256()
        h.update(self.name.encode())
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
