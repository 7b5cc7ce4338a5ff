"""Forward-mode differentiation of a recorded computation (a list of steps), symbolically.

A derivation written as steps s_k = e_k(inputs, earlier steps) is differentiated along one
direction by the chain rule, step by step: ds_k = Σ_v ∂e_k/∂v · dv. The derivative is itself a list
of small steps, so differentiating a large recursion never builds the expanded expression.
"""

from __future__ import annotations

import sympy as sp


def _key(s: sp.Symbol) -> str:
    return s.name


def directional(steps, exprs, seeds: dict, prefix: str):
    """Derivative of `exprs` along the direction given by `seeds` {input symbol: its derivative}.

    Returns (new steps, derivative expressions). Steps whose derivative is zero add nothing.
    """
    tangent = {s: sp.S(v) for s, v in seeds.items() if sp.S(v) != 0}
    new_steps = []
    for sym, expr in steps:
        d = _differentiate(expr, tangent)
        if d != 0:
            if d.is_Atom or (d.is_Mul and len(d.args) == 2 and d.args[0] == -1 and d.args[1].is_Atom):
                tangent[sym] = d
            else:
                dsym = sp.Symbol(f"{prefix}{sym.name}", real=True)
                new_steps.append((dsym, d))
                tangent[sym] = dsym
    return new_steps, [_differentiate(sp.S(e), tangent) for e in exprs]


def _differentiate(expr, tangent) -> sp.Expr:
    terms = []
    for v in sorted(expr.free_symbols & tangent.keys(), key=_key):
        terms.append(sp.diff(expr, v) * tangent[v])
    return sp.Add(*terms) if terms else sp.S(0)


def gradient(steps, expr, prefix: str):
    """Reverse mode: ∂expr/∂v for every input symbol v the steps depend on, in one backward pass.

    Returns (new steps, {input symbol: derivative expression}). The adjoint of each step is
    complete when it is reached (its users come later), so it is named once and reused.
    """
    defined = {s for s, _ in steps}
    contrib: dict = {}

    def add(v, term):
        contrib.setdefault(v, []).append(term)

    expr = sp.S(expr)
    for v in sorted(expr.free_symbols, key=_key):
        add(v, sp.diff(expr, v))
    new_steps = []
    for sym, e in reversed(steps):
        terms = contrib.pop(sym, None)
        if not terms:
            continue
        adj = sp.Add(*terms)
        if adj == 0:
            continue
        if not (adj.is_Atom or (adj.is_Mul and len(adj.args) == 2 and adj.args[0] == -1 and adj.args[1].is_Atom)):
            asym = sp.Symbol(f"{prefix}{sym.name}", real=True)
            new_steps.append((asym, adj))
            adj = asym
        for v in sorted(e.free_symbols, key=_key):
            d = sp.diff(e, v)
            if d != 0:
                add(v, d * adj)
    grads = {v: sp.Add(*terms) for v, terms in contrib.items() if v not in defined}
    return new_steps, grads
