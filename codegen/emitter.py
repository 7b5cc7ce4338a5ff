"""The one emitter: lower kernel specs with CSE, render them with jinja2, write generated/.

`lower` turns a KernelSpec into straight-line code (assignments after common-subexpression
elimination), printed for C and NumPy; `Emitter.render` hands the lowered kernels of each
derivation to the templates in codegen/templates and returns {relative path: text};
`Emitter.render_chain` does the same for one chain's specialised kernels (`apair codegen`). Lowering is
the expensive part and is independent per kernel, so codegen/__main__.py runs it in parallel.
Output is deterministic: the same specs give byte-identical files, each naming the derivation that
produced it and a content hash of its inputs (the kernel specs and the template).
"""
from __future__ import annotations

import hashlib
import json
import tomllib
from dataclasses import dataclass
from pathlib import Path

import jinja2
import sympy as sp

from . import derivation
from .printers import CPrinter, JSPrinter, NumpyPrinter
from .polynomials import render_polynomial_set

_spec = derivation("spec")
Arg, KernelSpec, PolynomialSet = _spec.Arg, _spec.KernelSpec, _spec.PolynomialSet

TEMPLATES = Path(__file__).parent / "templates"
PREFIX = "apair_"


def _version() -> str:
    """The package version: from pyproject.toml in the source tree, else the installed apair's."""
    project = Path(__file__).resolve().parent.parent / "pyproject.toml"
    if project.is_file():
        return tomllib.loads(project.read_text())["project"]["version"]
    from importlib.metadata import version

    return version("apair")


VERSION = _version()  # stamped into the C library (header, CMake, pkg-config)


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

    inv_inputs: list[tuple[Arg, list[tuple[int, str]]]]
    invariants: list[tuple[str, str]]
    stored: list[str]
    core_inputs: list[tuple[Arg, list[tuple[int, str]]]]
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
    """A kernel as printed straight-line code, ready for the templates (cheap to pickle)."""

    spec: Signature
    inputs: list[tuple[Arg, list[tuple[int, str]]]]  # each input with the (slot, name) it reads
    c: Code
    py: Code
    ops: int
    fingerprint: str
    hoisted: Hoisted | None  # None: nothing depends on design inputs alone
    calls: list[LoweredCall]  # kernels evaluated first (their own hoisting applies)
    js: Code | None = None  # for WEB_KERNELS only

    @property
    def name(self) -> str:
        return self.spec.name


PRINTERS = {"c": CPrinter(), "py": NumpyPrinter()}
# The kernels the browser viewer (apair view) evaluates, printed as JavaScript too: the pair laws,
# one joint's transform (the page multiplies them into every frame) and the leg end points.
WEB_KERNELS = ("law_revolute", "law_sinusoidal", "law_general", "fk1", "pair_legs")
JS = JSPrinter()


def _bare(a: Arg) -> Arg:
    return Arg(a.name, tuple(a.shape), a.doc, design=a.design)


def _slots(spec_inputs, local, used) -> list[tuple[Arg, list[tuple[int, str]]]]:
    """Each input with the (slot, name) pairs of its symbols in `used`."""
    out = []
    for a in spec_inputs:
        syms = [local.get(s, s) for s in a.symbols]
        out.append((_bare(a), [(k, str(s)) for k, s in enumerate(syms) if s in used]))
    return out


def _hoist(spec: KernelSpec, local: dict, assignments, reduced, printed: dict) -> Hoisted | None:
    """Split the assignments into those that depend on design inputs alone and the rest
    (`printed`: the C text of each assignment)."""
    design = {local.get(s, s) for a in spec.inputs if a.design for s in a.symbols}
    if not design:
        return None
    invariant = set()
    for sym, e in assignments:
        if e.free_symbols <= design | invariant:
            invariant.add(sym)
    inv = [(sym, e) for sym, e in assignments if sym in invariant]
    core = [(sym, e) for sym, e in assignments if sym not in invariant]
    needed = set().union(*(e.free_symbols for _, e in core), *(sp.S(e).free_symbols for e in reduced))
    stored = [sym for sym, _ in inv if sym in needed]
    if not stored:
        return None
    used_inv = set().union(*(e.free_symbols for _, e in inv))
    return Hoisted(_slots(spec.inputs, local, used_inv), [(str(s), printed[s]) for s, _ in inv],
                   [str(s) for s in stored], _slots(spec.inputs, local, needed),
                   [(str(s), printed[s]) for s, _ in core],
                   int(sp.count_ops([e for _, e in core] + [sp.S(e) for e in reduced])))


