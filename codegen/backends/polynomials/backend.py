"""The polynomials backend: a derived polynomial set as plain text, LaTeX, and JSON that loads back
into sympy (polynomials/<name>.{txt,tex,json})."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import sympy as sp

from ... import derivation
from ...hashing import content_hash
from ...templating import Templates

_spec = derivation("spec")
Entry, PolynomialSet = _spec.Entry, _spec.PolynomialSet

TEMPLATES = Templates(Path(__file__).parent / "templates")


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


def rows(ps: PolynomialSet) -> tuple[list[dict], dict[str, str]]:
    """The template context of each entry (its text, LaTeX, degree, terms), and {symbol: its assumption}."""
    out = []
    symbols = {}
    for e in ps.entries:
        for s in sorted((e.expr.free_symbols | (e.rhs.free_symbols if e.rhs is not None else set())), key=str):
            symbols[str(s)] = _assumption(s)
        out.append(
            {
                "label": e.label,
                "note": e.note,
                "text": collected(e.expr, e.variables, sp.sstr) + ("" if e.rhs is None else f" = {sp.sstr(e.rhs)}"),
                "latex": collected(e.expr, e.variables, sp.latex) + ("" if e.rhs is None else f" = {sp.latex(e.rhs)}"),
                "lhs": sp.sstr(e.expr),
                "rhs": None if e.rhs is None else sp.sstr(e.rhs),
                "variables": [str(v) for v in e.variables],
                **describe(e),
            }
        )
    return out, symbols


def render_polynomial_set(ps: PolynomialSet, hasher: Callable[[list[str]], str] = content_hash) -> dict[str, str]:
    """{path under generated/: text} of one set's text, LaTeX and JSON files."""
    entries, symbols = rows(ps)
    txt, txt_src = TEMPLATES("polynomials.txt.j2")
    tex, tex_src = TEMPLATES("polynomials.tex.j2")
    digest = hasher([txt_src, tex_src, json.dumps(entries, sort_keys=True)])
    ctx = {"ps": ps, "rows": entries, "hash": digest}
    data = {
        "name": ps.name,
        "title": ps.title,
        "source": ps.source,
        "description": ps.description,
        "content_hash": digest,
        "symbols": dict(sorted(symbols.items())),
        "entries": [
            {k: r[k] for k in ("label", "note", "lhs", "rhs", "variables", "degree", "terms")} for r in entries
        ],
    }
    return {
        f"polynomials/{ps.name}.txt": txt.render(**ctx),
        f"polynomials/{ps.name}.tex": tex.render(**ctx),
        f"polynomials/{ps.name}.json": json.dumps(data, indent=1, sort_keys=True) + "\n",
    }


def render(poly_sets: list[PolynomialSet]) -> dict[str, str]:
    """The text, LaTeX and JSON files of polynomial sets."""
    files: dict[str, str] = {}
    for ps in poly_sets:
        files.update(render_polynomial_set(ps))
    return files
