"""The one emitter: lower kernel specs with CSE, render them with jinja2, write generated/.

`lower` turns a KernelSpec into straight-line code (assignments after common-subexpression
elimination); `Emitter.render` hands the lowered kernels of each derivation to the templates in
codegen/templates and returns {relative path: text}. Output is deterministic: the same specs give
byte-identical files, each naming the derivation that produced it and a content hash of its inputs
(the kernel specs and the template).
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import jinja2
import sympy as sp

from derivations.spec import Arg, KernelSpec, PolynomialSet

from .printers import CPrinter, NumpyPrinter
from .polynomials import render_polynomial_set

TEMPLATES = Path(__file__).parent / "templates"
PREFIX = "apair_"


@dataclass
class Lowered:
    """A kernel as straight-line code, ready for the templates."""

    spec: KernelSpec
    inputs: list[tuple[Arg, list[tuple[int, str]]]]  # each input with the (slot, name) it reads
    assignments: list[tuple[str, sp.Expr]]
    outputs: list[tuple[Arg, list[sp.Expr]]]
    ops: int

    @property
    def name(self) -> str:
        return self.spec.name


def lower(spec: KernelSpec) -> Lowered:
    """Straight-line code for a spec: its steps and outputs after CSE, in dependency order.

    The steps are kept as named assignments (they are the derivation's own common subexpressions,
    so a recursion stays linear in size); CSE runs over the step expressions and outputs with the
    step symbols free, and the CSE temporaries are then placed just before their first use. Steps
    that no output needs are dropped.
    """
    arrays = {a.name for a in spec.inputs + spec.outputs}
    local = {}  # a scalar named like an array argument is renamed, e.g. theta -> theta_v
    for a in spec.inputs:
        for s in a.symbols:
            if str(s) in arrays:
                local[s] = sp.Symbol(f"{s}_v", real=True)
            if str(s).startswith("t") and str(s)[1:].isdigit():
                raise ValueError(f"{spec.name}: input symbol {s} clashes with CSE temporaries")
    outputs = [sp.S(e).xreplace(local) for a in spec.outputs for e in a.exprs]
    needed = set().union(*(e.free_symbols for e in outputs)) if outputs else set()
    steps = []
    for sym, expr in reversed(spec.steps):
        if sym in needed:
            expr = expr.xreplace(local)
            steps.append((sym, expr))
            needed |= expr.free_symbols
    steps.reverse()
    exprs = [e for _, e in steps] + outputs
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t"), order="canonical")
    assignments = _ordered(replacements, [(s, e) for (s, _), e in zip(steps, reduced[: len(steps)])])
    reduced = reduced[len(steps):]
    used = set()
    for _, e in assignments:
        used |= e.free_symbols
    for e in reduced:
        used |= sp.S(e).free_symbols
    inputs = []
    for a in spec.inputs:
        syms = [local.get(s, s) for s in a.symbols]
        inputs.append((a, [(k, str(s)) for k, s in enumerate(syms) if s in used]))
    outs, pos = [], 0
    for a in spec.outputs:
        outs.append((a, list(reduced[pos:pos + a.size])))
        pos += a.size
    ops = int(sp.count_ops([e for _, e in assignments] + list(reduced)))
    return Lowered(spec, inputs, [(str(s), e) for s, e in assignments], outs, ops)


def _ordered(replacements, steps):
    """Steps in their order, each preceded by the CSE temporaries it needs (first use first)."""
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


def _shape_doc(a: Arg) -> str:
    return " x ".join(str(s) for s in a.shape)


class Emitter:
    """Renders lowered kernels to C, NumPy and the manifest; polynomial sets to text/LaTeX/JSON."""

    def __init__(self):
        self.env = jinja2.Environment(
            loader=jinja2.FileSystemLoader(TEMPLATES),
            keep_trailing_newline=True,
            trim_blocks=True,
            lstrip_blocks=True,
            undefined=jinja2.StrictUndefined,
        )
        self.c = CPrinter()
        self.np = NumpyPrinter()
        self.env.filters["c"] = self.c.doprint
        self.env.filters["py"] = self.np.doprint
        self.env.filters["shape"] = _shape_doc

    def _template(self, name: str) -> tuple[jinja2.Template, str]:
        return self.env.get_template(name), (TEMPLATES / name).read_text()

    def render(self, groups: dict[str, list[KernelSpec]], poly_sets: list[PolynomialSet]) -> dict[str, str]:
        """groups: {derivation module stem: its kernel specs} -> {path under generated/: text}."""
        files: dict[str, str] = {}
        lowered = {stem: [lower(s) for s in specs] for stem, specs in groups.items() if specs}  # skip set-only ones
        all_kernels = [k for ks in lowered.values() for k in ks]
        fingerprints = {k.name: k.spec.fingerprint() for k in all_kernels}

        header_t, header_src = self._template("apair.h.j2")
        src_t, src_src = self._template("kernels.c.j2")
        py_t, py_src = self._template("kernels.py.j2")
        header_hash = content_hash([header_src] + [fingerprints[k.name] for k in all_kernels])
        sources = sorted({k.spec.source for k in all_kernels})
        files["c/apair.h"] = header_t.render(kernels=all_kernels, hash=header_hash, sources=sources, prefix=PREFIX)
        manifest = {"content_hash": header_hash, "prefix": PREFIX, "kernels": {}}
        for stem, ks in lowered.items():
            source = ks[0].spec.source
            c_hash = content_hash([src_src] + [fingerprints[k.name] for k in ks])
            py_hash = content_hash([py_src] + [fingerprints[k.name] for k in ks])
            files[f"c/{stem}.c"] = src_t.render(kernels=ks, source=source, hash=c_hash, prefix=PREFIX)
            files[f"numpy/{stem}.py"] = py_t.render(kernels=ks, source=source, hash=py_hash)
            for k in ks:
                manifest["kernels"][k.name] = {
                    "module": stem,
                    "source": source,
                    "doc": k.spec.doc,
                    "inputs": [{"name": a.name, "shape": list(a.shape), "doc": a.doc} for a in k.spec.inputs],
                    "outputs": [{"name": a.name, "shape": list(a.shape), "doc": a.doc} for a in k.spec.outputs],
                    "ops": k.ops,
                    "fingerprint": fingerprints[k.name][:16],
                }
        files["numpy/__init__.py"] = self.env.get_template("numpy_init.py.j2").render(
            modules=sorted(lowered), kernels=sorted((k.name, stem) for stem, ks in lowered.items() for k in ks),
            hash=header_hash)
        files["manifest.json"] = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
        files["__init__.py"] = (f'"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.\n\n'
                                f'Content hash: {header_hash}\n"""\n')
        for ps in poly_sets:
            files.update(render_polynomial_set(ps, content_hash))
        return files


def content_hash(parts: list[str]) -> str:
    """The 16-hex-digit SHA-256 of the parts (NUL-separated) that a generated file is made from."""
    h = hashlib.sha256()
    for p in parts:
        h.update(p.encode())
        h.update(b"\0")
    return h.hexdigest()[:16]


def write(files: dict[str, str], out: Path, clean: bool = True, keep: tuple[str, ...] = ()) -> list[str]:
    """Write files under `out`; with `clean`, remove generated files no longer produced (except
    those whose path starts with one of `keep`: another step writes them). Returns changes."""
    changed = []
    out.mkdir(parents=True, exist_ok=True)
    for rel, text in sorted(files.items()):
        path = out / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
            changed.append(rel)
    if clean:
        for path in sorted(out.rglob("*")):
            rel = path.relative_to(out).as_posix()
            if path.is_file() and rel not in files and "__pycache__" not in rel and not rel.startswith(keep):
                path.unlink()
                changed.append(f"removed {rel}")
    return changed
