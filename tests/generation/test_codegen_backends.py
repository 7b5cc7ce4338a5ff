"""The code generator's layout: lowering passes, one backend per target, hand-written C as plain C.

Quick checks of the structure (`make check` compares the whole of generated/ with a regeneration):
the lowering passes on a small spec, each backend's files from its own templates, the facade
(codegen.emitter) giving the same files, and generated/c/apair_ik*.{c,h} as copies of src/csrc.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import sympy as sp

from codegen import emitter
from codegen.backends import c as c_backend
from codegen.backends import chain, js, numpy, polynomials
from codegen.ir import Arg, KernelSpec
from codegen.lowering import lower
from codegen.lowering.cse import drop_aliases, drop_unused, rename
from codegen.lowering.order import ordered
from codegen.lowering.symbols import local_names
from codegen.render import render_all

ROOT = Path(__file__).resolve().parents[2]
BACKENDS = ROOT / "codegen" / "backends"


def small_spec(**kw) -> KernelSpec:
    x, y, a = sp.symbols("x y a", real=True)
    s1, s2 = sp.symbols("s1 s2", real=True)
    inputs = [Arg("q", (2,), "state", (x, y)), Arg("dh", (1,), "design", (a,), design=True)]
    outputs = [Arg("out", (2,), "result", exprs=(s2 * sp.cos(a), s2 + sp.cos(a) * x))]
    return KernelSpec(
        kw.pop("name", "small"),
        "A small kernel.",
        "derivations/test.py",
        inputs,
        outputs,
        steps=[(s1, x * y), (s2, s1 + sp.sin(x))],
        **kw,
    )


def test_lowering_passes():
    spec = small_spec()
    low = lower(spec)
    assert [name for name, _ in low.c.assignments] == [f"t{k}" for k in range(len(low.c.assignments))]
    assert low.c.assignments == [("t0", "x*y"), ("t1", "t0 + sin(x)"), ("t2", "cos(a)")]
    assert low.c.outputs[0][1] == ["t1*t2", "t1 + t2*x"] and low.py.assignments[2] == ("t2", "numpy.cos(a)")
    assert low.hoisted is not None and low.hoisted.invariants == [("t2", "cos(a)")]  # the design's part
    assert low.hoisted.stored == ["t2"] and [n for n, _ in low.hoisted.core] == ["t0", "t1"]
    assert low.js is None  # only the viewer's kernels are printed as JavaScript
    # the passes one by one
    t0, t1, u = sp.symbols("t0 t1 u")
    kept, reduced = drop_aliases([(t0, u), (t1, t0 + 1)], [t1 * 2])
    assert kept == [(t1, u + 1)] and reduced == [2 * t1]
    assert drop_unused([(t0, u + 1), (t1, u + 2)], [t1]) == [(t1, u + 2)]
    assert rename([(u, t0 + 1)], [u]) == ([(sp.Symbol("t0", real=True), t0 + 1)], [sp.Symbol("t0", real=True)])
    assert ordered([(t0, u + 1), (t1, t0 * 2)], [(u, sp.Symbol("v")), (sp.Symbol("w"), t1)]) == [
        (u, sp.Symbol("v")),
        (t0, u + 1),
        (t1, 2 * t0),
        (sp.Symbol("w"), t1),
    ]


def test_symbol_check():
    x = sp.Symbol("q", real=True)  # a scalar named like its array is renamed
    spec = KernelSpec(
        "k", "doc", "derivations/test.py", [Arg("q", (1,), "q", (x,))], [Arg("out", (1,), "out", exprs=(x * 2,))]
    )
    assert local_names(spec)[x] == sp.Symbol("q_v", real=True)
    t = sp.Symbol("t3", real=True)
    bad = KernelSpec(
        "k", "doc", "derivations/test.py", [Arg("q", (1,), "q", (t,))], [Arg("out", (1,), "out", exprs=(t * 2,))]
    )
    with pytest.raises(ValueError, match="clashes with CSE temporaries"):
        lower(bad)


def test_each_backend_renders_from_its_own_templates():
    low = {"test": [lower(small_spec())]}
    files = render_all(low, {})
    assert files == emitter.Emitter().render(low, {})  # the facade asks the same backends
    library = c_backend.render(low["test"])
    assert set(library.files) < set(files) and files["manifest.json"].count(library.content_hash) == 1
    assert set(numpy.render(low, library.content_hash)) == {"numpy/test.py", "numpy/__init__.py"}
    assert js.render(low["test"]) == {}  # not the viewer's kernels
    assert "c/apair_ik_track.c" in files and "c/apair_ik_internal.h" in files and "c/small.c" in files


def test_templates_sit_with_their_backend_and_stay_small():
    for folder in BACKENDS.glob("*/templates"):
        for t in folder.iterdir():
            assert t.suffix == ".j2" and len(t.read_text().splitlines()) <= 400, t
    assert not (ROOT / "codegen" / "templates").exists()
    names = [t.name for t in BACKENDS.glob("*/templates/*.j2")]
    assert len(names) == len(set(names))  # emitter.Emitter finds them all by name
    assert {p.parent.name for p in BACKENDS.glob("*/backend.py")} == {
        "c",
        "numpy",
        "js",
        "polynomials",
        "chain",
        "casadi",
    }
    assert chain.render_registry and polynomials.render_polynomial_set


def test_hand_written_c_is_copied_verbatim():
    copies = c_backend.backend.copies()
    sources = sorted(p for p in (ROOT / "src" / "csrc").iterdir() if p.suffix in (".c", ".h"))
    assert sorted(copies) == [p.name for p in sources] and "apair_ik_track.c" in copies
    for path in sources:
        source = path.read_text()
        assert "{{" not in source and "{%" not in source  # plain C, not a template
        copy = (ROOT / "generated" / "c" / path.name).read_text()
        assert copy.endswith(source) and copy == copies[path.name]
