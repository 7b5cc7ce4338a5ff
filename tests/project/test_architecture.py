"""The shape of the runtime package: its import graph is free of cycles (imports inside functions
counted: grimp, import-linter's graph builder, reads them all), and no hand-written module (nor
hand-written C source or header under src) is over MAX_LINES lines. The layers (what may use
what) are import-linter's contracts in .importlinter, checked by `make lint`."""

from __future__ import annotations

from pathlib import Path

import pytest

grimp = pytest.importorskip("grimp")

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT / "src" / "apair"
MAX_LINES = 800


def _graph():
    """apair's own modules and the imports among them (the mapped apair.generated, apair.codegen
    and apair.derivations live outside src/apair and are not in the graph)."""
    return grimp.build_graph("apair", include_external_packages=False, cache_dir=None)


def _cycle(graph, modules: set[str]) -> list[str]:
    """One shortest cycle through the strongly connected `modules` (a breadth-first search from
    each back to itself), as [m0, m1, ..., m0]."""
    best: list[str] = []
    for start in sorted(modules):
        parent = {start: None}
        frontier, found = [start], None
        while frontier and found is None:
            nxt = []
            for m in frontier:
                for k in sorted(graph.find_modules_directly_imported_by(m) & modules):
                    if k == start:
                        found = m
                        break
                    if k not in parent:
                        parent[k] = m
                        nxt.append(k)
                if found is not None:
                    break
            frontier = nxt
        if found is None:
            continue
        path = [found]
        while parent[path[-1]] is not None:
            path.append(parent[path[-1]])
        cycle = path[::-1] + [start]
        if not best or len(cycle) < len(best):
            best = cycle
    return best


def _components(graph) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out: list[set[str]] = []
    counter = 0
    for root in sorted(graph.modules):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.find_modules_directly_imported_by(child)))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    m = stack.pop()
                    on_stack.discard(m)
                    component.add(m)
                    if m == node:
                        break
                if len(component) > 1:
                    out.append(component)
    return out


def test_import_graph_has_no_cycle():
    """No module of apair imports (directly or through others, at the top or inside a function)
    a module that imports it back."""
    graph = _graph()
    assert "apair.chain" in graph.modules  # the graph is the package's
    cycles = []
    for component in _components(graph):
        cycle = _cycle(graph, component)
        lines = []
        for a, b in zip(cycle, cycle[1:]):
            details = graph.get_import_details(importer=a, imported=b)
            where = f" (line {details[0]['line_number']}: {details[0]['line_contents']})" if details else ""
            lines.append(f"  {a} -> {b}{where}")
        cycles.append(
            f"{len(component)} modules in a cycle ({', '.join(sorted(component))}), e.g.\n" + "\n".join(lines)
        )
    assert not cycles, "import cycles in apair:\n" + "\n".join(cycles)


def test_no_hand_written_module_is_too_long():
    """Every Python module under src/apair, and every hand-written C source and header under src
    (the binding src/apair/_native*, the solvers src/csrc), has at most MAX_LINES lines."""
    paths = [p for p in SOURCE.rglob("*.py") if "__pycache__" not in p.parts]
    c_files = [p for p in (ROOT / "src").rglob("*") if p.suffix in (".c", ".h") and p.is_file()]
    sizes = {p.relative_to(ROOT).as_posix(): len(p.read_text(encoding="utf-8").splitlines()) for p in paths + c_files}
    assert paths and c_files
    long = {p: n for p, n in sorted(sizes.items()) if n > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_test_files_have_unique_names():
    """pytest imports test modules by their base name (rootdir import mode): two test_x.py in
    different folders would stop the collection of the second."""
    names = [p.name for p in (Path(__file__).resolve().parents[1]).rglob("test_*.py")]
    assert sorted(n for n in set(names) if names.count(n) > 1) == []


def test_every_subpackage_ships():
    """Every package folder under src/apair is listed in pyproject's packages: a wheel (not the
    editable install the tests use) would leave out one that is not."""
    import tomllib

    root = Path(__file__).resolve().parents[2]
    listed = set(tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    src = root / "src" / "apair"
    found = {"apair." + ".".join(p.parent.relative_to(src).parts) for p in src.rglob("__init__.py")}
    assert sorted(found - {"apair."} - listed) == []


def test_no_test_imports_from_a_conftest():
    """Helpers shared between folders live in tests/apair_test_helpers.py: `from conftest import`
    resolves to whichever folder's conftest pytest loaded first (tests/design has its own)."""
    tests = Path(__file__).resolve().parents[1]
    offenders = [
        str(p.relative_to(tests))
        for p in tests.rglob("*.py")
        if any(line.startswith(("from conftest import", "import conftest")) for line in p.read_text().splitlines())
    ]
    assert offenders == []