def lower(spec: KernelSpec) -> Lowered:
    """Straight-line code for a spec: its steps and outputs after CSE, in dependency order.

    The steps are kept as assignments (they are the derivation's own common subexpressions, so a
    recursion stays linear in size); CSE runs over the step expressions and outputs with the step
    symbols free, and the CSE temporaries are then placed just before their first use. Steps that
    no output needs are dropped, and all intermediates are renamed t0, t1, ... in order.
    """
    arrays = {a.name for a in spec.inputs + spec.outputs}
    local = {}  # a scalar named like an array argument is renamed, e.g. theta -> theta_v
    for a in spec.inputs:
        for s in a.symbols:
            if str(s) in arrays:
                local[s] = sp.Symbol(f"{s}_v", real=True)
            if str(s).startswith("t") and str(s)[1:].isdigit():
                raise ValueError(f"{spec.name}: input symbol {s} clashes with CSE temporaries")
    for c in spec.calls:
        for r in c.results:
            if str(r).startswith("t") and str(r)[1:].isdigit() or str(r) in arrays:
                raise ValueError(f"{spec.name}: result symbol {r} clashes with a temporary or an argument")
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
    # a step that is only another name (of a symbol or a number) is substituted away
    alias, kept = {}, []
    for s, e in assignments:
        e = e.xreplace(alias) if alias else e
        if e.is_Symbol or e.is_Number:
            alias[s] = e
        else:
            kept.append((s, e))
    reduced = [sp.S(e).xreplace(alias) for e in reduced]
    live = set().union(*(sp.S(e).free_symbols for e in reduced)) if reduced else set()
    assignments = []
    for s, e in reversed(kept):  # and what nothing uses any more is dropped
        if s in live:
            assignments.append((s, e))
            live |= e.free_symbols
    assignments.reverse()
    # every intermediate becomes t0, t1, ... in order of definition: short lines, small sources
    rename = {s: sp.Symbol(f"t{k}", real=True) for k, (s, _) in enumerate(assignments)}
    assignments = [(rename[s], e.xreplace(rename)) for s, e in assignments]
    reduced = [sp.S(e).xreplace(rename) for e in reduced]
    used = set()
    for _, e in assignments:
        used |= e.free_symbols
    for e in reduced:
        used |= sp.S(e).free_symbols
    inputs = _slots(spec.inputs, local, used)
    outs, pos = [], 0
    for a in spec.outputs:
        outs.append((a, list(reduced[pos:pos + a.size])))
        pos += a.size
    ops = int(sp.count_ops([e for _, e in assignments] + list(reduced)))
    printed = {target: {s: p.doprint(e) for s, e in assignments} for target, p in PRINTERS.items()}
    code = {target: Code([(str(s), printed[target][s]) for s, _ in assignments],
                         [(_bare(a), [p.doprint(e) for e in es]) for a, es in outs])
            for target, p in PRINTERS.items()}
    signature = Signature(spec.name, spec.doc, spec.source, [_bare(a) for a in spec.inputs],
                          [_bare(a) for a in spec.outputs], spec.wide)
    calls = [LoweredCall(c.kernel.name, [(name, _bare(a)) for name, a in zip(c.args, c.kernel.inputs)],
                         _bare(c.kernel.outputs[0]), [(i, str(r)) for i, r in enumerate(c.results) if r in used])
             for c in spec.calls]
    for c, call in zip(spec.calls, calls):
        if c.kernel.source != spec.source:
            raise ValueError(f"{spec.name}: calls {c.kernel.name} from another derivation")
        for name, a in call.args:
            if a.design and name is None:
                raise ValueError(f"{spec.name}: {c.kernel.name}'s design input {a.name} cannot be zeros")
    hoisted = _hoist(spec, local, assignments, reduced, printed["c"])
    if spec.wide and (spec.calls or hoisted is None):
        raise ValueError(f"{spec.name}: a wide kernel needs a design-only part and calls no other kernel "
                         "(the template emits its wide version from the hoisted core)")
    js = None
    if spec.name in WEB_KERNELS:
        if spec.calls:
            raise ValueError(f"{spec.name}: a web kernel cannot call other kernels")
        js = Code([(str(s), JS.doprint(e)) for s, e in assignments], [(_bare(a), [JS.doprint(e) for e in es]) for a, es in outs])
    return Lowered(signature, inputs, code["c"], code["py"], ops, spec.fingerprint(), hoisted, calls, js)


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
        self.env.filters["shape"] = _shape_doc
        self.env.filters["dims"] = lambda a: ", ".join(str(d) for d in (tuple(a.shape) + (0, 0, 0))[:3])

    def _template(self, name: str) -> tuple[jinja2.Template, str]:
        """The template and its text (with the shared C macros' text for a C template), for hashes."""
        text = (TEMPLATES / name).read_text()
        if '"c_macros.j2"' in text:
            text += (TEMPLATES / "c_macros.j2").read_text()
        return self.env.get_template(name), text

    def render(self, lowered: dict[str, list[Lowered]], poly_files: dict[str, str]) -> dict[str, str]:
        """lowered: {derivation module stem: its lowered kernels}; poly_files: the rendered
        polynomial sets (`render_polynomials`) -> {path under generated/: text}."""
        files: dict[str, str] = dict(poly_files)
        lowered = {stem: ks for stem, ks in lowered.items() if ks}  # skip set-only derivations
        all_kernels = [k for ks in lowered.values() for k in ks]
        fingerprints = {k.name: k.fingerprint for k in all_kernels}
        by_name = {k.name: k for k in all_kernels}
        inv_sizes = {k.name: _invariant_size(k, by_name) for k in all_kernels if k.hoisted or k.calls}

        header_t, header_src = self._template("apair.h.j2")
        src_t, src_src = self._template("kernels.c.j2")
        py_t, py_src = self._template("kernels.py.j2")
        sources = sorted({k.spec.source for k in all_kernels})
        registry_t, registry_src = self._template("registry.c.j2")
        files["c/apair_registry.c"] = registry_t.render(
            kernels=sorted(all_kernels, key=lambda k: k.name), prefix=PREFIX, sources=sources, inv_sizes=inv_sizes,
            hash=content_hash([registry_src] + [fingerprints[k.name] for k in all_kernels]))
        # one C file per kernel: a program that links the library takes only the kernels it calls
        called = sorted({c.kernel for k in all_kernels for c in k.calls})
        for name in called:
            if by_name[name].hoisted is None:
                raise ValueError(f"{name} is called by another kernel but has no design-only part to share")
        wide = [k for k in all_kernels if k.spec.wide]
        internal = sorted(set(called) | {k.name for k in wide})
        internal_t, internal_src = self._template("apair_internal.h.j2")
        files["c/apair_internal.h"] = internal_t.render(
            kernels=[by_name[c] for c in called], wide=wide, prefix=PREFIX,
            sources=sorted({by_name[c].spec.source for c in internal}) or ["no derivation (no internal kernel)"],
            hash=content_hash([internal_src] + [fingerprints[c] for c in internal]))
        for k in all_kernels:
            c_hash = content_hash([src_src, fingerprints[k.name]] + [fingerprints[c.kernel] for c in k.calls])
            files[f"c/{k.name}.c"] = src_t.render(kernels=[k], source=k.spec.source, hash=c_hash, prefix=PREFIX,
                                                  by_name=by_name, called=called, inv_sizes=inv_sizes)
        ik_t, ik_src = self._template("ik.c.j2")
        ik_inv = [inv_sizes.get(k.name, 0) for k in all_kernels if k.name.startswith("ik_system")]
        files["c/apair_ik.c"] = ik_t.render(prefix=PREFIX, inv_max=max(ik_inv + [1]),
                                            hash=content_hash([ik_src, str(max(ik_inv + [1]))]))
        c_sources = sorted(["apair_registry.c", "apair_ik.c"] + [f"{k.name}.c" for k in all_kernels])
        # the header's hash covers every C source the binding compiles (so their templates too)
        header_hash = content_hash([header_src, VERSION] + [fingerprints[k.name] for k in all_kernels]
                                   + [files[f"c/{c}"] for c in c_sources] + [files["c/apair_internal.h"]])
        files["c/apair.h"] = header_t.render(kernels=all_kernels, hash=header_hash, sources=sources, prefix=PREFIX,
                                             version=VERSION, inv_sizes=inv_sizes)
        for name in ("CMakeLists.txt", "apair.pc.in"):
            t, src = self._template(f"{name}.j2")
            files[f"c/{name}"] = t.render(sources=sources, c_sources=c_sources, version=VERSION,
                                          hash=content_hash([src, VERSION] + c_sources))
        manifest = {"content_hash": header_hash, "prefix": PREFIX, "kernels": {},
                    "sources_hash": sources_hash({rel[2:]: text for rel, text in files.items()
                                                  if rel.startswith("c/") and rel.endswith((".c", ".h"))})}
        for stem, ks in lowered.items():
            source = ks[0].spec.source
            py_hash = content_hash([py_src] + [fingerprints[k.name] for k in ks])
            files[f"numpy/{stem}.py"] = py_t.render(kernels=ks, source=source, hash=py_hash)
            for k in ks:
                manifest["kernels"][k.name] = {
                    "module": stem,
                    "source": source,
                    "doc": k.spec.doc,
                    "inputs": [{"name": a.name, "shape": list(a.shape), "doc": a.doc} for a in k.spec.inputs],
                    "outputs": [{"name": a.name, "shape": list(a.shape), "doc": a.doc} for a in k.spec.outputs],
                    "ops": k.ops,
                    # per item of a batch that shares its design (callees counted in)
                    "ops_per_item": _ops_per_item(k, by_name),
                    "fingerprint": fingerprints[k.name][:16],
                }
        web = sorted((k for k in all_kernels if k.js is not None), key=lambda k: k.name)
        if sorted(k.name for k in web) == sorted(WEB_KERNELS):  # (not all derivations run: --only)
            js_t, js_src = self._template("kernels.js.j2")
            files["js/apair_kernels.js"] = js_t.render(
                kernels=web, sources=sorted({k.spec.source for k in web}),
                hash=content_hash([js_src] + [fingerprints[k.name] for k in web]))
        files["numpy/__init__.py"] = self.env.get_template("numpy_init.py.j2").render(
            modules=sorted(lowered), kernels=sorted((k.name, stem) for stem, ks in lowered.items() for k in ks),
            hash=header_hash)
        files["__init__.py"] = (f'"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.\n\n'
                                f'Content hash: {header_hash}\n"""\n')
        manifest["files"] = sorted(set(files) | {"manifest.json"})  # what a later run may replace or remove
        files["manifest.json"] = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
        return files

    def render_chain(self, kernels: list[Lowered], parts: dict[str, Lowered], name: str, meta: dict,
                     tests: list[dict]) -> dict[str, str]:
        """The code of one chain with its design built in (derivations/specialised.py): name.h,
        name.c, name.py, name_selftest.c, CMakeLists.txt, name.pc.in and manifest.json;
        `parts`: the kernels that `kernels` call, by name; `meta`: title, origin (the chain file),
        joints, ranges, n, hash; `tests`: per kernel checked {kernel (Lowered), inputs:
        [(Arg, values)], outputs: [(Arg, values)]}, values as C literals."""
        for k in kernels + list(parts.values()):
            if k.hoisted or any(c.kernel not in parts for c in k.calls):
                raise ValueError(f"{k.name}: a specialised kernel has no design inputs, and its parts are given")
        ctx = dict(meta, name=name, kernels=kernels, parts=parts, version=VERSION, guard=f"{name.upper()}_H")
        files = {}
        for template, out in (("chain.h.j2", f"{name}.h"), ("chain.c.j2", f"{name}.c"),
                              ("chain_CMakeLists.txt.j2", "CMakeLists.txt"), ("chain.pc.in.j2", f"{name}.pc.in")):
            files[out] = self._template(template)[0].render(**ctx)
        count = len(tests[0]["inputs"][0][1]) // tests[0]["inputs"][0][0].size if tests else 0
        files[f"{name}_selftest.c"] = self._template("chain_selftest.c.j2")[0].render(**ctx, count=count, tests=tests)
        files[f"{name}.py"] = self._template("kernels.py.j2")[0].render(
            kernels=list(parts.values()) + kernels, source=meta["origin"], hash=meta["hash"],
            constants=[("N", meta["n"]), ("CONTENT_HASH", repr(meta["hash"]))])
        manifest = {"content_hash": meta["hash"], "prefix": name, "n": meta["n"], "origin": meta["origin"],
                    "kernels": {k.name: {"inputs": [{"name": a.name, "shape": list(a.shape)} for a in k.spec.inputs],
                                         "outputs": [{"name": a.name, "shape": list(a.shape)} for a in k.spec.outputs],
                                         "ops": k.ops} for k in kernels}}
        manifest["files"] = sorted(set(files) | {"manifest.json"})
        files["manifest.json"] = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
        return files

    def render_chain_registry(self, kernels: list[Lowered], name: str, hash: str) -> str:
        """The registry of a specialised chain's kernels in apair.h's form (for the runtime)."""
        return self._template("chain_registry.c.j2")[0].render(kernels=kernels, name=name, hash=hash)


