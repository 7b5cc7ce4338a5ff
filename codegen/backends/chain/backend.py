"""The specialised-chain backend (`apair codegen`): the code of one chain with its design built in
(derivations/specialised.py), as a small C99 library with its own prefix: name.h, name.c, a
self-test against reference values of the runtime, CMakeLists.txt, name.pc.in, a NumPy module
name.py and manifest.json; and the registry in apair.h's form by which AChain.specialise() loads it.

Its kernels have no design inputs (nothing to hoist); a composite kernel calls its parts (the
kernels it is built from) one block of items at a time. A chain with base and tool frames
(meta["frames"]) gets its fk, fk_study and jacobian as name_fk_dh, ... (of frame n in frame 0) and
public name_fk, ... that compose the frames around them (chain_frames.c.j2, chain_frames.py.j2);
without frames the files are those of before frames existed, byte for byte.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

from ...ir import Lowered, LoweredCall, Signature
from ...templating import VERSION, Templates, TemplateSource
from ..c.backend import TEMPLATES as C_TEMPLATES
from ..numpy import module as numpy_module
from ..numpy.backend import TEMPLATES as NUMPY_TEMPLATES

TEMPLATES = Templates(Path(__file__).parent / "templates", *C_TEMPLATES.folders, *NUMPY_TEMPLATES.folders)


# The kernels that base and tool frames change (meta["frames"]): the public name_fk, name_fk_study,
# name_jacobian compose them around the frame-0 kernels name_fk_dh, ... (`dh_kernel`).
FRAMED = ("fk", "fk_study", "jacobian")
_FRAMED_DOCS = {
    "fk": "Forward kinematics of the tool in the world: T = B * (A_1 ... A_{n}) * P, B = {name}_BASE (frame 0 "
    "in the world), A_1 ... A_{n} = {name}_fk_dh, P = {name}_TOOL (the tool in frame {n}).",
    "fk_study": "Study point (x0..x3, y0..y3) of the tool in the world, the dual-quaternion product "
    "{name}_BASE_STUDY * {name}_fk_study_dh * {name}_TOOL_STUDY; x is a unit quaternion, and (x, y) ~ (-x, -y).",
    "jacobian": "Geometric Jacobian (6 x {n}, world frame, rows [v; omega], v the velocity of the tool's origin) of "
    "this chain: with [v_n; omega] = {name}_jacobian_dh, r = R_n p (R_n of {name}_fk_dh, p the tool's "
    "translation), J = [R_B (v_n + omega x r); R_B omega], R_B the base's rotation.",
}
# floating-point operations the composition adds to the frame-0 kernel (manifest.json's ops):
# two 4 x 4 products; two dual-quaternion products (three quaternion products and 4 sums each);
# per column R_B v and R_B omega (and with a tool translation, R_n p once and v + omega x r)
_FRAME_OPS = {"fk": lambda n, p: 224, "fk_study": lambda n, p: 176, "jacobian": lambda n, p: 30 * n + p * (15 + 12 * n)}


def dh_kernel(k: Lowered) -> Lowered:
    """The frame-0 kernel of a chain with frames: fk, fk_study or jacobian as name_dh, of frame n
    in frame 0 (the DH chain without its base and tool)."""
    doc = f"{k.spec.doc} (The DH chain alone, in frame 0, without the base and tool frames.)"
    return replace(k, spec=replace(k.spec, name=f"{k.name}_dh", doc=doc))


def dh_of(k: Lowered) -> Lowered:
    """`dh_kernel` of fk, fk_study, jacobian; any other kernel as it is."""
    return dh_kernel(k) if k.name in FRAMED else k


@dataclass
class FramedKernel:
    """A public kinematic kernel of a chain with frames: its frame-0 kernel `dh` composed with
    the base and tool (chain_frames.c.j2)."""

    spec: Signature
    dh: Lowered
    ops: int

    @property
    def name(self) -> str:
        return self.spec.name


def framed_kernel(k: Lowered, name: str, n: int, offset: bool) -> FramedKernel:
    doc = _FRAMED_DOCS[k.name].format(name=name, n=n)
    return FramedKernel(replace(k.spec, doc=doc), dh_kernel(k), k.ops + _FRAME_OPS[k.name](n, int(offset)))


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
    chain file), joints, ranges, n, hash, and with base and tool frames `frames`
    (apair.specialise.frame_constants); `tests`: per kernel checked {kernel (Lowered, or one with
    the name of the C function tested: name_fk_dh), inputs: [(Arg, values)], outputs: [(Arg,
    values)]}, values as C literals."""
    for k in kernels + list(parts.values()):
        if k.hoisted or any(c.kernel not in parts for c in k.calls):
            raise ValueError(f"{k.name}: a specialised kernel has no design inputs, and its parts are given")
    frames = meta.get("frames")
    public: list[Lowered | FramedKernel] = list(kernels)
    if frames is not None:  # the frame-0 kernels as name_dh, each after its public kernel
        offset = frames["tool_offset"] is not None
        public = []
        for k in kernels:
            public += [framed_kernel(k, name, meta["n"], offset), dh_kernel(k)] if k.name in FRAMED else [k]
        kernels = [dh_of(k) for k in kernels]
    framed = [k.name for k in public if isinstance(k, FramedKernel)]
    ctx = dict(
        meta, name=name, kernels=public, version=VERSION, guard=f"{name.upper()}_H", frames=frames, framed=framed
    )
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
    if frames is not None:
        files[f"{name}.py"] += template("chain_frames.py.j2")[0].render(**ctx)
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
            for k in public
        },
    }
    if frames is not None:
        manifest["frames"] = {"base": frames["base"], "tool": frames["tool"]}
    files["manifest.json"] = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
    return files


def render_registry(kernels: list[Lowered], name: str, hash: str, template: TemplateSource = TEMPLATES) -> str:
    """The registry of a specialised chain's kernels in apair.h's form (for the runtime)."""
    return template("chain_registry.c.j2")[0].render(kernels=kernels, name=name, hash=hash)
