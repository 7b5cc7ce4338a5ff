"""Rendering of derived polynomial sets: plain text, LaTeX, and JSON that loads back into sympy."""
from __future__ import annotations

import json
from pathlib import Path

import jinja2
import sympy as sp

from . import derivation

_spec = derivation("spec")
Entry, PolynomialSet = _spec.Entry, _spec.PolynomialSet

TEMPLATES = Path(__file__).parent / "templates"


def _assumption(sym: sp.Symbol) -> str:
    if sym.is_positive:
        return "positive"
    if sym.is_real:
        return "real"
    return "complex"


def describe(entry: Entry) -> dict:
    """Degree and term count of an entry: in its variables if it names them, else in all symbols."""
    expr = entry.expr if entry.rhs is None else entry.rhs
    gens = entry.variables or tuple(sorted(expr.free_symbols, key=str))
    info = {"degree": None, "terms": len(sp.Add.make_args(sp.expand(expr)))}
    if gens and expr.is_polynomial(*gens):
        poly = sp.Poly(expr, *gens)
        if poly.is_zero:
            return {"degree": None, "terms": 0}
        info["degree"] = int(poly.total_degree())
        info["terms"] = len(poly.terms())
    elif expr == 0:
        return {"degree": None, "terms": 0}
    elif not gens and expr.is_number:
        info["degree"] = 0
    return info


def collected(expr, variables, printer) -> str:
    """A polynomial printed term by term in its variables, each coefficient factored."""
    if not variables or not expr.is_polynomial(*variables) or expr == 0:
        return printer(expr)
    parts = []
    for monom, coeff in sp.Poly(expr, *variables).terms():
        mon = sp.Mul(*[v**k for v, k in zip(variables, monom)])
        c = sp.factor(coeff)
        sign = "-" if c.could_extract_minus_sign() else "+"
        c = -c if sign == "-" else c
        if mon == 1:
            body = printer(c)
        elif c == 1:
            body = printer(mon)
        elif c.is_Atom or c.is_Pow or (c.is_Mul and not any(a.is_Add for a in c.args)):
            body = f"{printer(c)}{'*' if printer is sp.sstr else ' '}{printer(mon)}"
        else:
            body = f"({printer(c)}){'*' if printer is sp.sstr else ' '}{printer(mon)}"
        parts.append((sign, body))
    first_sign, first = parts[0]
    out = ("-" if first_sign == "-" else "") + first
    for sign, body in parts[1:]:
        out += f" {sign} {body}"
    return out


def render_polynomial_set(ps: PolynomialSet, hasher) -> dict[str, str]:
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(TEMPLATES), keep_trailing_newline=True,
                             trim_blocks=True, lstrip_blocks=True, undefined=jinja2.StrictUndefined)
    rows = []
    symbols = {}
    for e in ps.entries:
        for s in sorted((e.expr.free_symbols | (e.rhs.free_symbols if e.rhs is not None else set())), key=str):
            symbols[str(s)] = _assumption(s)
        rows.append({
            "label": e.label,
            "note": e.note,
            "text": collected(e.expr, e.variables, sp.sstr) + ("" if e.rhs is None else f" = {sp.sstr(e.rhs)}"),
            "latex": collected(e.expr, e.variables, sp.latex) + ("" if e.rhs is None else f" = {sp.latex(e.rhs)}"),
            "lhs": sp.sstr(e.expr),
            "rhs": None if e.rhs is None else sp.sstr(e.rhs),
            "variables": [str(v) for v in e.variables],
            **describe(e),
        })
    txt_src = (TEMPLATES / "polynomials.txt.j2").read_text()
    tex_src = (TEMPLATES / "polynomials.tex.j2").read_text()
    content = json.dumps(rows, sort_keys=True)
    digest = hasher([txt_src, tex_src, content])
    ctx = {"ps": ps, "rows": rows, "hash": digest}
    data = {
        "name": ps.name, "title": ps.title, "source": ps.source, "description": ps.description,
        "content_hash": digest, "symbols": dict(sorted(symbols.items())),
        "entries": [{k: r[k] for k in ("label", "note", "lhs", "rhs", "variables", "degree", "terms")} for r in rows],
    }
    return {
        f"polynomials/{ps.name}.txt": env.get_template("polynomials.txt.j2").render(**ctx),
        f"polynomials/{ps.name}.tex": env.get_template("polynomials.tex.j2").render(**ctx),
        f"polynomials/{ps.name}.json": json.dumps(data, indent=1, sort_keys=True) + "\n",
    }
