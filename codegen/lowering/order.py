"""Lowering pass 3, ordering: the CSE temporaries placed just before their first use."""

from __future__ import annotations


def ordered(replacements, steps):
    """Steps in their order, each preceded by the CSE temporaries it needs (first use first), then
    the temporaries that only the outputs use."""
    temp = dict(replacements)
    index = {s: k for k, (s, _) in enumerate(replacements)}
    done, out = set(), []

    def need(expr):
        for s in sorted(expr.free_symbols & temp.keys() - done, key=index.__getitem__):
            if s not in done:
                need(temp[s])
                done.add(s)
                out.append((s, temp[s]))

    for sym, expr in steps:
        need(expr)
        out.append((sym, expr))
    for s, e in replacements:  # those only the outputs use
        if s not in done:
            need(e)
            done.add(s)
            out.append((s, e))
    return out
