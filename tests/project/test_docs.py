"""The documentation's examples run as written, and the site's generated parts are complete.

Every ```python block of README.md and docs/**/*.md runs, the blocks of one page in order in one
namespace, in a fresh interpreter whose working directory is a temporary folder holding a copy of
examples/ (so `apair.load("examples/4a_chain.toml")` works as it does from the repository root and
nothing is written into the repository). In ```console blocks every line `$ apair ...` runs too
(through the console script's entry point, `apair.cli.main`) and must exit with status 0; other `$`
lines, such as cmake or cc, are shown, not run. A ```c block that is a whole program (it has
`main`) is compiled strictly against the generated C library and must run with status 0. A block
opts out only with `<!-- skip-test: reason -->` on the line before its fence.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md"] + sorted(DOCS.rglob("*.md"))
FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<lang>[\w-]*)[^\n]*\n(?P<body>.*?)^(?P=indent)```[ \t]*$", re.M | re.S)
SKIP = re.compile(r"^\s*<!--\s*skip-test:\s*(?P<reason>\S.*?)\s*-->\s*$")
MAX_SKIPS = 3  # opting out is for what cannot run here or would take the run past a minute, never for a failure


@dataclass
class Block:
    lang: str
    code: str
    line: int  # of the block's first code line in the page, from 1
    skip: str | None  # the reason given by a skip-test marker


def blocks(path: Path) -> list[Block]:
    """The fenced code blocks of a Markdown page, with the skip-test marker before each."""
    text = path.read_text()
    out = []
    for m in FENCE.finditer(text):
        before = text[: m.start()].rstrip("\n").rsplit("\n", 1)[-1]
        skip = SKIP.match(before)
        indent = len(m.group("indent"))
        code = "\n".join(line[indent:] for line in m.group("body").split("\n"))
        out.append(Block(m.group("lang"), code, text.count("\n", 0, m.start()) + 2, skip and skip.group("reason")))
    return out


def commands(block: Block) -> list[str]:
    return [line[2:] for line in block.code.splitlines() if line.startswith("$ apair ")]


def runnable(block: Block) -> bool:
    return (
        block.lang == "python"
        or (block.lang == "console" and bool(commands(block)))
        or (block.lang == "c" and re.search(r"^int main\(", block.code, re.M) is not None)
    )


# Runs in a fresh interpreter: the page's blocks (JSON on stdin) in order, in one namespace.
RUNNER = r"""
import json, shlex, subprocess, sys
page = json.load(sys.stdin)
namespace = {"__name__": "__main__"}
for block in page["blocks"]:
    if block["lang"] == "python":
        code = compile("\n" * (block["line"] - 1) + block["code"], page["path"], "exec")
        exec(code, namespace)
        continue
    if block["lang"] == "c":
        exe = f"./program{block['line']}"
        with open(exe + ".c", "w") as f:
            f.write(block["code"])
        for argv in (page["cc"] + [exe + ".c"] + page["link"] + ["-o", exe], [exe]):
            done = subprocess.run(argv, capture_output=True, text=True)
            if done.returncode != 0:
                sys.exit(f"{page['path']}:{block['line']}: `{' '.join(argv[:3])} ...` exited with "
                         f"{done.returncode}:\n{done.stdout[-2000:]}{done.stderr[-2000:]}")
        continue
    from apair import cli  # the console script's own entry point, in this process

    for command in block["commands"]:
        try:
            code = cli.main(shlex.split(command)[1:])
        except SystemExit as exc:  # --help, --version, argparse's usage errors
            code = exc.code
        if code not in (0, None):
            sys.exit(f"{page['path']}:{block['line']}: `$ {command}` exited with {code}")
