"""The specialised-chain backend (`apair codegen`): the code of one chain with its design built in
(derivations/specialised.py), as a small C99 library with its own prefix: name.h, name.c, a
self-test against reference values of the runtime, CMakeLists.txt, name.pc.in, a NumPy module
name.py and manifest.json; and the registry in apair.h's form by which AChain.specialise() loads it.

Its kernels have no design inputs (nothing to hoist); a composite kernel calls its parts (the
kernels it is built from) one block of items at a time.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from ...ir import Lowered, LoweredCall
from ...templating import VERSION, Templates, TemplateSource
from ..c.backend import TEMPLATES as C_TEMPLATES
from ..numpy import module as numpy_module
from ..numpy.backend import TEMPLATES as NUMPY_TEMPLATES

TEMPLATES = Templates(Path(__file__).parent / "templates", *C_TEMPLATES.folders, *NUMPY_TEMPLATES.folders)


@dataclass
class PartCall:
    """A composite kernel's call of a part, as chain.c.j2 writes it."""

    index: int  # its results are r<index>
    part: Lowered
    size: int  # of its output
    args: list[str]  # its arguments for one item
    block_args: list[str]  # ... for item k0 + j of a block (an earlier part's results at j)
    used: bool  # the finish reads some of its results


@dataclass
class ChainKernel:
    """A kernel with what chain.c.j2 needs of its calls."""

    kernel: Lowered
    calls: list[PartCall]
    finish: list[tuple[str, str]]  # the finish's assignments: the results it reads (name, "r<i>[j]"), then its code


def _part_call(i: int, c: LoweredCall, parts: dict[str, Lowered]) -> PartCall:
    block = [
        f"{arg} + j * {a.size}" if arg[:1] == "r" and arg[1:].isdigit() else f"{arg} + (k0 + j) * {a.size}"
        for arg, a in c.args
    ]
    return PartCall(i, parts[c.kernel], c.out.size, [arg for arg, _ in c.args], block, bool(c.results))


def chain_kernel(k: Lowered, parts: dict[str, Lowered]) -> ChainKernel:
    """The template context of one kernel."""
    results = [(name, f"r{i}[{j}]") for i, c in enumerate(k.calls) for j, name in c.results]
    return ChainKernel(k, [_part_call(i, c, parts) for i, c in enumerate(k.calls)], results + k.c.assignments)


def render(
    kernels: list[Lowered],
    parts: dict[str, Lowered],
    name: str,
    meta: dict,
    tests: list[dict],
    template: TemplateSource = TEMPLATES,
) -> dict[str, str]:
    """The chain's files: name.h, name.c, name.py, name_selftest.c, CMakeLists.txt, name.pc.in and
    manifest.json. `parts`: the kernels that `kernels` call, by name; `meta`: title, origin (the
    chain file), joints, ranges, n, hash; `tests`: per kernel checked {kernel (Lowered), inputs:
    [(Arg, values)], outputs: [(Arg, values)]}, values as C literals."""
    for k in kernels + list(parts.values()):
        if k.hoisted or any(c.kernel not in parts for c in k.calls):
            raise ValueError(f"{k.name}: a specialised kernel has no design inputs, and its parts are given")
    ctx = dict(meta, name=name, kernels=kernels, version=VERSION, guard=f"{name.upper()}_H")
    files = {}
    for source, out in (
        ("chain.h.j2", f"{name}.h"),
        ("chain_CMakeLists.txt.j2", "CMakeLists.txt"),
        ("chain.pc.in.j2", f"{name}.pc.in"),
    ):
        files[out] = template(source)[0].render(**ctx)
    views = [chain_kernel(k, parts) for k in kernels]
    files[f"{name}.c"] = template("chain.c.j2")[0].render(**dict(ctx, kernels=views))
    count = len(tests[0]["inputs"][0][1]) // tests[0]["inputs"][0][0].size if tests else 0
    files[f"{name}_selftest.c"] = template("chain_selftest.c.j2")[0].render(**ctx, count=count, tests=tests)
    files[f"{name}.py"] = numpy_module(
        list(parts.values()) + kernels,
        meta["origin"],
        meta["hash"],
        constants=[("N", meta["n"]), ("CONTENT_HASH", repr(meta["hash"]))],
        template=template,
    )
    manifest = {
        "content_hash": meta["hash"],
        "prefix": name,
        "n": meta["n"],
        "origin": meta["origin"],
        "kernels": {
            k.name: {
                "inputs": [{"name": a.name, "shape": list(a.shape)} for a in k.spec.inputs],
                "outputs": [{"name": a.name, "shape": list(a.shape)} for a in k.spec.outputs],
                "ops": k.ops,
            }
            for k in kernels
        },
    }
    files["manifest.json"] = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
    return files


def render_registry(kernels: list[Lowered], name: str, hash: str, template: TemplateSource = TEMPLATES) -> str:
    """The registry of a specialised chain's kernels in apair.h's form (for the runtime)."""
    return template("chain_registry.c.j2")[0].render(kernels=kernels, name=name, hash=hash)