def _invariant_size(k: Lowered, by_name: dict) -> int:
    """Doubles of a kernel's split form: its own invariants after those of the kernels it calls."""
    own = len(k.hoisted.stored) if k.hoisted else 0
    return own + sum(len(by_name[c.kernel].hoisted.stored) for c in k.calls)


def _ops_per_item(k: Lowered, by_name: dict) -> int:
    own = k.hoisted.core_ops if k.hoisted else k.ops
    return own + sum(_ops_per_item(by_name[c.kernel], by_name) for c in k.calls)


def render_polynomials(poly_sets: list[PolynomialSet]) -> dict[str, str]:
    """The text, LaTeX and JSON files of polynomial sets."""
    files: dict[str, str] = {}
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


def sources_hash(texts: dict[str, str]) -> str:
    """SHA-256 of the C files the binding compiles ({file name: text}, in name order). setup.py
    computes the same digest of the files it actually compiles and builds it into apair._native,
    so the runtime notices a build from other sources than the manifest's (even a hand edit)."""
    h = hashlib.sha256()
    for name in sorted(texts):
        h.update(name.encode() + b"\0" + texts[name].encode() + b"\0")
    return h.hexdigest()


class OutputError(Exception):
    """The output folder is not one the generator may write into."""


def owned_files(out: Path) -> set[str] | None:
    """The files a previous run wrote into `out` (from its manifest.json), or None when `out`
    holds no manifest of ours."""
    try:
        data = json.loads((out / "manifest.json").read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or "kernels" not in data or "content_hash" not in data:
        return None
    return set(data.get("files", []))


def write(files: dict[str, str], out: Path, clean: bool = True) -> list[str]:
    """Write files under `out`; with `clean`, remove the files an earlier run listed in its
    manifest that are no longer produced, and nothing else. A non-empty `out` that holds no
    manifest of ours is refused (OutputError): its files belong to someone else. Returns the
    changes."""
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out: {out} is not a folder")
    previous = owned_files(out) if out.exists() else set()
    if previous is None and any(out.iterdir()):
        raise OutputError(f"--out: {out} is not empty and was not written by codegen (no manifest.json of "
                          "ours): give an empty or new folder")
    changed = []
    out.mkdir(parents=True, exist_ok=True)
    for rel, text in sorted(files.items()):
        path = out / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
            changed.append(rel)
    if clean:
        for rel in sorted((previous or set()) - set(files)):
            path = out / rel
            if path.is_file():
                path.unlink()
                changed.append(f"removed {rel}")
    return changed