"""


def relative(path: Path) -> str:
    return str(path.relative_to(ROOT))


def c_build() -> tuple[list[str], list[str]]:
    """The compiler command for a program of the docs, and how to link the generated library:
    build/libapair.so (make lib) where it is newer than every generated source, else the sources."""
    c_dir = ROOT / "generated" / "c"
    cc = [os.environ.get("CC", "cc"), "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", f"-I{c_dir}"]
    lib = ROOT / "build" / "libapair.so"
    sources = sorted(c_dir.glob("*.c"))
    if lib.exists() and all(p.stat().st_mtime <= lib.stat().st_mtime for p in [*sources, c_dir / "apair.h"]):
        return cc, [f"-L{lib.parent}", "-lapair", f"-Wl,-rpath,{lib.parent}", "-lm"]
    return cc, ["-O0", *map(str, sources), "-lm"]


def run_page(path: Path, workdir: Path) -> subprocess.CompletedProcess:
    """Run the page's runnable blocks in `workdir` (a copy of examples/ is put there first)."""
    shutil.copytree(
        ROOT / "examples", workdir / "examples", ignore=shutil.ignore_patterns("__pycache__"), dirs_exist_ok=True
    )
    todo = [
        {"lang": b.lang, "code": b.code, "line": b.line, "commands": commands(b)}
        for b in blocks(path)
        if runnable(b) and b.skip is None
    ]
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONWARNINGS="default")
    cc, link = c_build()
    page = {"path": relative(path), "blocks": todo, "cc": cc, "link": link}
    return subprocess.run(
        [sys.executable, "-c", RUNNER],
        input=json.dumps(page),
        cwd=workdir,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


PAGES_WITH_CODE = [p for p in PAGES if any(runnable(b) for b in blocks(p))]


@pytest.mark.parametrize("path", PAGES_WITH_CODE, ids=relative)
@pytest.mark.slow
def test_page_examples_run(path, tmp_path):
    done = run_page(path, tmp_path)
    assert done.returncode == 0, f"{relative(path)}:\n{done.stdout[-3000:]}\n{done.stderr[-6000:]}"


def test_examples_are_collected_and_opt_outs_are_rare():
    every = [(p, b) for p in PAGES for b in blocks(p)]
    assert sum(b.lang == "python" for _, b in every) >= 20
    assert sum(bool(commands(b)) for _, b in every) >= 5
    skipped = [(relative(p), b.line, b.skip) for p, b in every if b.skip]
    assert len(skipped) <= MAX_SKIPS, skipped
    for page in ("README.md", "docs/tutorial.md"):
        assert not any(s[0] == page for s in skipped), f"{page} must run in full"
    # a skip marker must sit right before a fence, or it would silently skip nothing
    for p in PAGES:
        markers = len(re.findall(r"<!--\s*skip-test:", p.read_text()))
        assert markers == sum(bool(b.skip) for b in blocks(p)), relative(p)


def test_block_parser_handles_indentation_and_markers(tmp_path):
    page = tmp_path / "p.md"
    page.write_text(
        "text\n\n<!-- skip-test: needs a cluster -->\n```python\nx = 1\n```\n\n- item\n\n"
        "    ```console\n    $ apair list\n    output\n    ```\n"
    )
    got = blocks(page)
    assert [(b.lang, b.line, b.skip) for b in got] == [("python", 5, "needs a cluster"), ("console", 11, None)]
    assert commands(got[1]) == ["apair list"]


# ------------------------------------------------------------------------------------ generated pages
def hook():
    spec = importlib.util.spec_from_file_location("docs_benchmarks_hook", DOCS / "hooks" / "benchmarks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_benchmark_tables_come_from_the_results_file():
    h = hook()
    page = (DOCS / "benchmarks.md").read_text()
    names = set(h.MARKER.findall(page))
    assert names == set(h.SECTIONS), "every section is on the page, and only known ones"
    results = h.load(DOCS)
    rendered = h.render(page, results)
    assert not h.MARKER.search(rendered)
    assert "This results file has no" not in rendered, "the committed results cover every table"
    six = results["kernels"]["6"]["fk"]
    assert h.duration(six["c_batched"]["median_ns"]) in rendered  # a number from the file, not typed
    # bench/run.py's structure: the keys it writes (and the provenance record)
    written = set(re.findall(r'results\["([a-z_0-9]+)"\]', (ROOT / "bench" / "run.py").read_text()))
    written |= {"machine", "settings", "kernels"}
    assert set(results) - {"source"} <= written, set(results) - written
    # a partial run (--native-only, no peers) renders with notes instead of failing
    partial = {
        "native": {
            "R-chain": {"n": 6, "tools": {"apair -O2": results["native"]["R-chain"]["tools"]["apair -O2"]}},
            "apair_ops_per_item": results["native"]["apair_ops_per_item"],
        }
    }
    text = h.render(page, partial)
    assert "This results file has no" in text and not h.MARKER.search(text)
    # a run with the derivatives of the dynamics: their rows, with the numbers of the file
    tools = {
        name: {"ns": {**t["ns"], "inverse_dynamics_derivatives": 1234.0 + k, "forward_dynamics_derivatives": 4321.0}}
        for k, (name, t) in enumerate(results["native"]["R-chain"]["tools"].items())
        if not name.startswith("apair_specialised")
    }
    single = {"c_single_api": {"median_ns": 5678.0}, "pinocchio_per_call": {"median_ns": 2839.0}}
    with_derivatives = dict(
        results,
        native=dict(results["native"], **{"R-chain": dict(results["native"]["R-chain"], tools=tools)}),
        derivatives_single={"inverse_dynamics_derivatives": single, "forward_dynamics_derivatives": single},
    )
    text = h.render(page, with_derivatives)
    assert h.OP_NAMES["inverse_dynamics_derivatives"] in text and "| 4321 (" in text
    assert "`forward_dynamics_derivatives` / `computeABADerivatives` | 5678 (2.00)" in text
    with pytest.raises(ValueError, match="unknown benchmark section"):
        h.render("<!-- bench:no-such-table -->", results)


def test_cli_reference_has_every_command_and_option():
    """Every command of `apair --help` has its section in reference/cli.md, naming all its options."""

    import contextlib
    import io

    from apair import cli

    def help_of(*argv):
        out = io.StringIO()
        with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
            cli.main([*argv, "--help"])
        return out.getvalue()

    names = re.search(r"\{([a-z,-]+)\}", help_of()).group(1).split(",")
    page = (DOCS / "reference" / "cli.md").read_text()
    sections = dict(re.findall(r"^## `apair ([a-z-]+)`\n(.*?)(?=^## |\Z)", page, re.M | re.S))
    for name in names:
        assert name in sections, f"apair {name} is not in reference/cli.md"
        argv = [name, "mjcf"] if name == "export" else [name]
        for option in set(re.findall(r"(?<![\w-])(--[a-z][a-z-]*)", help_of(*argv))) - {"--help"}:
            assert option in sections[name], f"apair {name} {option} is not in reference/cli.md"


def test_api_reference_covers_the_public_api():
    import apair

    page = (DOCS / "reference" / "apair.md").read_text()
    for name in apair.__all__:
        if name in ("plots", "polynomials", "__version__"):
            assert name == "__version__" or (DOCS / "reference" / f"{name}.md").exists(), name
            continue
        assert f"::: apair.{name}\n" in page, f"apair.{name} is not in reference/apair.md"
    assert "::: apair.ik\n" in (DOCS / "reference" / "ik.md").read_text()


def test_site_builds_strictly(tmp_path):
    """`make docs`: any warning (a broken link or anchor, an unreadable docstring) fails it."""
    mkdocs = Path(sys.executable).with_name("mkdocs")
    if not mkdocs.exists():
        pytest.skip("mkdocs is not installed (the docs extra)")
    done = subprocess.run(
        [str(mkdocs), "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=dict(os.environ, NO_MKDOCS_2_WARNING="1"),
    )
    assert done.returncode == 0, done.stderr[-4000:]
    assert (tmp_path / "site" / "benchmarks" / "index.html").exists()
