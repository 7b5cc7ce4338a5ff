"""Compiled programs that time apair's generated C and its C/C++ peers on the same chain and states.

Each tool gets a small program, compiled with the same flags, that reads the same binary input
file (the states of `count` poses and the chain's design), evaluates every operation over all poses
in round-robin rounds, and prints the minimum ns per evaluation of each operation over the rounds
as JSON; it also writes its results for the first poses so that agreement is checked before any
timing is reported (each program first runs one untimed warm-up round). apair's path is the one a C user takes: each joint's law kernel (one sincos
per joint), then the chain kernel's batch function with the design shared by the batch. The
derivatives of the dynamics (DERIVATIVES) take each joint's law value and the law's third
derivative: the law kernel and the law_<kind>_d3 kernel per joint, then the derivative kernel's
batch function, all three inside the timing.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CHECKED = 16  # poses whose results each program writes for the agreement check

# the chain kernel, its per-pose inputs (after law) and its output size, per operation
OPERATIONS = {
    "fk": ("fk", (), lambda n: 16),
    "jacobian": ("jacobian", (), lambda n: 6 * n),
    "mass_matrix": ("mass_matrix", (), lambda n: n * n),
    "inverse_dynamics": ("inverse_dynamics", ("qd", "qdd"), lambda n: n),
    "forward_dynamics": ("forward_dynamics", ("qd", "tau"), lambda n: n),
}

# the derivatives of the dynamics: per-pose inputs after the law values and the law's third
# derivatives, and the kernel's outputs (each n x n, row-major), in the order every program writes
# them after OPERATIONS' outputs
DERIVATIVES = {
    "inverse_dynamics_derivatives": (("qd", "qdd"), ("dtau_dq", "dtau_dqd")),
    "forward_dynamics_derivatives": (("qd", "tau"), ("dqdd_dq", "dqdd_dqd", "Minv")),
}


def outputs_of(n: int, derivatives: bool) -> list[tuple[str, int]]:
    """(name, values per pose) of what a program writes, in its order: one output per operation of
    OPERATIONS, then (if `derivatives`) each output of DERIVATIVES' kernels."""
    out = [(op, size(n)) for op, (_, _, size) in OPERATIONS.items()]
    if derivatives:
        out += [(name, n * n) for _, names in DERIVATIVES.values() for name in names]
    return out


@dataclass
class States:
    """The poses every tool evaluates: q, qd, qdd, tau (count, n)."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray

    @property
    def count(self) -> int:
        return self.q.shape[0]

    @property
    def n(self) -> int:
        return self.q.shape[1]


def write_inputs(path: Path, chain, states: States) -> None:
    """count, n, then q, qd, qdd, tau, dh, turning, links, legs, gravity (in frame 0), law
    parameters (n) as doubles."""
    law_param = np.array([p.law_kernel[1][0] if p.law_kernel[1] else 0.0 for p in chain.pairs])
    head = np.array([states.count, states.n], dtype=np.float64)
    parts = [
        head,
        states.q,
        states.qd,
        states.qdd,
        states.tau,
        chain._dh,
        chain._turning,
        chain._links,
        chain._legs,
        chain._gravity,  # in the DH base frame (frame 0): Rbᵀ·g, what the kernels take
        law_param,
    ]
    np.concatenate([np.ascontiguousarray(p, dtype=np.float64).ravel() for p in parts]).tofile(path)


PIN_AXES = {"JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2, "JointModelRevoluteUnaligned": 3}


def write_pin_model(path: Path, model, frame: str) -> None:
    """A Pinocchio model of revolute joints (pinocchio.Model, built in Python from DH constants or a
    URDF) for bench/peers/pinocchio_timing.cpp, which rebuilds it: per joint its type (PIN_AXES),
    axis, parent, placement and body inertia; then the frame `frame` (parent joint, placement) and
    the gravity, as doubles."""
    if not model.existFrame(frame):
        raise ValueError(f"frame: no frame {frame!r} in the Pinocchio model")
    rows: list[np.ndarray] = [np.array([model.njoints - 1.0])]
    for j in range(1, model.njoints):
        joint = model.joints[j]
        kind = PIN_AXES.get(joint.shortname())
        if kind is None or joint.nq != 1 or joint.idx_v != j - 1:
            raise ValueError(f"model: joint {model.names[j]} is not a revolute joint in chain order")
        axis = np.asarray(joint.extract().axis, dtype=float) if kind == 3 else np.eye(3)[kind]
        M, body = model.jointPlacements[j], model.inertias[j]
        rows += [np.array([kind]), axis, np.array([model.parents[j]]), M.rotation.ravel(), M.translation]
        rows += [np.array([body.mass]), body.lever, np.asarray(body.inertia).ravel()]
    f = model.frames[model.getFrameId(frame)]
    rows += [np.array([f.parentJoint]), f.placement.rotation.ravel(), f.placement.translation]
    rows.append(np.asarray(model.gravity.linear, dtype=float))
    np.concatenate([np.asarray(r, dtype=np.float64).ravel() for r in rows]).tofile(path)


PEERS = ROOT / "bench" / "peers"  # bench_inputs.h: the input file's reader, shared by every program


FRAME_TOL = 1e-12  # a base or tool frame (or the tool's offset) closer than this to the identity is not applied


def _c_array(name: str, values) -> str:
    return f"static const double {name}[{len(values)}] = {{{', '.join(repr(float(v)) for v in values)}}};"


def frames_code(chain) -> tuple[str, dict[str, str], dict]:
    """The C a user of the generic kernels writes to get the tool's pose and Jacobian in the world
    from a chain with base and tool frames (what AChain.fk and AChain.jacobian do in Python):
    (definitions, {op: code run after the op's batch call, inside the timing}, a description).
    fk: base · T · tool; Jacobian: v + ω × (R_n · tool offset), then both row blocks rotated by the
    base (R_n from the fk kernel, called for it). Frames within FRAME_TOL of the identity are skipped."""
    n = chain.n
    B, T = (np.eye(4) if m is None else m for m in (chain._base_T, chain._tool_T))
    base_rot = bool(np.abs(B[:3, :3] - np.eye(3)).max() > FRAME_TOL)
    base_move = base_rot or bool(np.abs(B[:3, 3]).max() > FRAME_TOL)
    tool_move = bool(np.abs(T - np.eye(4)).max() > FRAME_TOL)
    offset = bool(np.abs(T[:3, 3]).max() > FRAME_TOL)
    about = {"base_applied": base_move, "tool_applied": tool_move, "tool_offset_applied": offset}
    defs = [_c_array("BASE", B.ravel()), _c_array("TOOL", T.ravel()), _c_array("TOFF", T[:3, 3])]
    defs.append("""static double *SCRATCH;
static void rigid(const double *A, const double *B, double *C) /* C = A B, rigid 4 x 4 */
{
    int r, c;
    for (r = 0; r < 3; ++r)
        for (c = 0; c < 4; ++c)
            C[4 * r + c] = A[4 * r] * B[c] + A[4 * r + 1] * B[4 + c] + A[4 * r + 2] * B[8 + c] + (c == 3 ? A[4 * r + 3] : 0.0);
    C[12] = C[13] = C[14] = 0.0;
    C[15] = 1.0;
}""")
    post: dict[str, str] = {}
    if base_move or tool_move:
        steps = []
        if base_move:
            steps.append("rigid(BASE, F, A); for (i = 0; i < 16; ++i) F[i] = A[i];")
        if tool_move:
            steps.append("rigid(F, TOOL, A); for (i = 0; i < 16; ++i) F[i] = A[i];")
        post["fk"] = f"""{{
            long k;
            int i;
            double A[16];
            for (k = 0; k < COUNT; ++k) {{
                double *F = OUT_fk + 16 * k;
                {" ".join(steps)}
            }}
        }}"""
    if offset or base_rot:
        fk_call = f"apair_fk{n}_batch((size_t)COUNT, LAW, {5 * n}, DH, 0, SCRATCH);" if offset else ""
        shift = (
            """const double *F = SCRATCH + 16 * k;
                double r[3];
                for (i = 0; i < 3; ++i) r[i] = F[4 * i] * TOFF[0] + F[4 * i + 1] * TOFF[1] + F[4 * i + 2] * TOFF[2];
                for (c = 0; c < N; ++c) {
                    const double w0 = J[3 * N + c], w1 = J[4 * N + c], w2 = J[5 * N + c];
                    J[c] += w1 * r[2] - w2 * r[1];
                    J[N + c] += w2 * r[0] - w0 * r[2];
                    J[2 * N + c] += w0 * r[1] - w1 * r[0];
                }"""
            if offset
            else ""
        )
        rotate = (
            """for (c = 0; c < N; ++c)
                    for (b = 0; b < 6; b += 3) {
                        const double x = J[b * N + c], y = J[(b + 1) * N + c], z = J[(b + 2) * N + c];
                        for (i = 0; i < 3; ++i) J[(b + i) * N + c] = BASE[4 * i] * x + BASE[4 * i + 1] * y + BASE[4 * i + 2] * z;
                    }"""
            if base_rot
            else ""
        )
        post["jacobian"] = f"""{fk_call}
        {{
            long k;
            int i, c, b;
            (void)b;
            for (k = 0; k < COUNT; ++k) {{
                double *J = OUT_jacobian + 6 * N * k;
                {shift}
                {rotate}
            }}
        }}"""
    return "\n".join(defs), post, about


def apair_program(chain, derivatives: bool = True) -> str:
    """C source timing the generated kernels for `chain`, those its methods call (a chain of
    R-pairs: the REVOLUTE families' forms for it; its pairs' law kernels are fixed here,
    the design is read at run time; the base and tool frames, if any, are applied to fk and the
    Jacobian as frames_code writes them). With `derivatives`, also DERIVATIVES' kernels, each timed
    with the law kernels and the law_<kind>_d3 kernels it needs."""
    n = chain.n
    frame_defs, frame_post, _ = frames_code(chain)
    law_calls, d3_calls = [], []
    for i, p in enumerate(chain.pairs):
        kernel, params = p.law_kernel
        extra = "".join(f", &LAWP[{i}]" for _ in params)
        law_calls.append(f"apair_{kernel}(&q[{i}]{extra}, &law[{5 * i}]);")
        d3_calls.append(f"apair_{kernel}_d3(&q[{i}]{extra}, &d3[{i}]);")
    laws = "\n            ".join(law_calls)
    d3s = "\n            ".join(d3_calls if derivatives else [])
    half = "\n            ".join(f"acc += cos(0.5 * q[{i}]) + sin(0.5 * q[{i}]);" for i in range(n))
    ops_code = []
    for op, (stem, extra, size) in OPERATIONS.items():
        call_inputs = [f"LAW, {5 * n}"]
        for name in extra:
            call_inputs.append(f"{name.upper()}, {n}")
        design = {
            "fk": ["DH, 0"],
            "jacobian": ["DH, 0", "TURN, 0"],
            "mass_matrix": ["DH, 0", "TURN, 0", "LINKS, 0", "LEGS, 0"],
        }.get(op, ["DH, 0", "TURN, 0", "LINKS, 0", "LEGS, 0", "GRAV, 0"])
        ops_code.append(
            (
                op,
                "laws_all();",
                f"apair_{chain._kernel(stem)}_batch((size_t)COUNT, {', '.join(call_inputs + design)}, OUT_{op});",
                [(op, size(n))],
            )
        )
    design_all = "DH, 0, TURN, 0, LINKS, 0, LEGS, 0, GRAV, 0"
    for op, (extra, outputs) in DERIVATIVES.items() if derivatives else ():
        state = ", ".join(f"{x.upper()}, {n}" for x in extra)
        results = ", ".join(f"OUT_{name}" for name in outputs)
        call = (
            f"apair_{chain._kernel(op)}_batch((size_t)COUNT, LAW, {5 * n}, D3, {n}, {state}, {design_all}, {results});"
        )
        ops_code.append((op, "laws_all(); d3_all();", call, [(name, n * n) for name in outputs]))
    body = []
    for op, pre, call, _outs in ops_code:
        body.append(f"""
        t0 = now_ns();
        {pre}
        {call}
        {frame_post.get(op, "")}
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[{len(body)}]) best[{len(body)}] = t;""")
    names = [op for op, _, _, _ in ops_code]
    d3_timing = d3_print = ""  # the law_<kind>_d3 kernels alone, where the program calls them
    if derivatives:
        d3_timing = f"""t0 = now_ns();
        d3_all();
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[{len(names) + 2}]) best[{len(names) + 2}] = t;"""
        d3_print = f'printf(", \\"law_d3_kernels\\": %.3f", best[{len(names) + 2}]);'
    buffers = [buf for _, _, _, bufs in ops_code for buf in bufs]
    outs = "\n".join(f"static double *OUT_{name};" for name, _ in buffers)
    allocs = "\n    ".join(f"OUT_{name} = (double *)malloc(sizeof(double) * COUNT * {size});" for name, size in buffers)
    dumps = "\n    ".join(f"fwrite(OUT_{name}, sizeof(double), {CHECKED} * {size}, f);" for name, size in buffers)
    prints = " ".join(
        f'printf("%s\\"{op}\\": %.3f", "{"{" if k == 0 else ", "}", best[{k}]);' for k, op in enumerate(names)
    )
    return f"""#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "apair.h"
#include "bench_inputs.h"

static double *LAW, *D3;
{outs}
{frame_defs}

static void laws_all(void)
{{
    long k;
    for (k = 0; k < COUNT; ++k) {{
        const double *q = Q + k * {n};
        double *law = LAW + k * {5 * n};
        {laws}
    }}
}}

static void d3_all(void)
{{
    long k;
    for (k = 0; k < COUNT; ++k) {{
        const double *q = Q + k * {n};
        double *d3 = D3 + k * {n};
        {d3s}
    }}
}}

static double trig_only(void)
{{
    double acc = 0;
    long k;
    for (k = 0; k < COUNT; ++k) {{
        const double *q = Q + k * {n};
        {half}
    }}
    return acc;
}}

int main(int argc, char **argv)
{{
    double best[{len(names) + 3}], t0, t, sink = 0;
    int round, k;
    FILE *f;
    if (argc < 4 || read_inputs(argv[1])) return 2;
    LAW = (double *)malloc(sizeof(double) * COUNT * {5 * n});
    D3 = (double *)malloc(sizeof(double) * COUNT * {n});
    SCRATCH = (double *)malloc(sizeof(double) * COUNT * 16);
    {allocs}
    for (k = 0; k < {len(names) + 3}; ++k) best[k] = 1e300;
    for (round = 0; round <= atoi(argv[3]); ++round) {{{"".join(body)}
        t0 = now_ns();
        sink += trig_only();
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[{len(names)}]) best[{len(names)}] = t;
        t0 = now_ns();
        laws_all();
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[{len(names) + 1}]) best[{len(names) + 1}] = t;
        {d3_timing}
    }}
    f = fopen(argv[2], "wb");
    {dumps}
    fclose(f);
    {prints}
    printf(", \\"trig_floor\\": %.3f, \\"law_kernels\\": %.3f", best[{len(names)}], best[{len(names) + 1}]);
    {d3_print}
    printf(", \\"sink\\": %.3g}}\\n", sink);
    return 0;
}}
"""


SPECIALISED = "bench_spec"  # the prefix of the specialised code (apair codegen) timed here


def specialised_program(n: int) -> str:
    """C source timing the chain's specialised kernels (apair codegen): they take q (and qd, qdd
    or tau) only, the design is built in."""
    body, names = [], list(OPERATIONS)
    for k, (op, (_stem, extra, _size)) in enumerate(OPERATIONS.items()):
        args = ", ".join(["Q"] + [x.upper() for x in extra])
        body.append(f"""
        t0 = now_ns();
        {SPECIALISED}_{op}_batch((size_t)COUNT, {args}, OUT_{op});
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[{k}]) best[{k}] = t;""")
    outs = "\n".join(f"static double *OUT_{op};" for op in names)
    allocs = "\n    ".join(
        f"OUT_{op} = (double *)malloc(sizeof(double) * COUNT * {OPERATIONS[op][2](n)});" for op in names
    )
    dumps = "\n    ".join(f"fwrite(OUT_{op}, sizeof(double), {CHECKED} * {OPERATIONS[op][2](n)}, f);" for op in names)
    prints = " ".join(
        f'printf("%s\\"{op}\\": %.3f", "{"{" if k == 0 else ", "}", best[{k}]);' for k, op in enumerate(names)
    )
    return f"""#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>

#include "{SPECIALISED}.h"
#include "bench_inputs.h"

{outs}

int main(int argc, char **argv)
{{
    double best[{len(names)}], t0, t;
    int round, k;
    FILE *f;
    if (argc < 4 || read_inputs(argv[1])) return 2;
    {allocs}
    for (k = 0; k < {len(names)}; ++k) best[k] = 1e300;
    for (round = 0; round <= atoi(argv[3]); ++round) {{{"".join(body)}
    }}
    f = fopen(argv[2], "wb");
    {dumps}
    fclose(f);
    {prints}
    printf("}}\\n");
    return 0;
}}
"""


def specialised_build(chain, workdir: Path, opt: str) -> Path:
    """The timing program of the chain's specialised code (generated once per content hash)."""
    from apair import specialise

    kernels = tuple(OPERATIONS)
    code = workdir / f"specialised_{specialise.content_hash(chain, kernels)}"
    if not (code / f"{SPECIALISED}.c").exists():
        specialise.write_code(chain, code, SPECIALISED, "the bench chain", kernels)
    exe = workdir / f"specialised{chain.n}{opt}"
    source = specialised_program(chain.n)
    return cached(
        exe,
        [source, (code / f"{SPECIALISED}.c").read_text(), opt],
        lambda: compile_c(source, exe, [opt, f"-I{code}", f"-I{PEERS}"], [str(code / f"{SPECIALISED}.c"), "-lm"]),
    )


def pinned(cmd: list[str]) -> list[str]:
    """cmd run on one core (the last one) where taskset exists."""
    taskset = shutil.which("taskset")
    if taskset:
        return [taskset, "-c", str(max(os.cpu_count() or 1, 1) - 1)] + cmd
    return cmd


def compile_c(source: str, out: Path, flags: list[str], extra: list[str]) -> None:
    """gcc -std=c99 FLAGS -DNDEBUG: the flags of the comparison (no fast-math, no -march)."""
    src = out.with_suffix(".c")
    src.write_text(source)
    subprocess.run(["gcc", "-std=c99", *flags, "-DNDEBUG", str(src), *extra, "-o", str(out)], check=True)


def cached(exe: Path, key: list[str], build) -> Path:
    """exe, rebuilt by build() only when `key` (sources and flags) changed since the last build."""
    import hashlib

    digest = hashlib.sha256("\0".join(key).encode()).hexdigest()
    stamp = exe.with_name(exe.name + ".key")
    if exe.exists() and stamp.exists() and stamp.read_text() == digest:
        return exe
    build()
    stamp.write_text(digest)
    return exe


def run_program(exe: Path, inputs: Path, outputs: Path, rounds: int, extra: tuple[str, ...] = ()) -> dict:
    res = subprocess.run(
        pinned([str(exe), str(inputs), str(outputs), str(rounds), *extra]), check=True, capture_output=True, text=True
    )
    return json.loads(res.stdout)


OBJECTS = ROOT / "build" / "bench" / "objects"  # the generated kernels compiled, shared by every chain


def kernel_object(source: Path, opt: str) -> Path:
    """The object file of a generated kernel's C at `opt` (the same gcc flags as compile_c),
    compiled once per content and flags: the derivative kernels take a minute each at -O3."""
    import hashlib

    c_dir = source.parent
    text = "\0".join([source.read_text(), (c_dir / "apair.h").read_text(), opt])
    OBJECTS.mkdir(parents=True, exist_ok=True)
    obj = OBJECTS / f"{source.stem}{opt}_{hashlib.sha256(text.encode()).hexdigest()[:16]}.o"
    if not obj.exists():
        part = obj.with_suffix(".o.part")
        subprocess.run(
            ["gcc", "-std=c99", opt, "-DNDEBUG", f"-I{c_dir}", "-c", str(source), "-o", str(part)], check=True
        )
        part.replace(obj)
    return obj


def apair_build(chain, workdir: Path, opt: str, derivatives: bool = True) -> Path:
    """The apair timing program for `chain`, linked with the generated kernels it calls (each
    compiled once, kernel_object)."""
    c_dir = ROOT / "generated" / "c"
    n = chain.n
    kinds = sorted({p.law_kernel[0] for p in chain.pairs})
    kernels = [chain._kernel(stem) for stem, _, _ in OPERATIONS.values()] + kinds
    if derivatives:
        kernels += [chain._kernel(op) for op in DERIVATIVES] + [f"{k}_d3" for k in kinds]
    exe = workdir / f"apair{n}_{'_'.join(k[4:] for k in kinds)}{'_d' if derivatives else ''}{opt}"
    objects = [str(kernel_object(c_dir / f"{k}.c", opt)) for k in kernels]
    compile_c(apair_program(chain, derivatives), exe, [opt, f"-I{c_dir}", f"-I{PEERS}"], objects + ["-lm"])
    return exe


def read_outputs(path: Path, n: int, derivatives: bool) -> dict:
    """A program's results for the first CHECKED poses: {output name: (CHECKED, size)}."""
    data = np.fromfile(path, dtype=np.float64)
    out, pos = {}, 0
    for name, size in outputs_of(n, derivatives):
        k = CHECKED * size
        out[name] = data[pos : pos + k].reshape(CHECKED, -1)
        pos += k
    return out


def cmeel_prefix() -> Path | None:
    """The prefix holding the C++ headers and libraries of the pin/libpinocchio and cmeel wheels."""
    import site
    import sysconfig

    for base in [sysconfig.get_paths()["purelib"], *site.getsitepackages()]:
        p = Path(base) / "cmeel.prefix"
        if (p / "include" / "pinocchio").is_dir():
            return p
    return None


BOOST_DEFINES = [
    "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
    "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
]


def pinocchio_build(workdir: Path, opt: str) -> Path:
    """Pinocchio's C++ timing program (bench/peers/pinocchio_timing.cpp) at optimisation `opt`."""
    prefix = cmeel_prefix()
    if prefix is None or not (prefix / "include" / "eigen3").is_dir():
        raise RuntimeError("Pinocchio's C++ headers or Eigen are missing: pip install '.[bench]'")
    exe = workdir / f"pinocchio{opt}"
    source = PEERS / "pinocchio_timing.cpp"
    # Pinocchio's own compile definitions for Boost (its CMake config), but not its
    # PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION: the algorithms are compiled here, with these flags
    cmd = [
        "g++",
        "-std=c++17",
        opt,
        "-DNDEBUG",
        *BOOST_DEFINES,
        f"-I{prefix / 'include'}",
        f"-I{prefix / 'include' / 'eigen3'}",
        f"-I{PEERS}",
        str(source),
        "-o",
        str(exe),
    ]
    key = cmd + [source.read_text(), (PEERS / "bench_inputs.h").read_text(), str(prefix)]
    return cached(exe, key, lambda: subprocess.run(cmd, check=True))


def casadi_dirs() -> tuple[Path, Path] | None:
    """(include dir, library dir) of the casadi wheel, or None."""
    try:
        import casadi
    except ImportError:
        return None
    base = Path(casadi.__file__).parent
    if not (base / "include" / "casadi" / "casadi.hpp").is_file():
        return None
    return base / "include", base


def casadi_generate(workdir: Path, inputs: Path) -> Path:
    """CasADi C code of Pinocchio's algorithms for the chain in `inputs` (pin_baked.c, pin_design.c),
    from bench/peers/casadi_codegen.cpp; returns the folder holding them."""
    prefix, dirs = cmeel_prefix(), casadi_dirs()
    if prefix is None or dirs is None:
        raise RuntimeError("Pinocchio's headers or the casadi wheel are missing: pip install '.[bench]'")
    include, lib = dirs
    exe = workdir / "casadi_codegen"
    source = PEERS / "casadi_codegen.cpp"
    cmd = [
        "g++",
        "-std=c++17",
        "-O1",
        *BOOST_DEFINES,
        f"-I{prefix / 'include'}",
        f"-I{prefix / 'include' / 'eigen3'}",
        f"-I{include}",
        f"-I{PEERS}",
        str(source),
        f"-L{lib}",
        "-lcasadi",
        f"-Wl,-rpath,{lib}",
        "-o",
        str(exe),
    ]
    cached(
        exe, cmd + [source.read_text(), (PEERS / "bench_inputs.h").read_text()], lambda: subprocess.run(cmd, check=True)
    )
    out = workdir / f"casadi_c_{inputs.stem}"
    out.mkdir(exist_ok=True)
    res = subprocess.run(
        [str(exe), str(inputs.resolve()), str(out)], check=True, cwd=out, capture_output=True, text=True
    )
    (out / "ops.json").write_text(res.stdout)
    return out


WORK_INT, WORK_REAL = 1 << 14, 1 << 20  # the work arrays given to CasADi's functions (checked)


def casadi_program(n: int, prefix: str, derivatives: bool = True) -> str:
    """C source timing CasADi's generated functions `{prefix}<op>` over the poses, one call per pose
    (with `derivatives`, also DERIVATIVES': CasADi's jacobians of its rnea and aba)."""
    design = prefix == "pind_"
    dynamics = ["DH", "LINKS", "GRAV"]
    specs = {
        "fk": ("Q", [], ["DH"], [("fk", OPERATIONS["fk"][2](n))]),
        "jacobian": ("Q", [], ["DH"], [("jacobian", OPERATIONS["jacobian"][2](n))]),
        "mass_matrix": ("Q", [], ["DH", "LINKS"], [("mass_matrix", n * n)]),
        "inverse_dynamics": ("Q", ["QD", "QDD"], dynamics, [("inverse_dynamics", n)]),
        "forward_dynamics": ("Q", ["QD", "TAU"], dynamics, [("forward_dynamics", n)]),
    }
    for op, (state, names) in DERIVATIVES.items() if derivatives else ():
        specs[op] = ("Q", [x.upper() for x in state], dynamics, [(name, n * n) for name in names])
    blocks, outs, allocs, dumps = [], [], [], []
    for k, (op, (q, state, des, results)) in enumerate(specs.items()):
        fn = f"{prefix}{op}"
        args = [f"{q} + i * {n}"] + [f"{s} + i * {n}" for s in state] + (des if design else [])
        for name, size in results:
            outs.append(f"static double *OUT_{name};")
            allocs.append(f"OUT_{name} = (double *)malloc(sizeof(double) * COUNT * {size});")
            dumps.append(f"fwrite(OUT_{name}, sizeof(double), {CHECKED} * {size}, f);")
        sets = "\n                ".join(f"arg[{j}] = {a};" for j, a in enumerate(args))
        sets += "".join(
            f"\n                res[{j}] = OUT_{name} + i * {size};" for j, (name, size) in enumerate(results)
        )
        # every output a dense column (a sparse one would be written compressed)
        dense = " ".join(
            f"if (!dense_column({fn}_sparsity_out({j}), {size})) return 4;" for j, (_, size) in enumerate(results)
        )
        blocks.append(f"""
        {{
            casadi_int sz_arg, sz_res, sz_iw, sz_w;
            const casadi_real *arg[16];
            casadi_real *res[4];
            long i;
            {fn}_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
            if (sz_arg > 16 || sz_res > 4 || sz_iw > {WORK_INT} || sz_w > {WORK_REAL}) return 3;
            {dense}
            t0 = now_ns();
            for (i = 0; i < COUNT; ++i) {{
                {sets}
                {fn}(arg, res, IW, W, 0);
            }}
            t = (now_ns() - t0) / COUNT;
            if (round > 0 && t < best[{k}]) best[{k}] = t;
        }}""")
    prints = " ".join(
        f'printf("%s\\"{op}\\": %.3f", "{"{" if k == 0 else ", "}", best[{k}]);' for k, op in enumerate(specs)
    )
    return f"""#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "{"pin_design.h" if design else "pin_baked.h"}"
#include "bench_inputs.h"

{chr(10).join(outs)}
static casadi_int IW[{WORK_INT}];
static casadi_real W[{WORK_REAL}];

/* CasADi's sparsity of an output: nrow, ncol, then 1 if dense, else the CCS colind[ncol + 1], row */
static int dense_column(const casadi_int *sp, casadi_int size)
{{
    return sp[0] == size && sp[1] == 1 && (sp[2] == 1 || sp[3] == size);
}}

int main(int argc, char **argv)
{{
    double best[{len(specs)}], t0, t;
    int round, k;
    FILE *f;
    if (argc < 4 || read_inputs(argv[1])) return 2;
    {chr(10).join("    " + a for a in allocs).strip()}
    for (k = 0; k < {len(specs)}; ++k) best[k] = 1e300;
    for (round = 0; round <= atoi(argv[3]); ++round) {{{"".join(blocks)}
    }}
    f = fopen(argv[2], "wb");
    {chr(10).join("    " + d for d in dumps).strip()}
    fclose(f);
    {prints}
    printf("}}\\n");
    return 0;
}}
"""


def casadi_build(workdir: Path, c_dir: Path, n: int, design: bool, opt: str, derivatives: bool = True) -> Path:
    """The timing program of CasADi's C code (design baked or as inputs), rebuilt when it changed."""
    prefix = "pind_" if design else "pin_"
    exe = workdir / f"casadi_{'design' if design else 'baked'}{n}{'_d' if derivatives else ''}{opt}"
    source = c_dir / f"pin_{'design' if design else 'baked'}.c"
    program = casadi_program(n, prefix, derivatives)
    return cached(
        exe,
        [program, opt, source.read_text(), (PEERS / "bench_inputs.h").read_text()],
        lambda: compile_c(program, exe, [opt, f"-I{c_dir}", f"-I{PEERS}"], [str(source), "-lm"]),
    )


# ------------------------------------------------------------------------------------ the comparison
AGREE = 5e-12  # largest relative difference (to the largest |value|) accepted before timing


def _agreement(ref: dict, got: dict) -> dict:
    """{output: largest |got - ref| over the checked poses / max(largest |ref|, 1)}, for the outputs
    both programs wrote."""
    return {op: float(np.max(np.abs(got[op] - ref[op])) / max(np.max(np.abs(ref[op])), 1.0)) for op in ref if op in got}


def compare(
    chain,
    states: States,
    workdir: Path,
    opts=("-O2", "-O3"),
    rounds: int = 7,
    peers: tuple[str, ...] = ("pinocchio", "casadi"),
    log=print,
    pin_model=None,
    pin_frame: str = "end",
    specialised: bool = True,
    derivatives: bool = True,
) -> dict:
    """Every tool on `chain` and `states` at each optimisation level: agreement with apair first,
    then `rounds` round-robin rounds (each program evaluates every operation over all poses once
    per round); the minimum ns per evaluation over the rounds. apair runs with its generic kernels
    ("apair") and, if `specialised`, the chain's own specialised code ("apair_specialised").
    `peers`: "pinocchio" (its C++ on `pin_model`, a pinocchio.Model of the same chain whose joints
    are in chain order, timing the frame `pin_frame`: the tool's, as apair's fk and Jacobian give
    it), "casadi" (its C code of Pinocchio's algorithms on the DH chain of the input file).
    With `derivatives`, also the derivatives of the dynamics (DERIVATIVES): apair's kernels,
    Pinocchio's computeRNEADerivatives and computeABADerivatives, CasADi's jacobians of its rnea
    and aba (the specialised code has none); their outputs are in "difference" by name (dtau_dq,
    ..., Minv)."""
    unknown = set(peers) - {"pinocchio", "casadi"}
    if unknown:
        raise ValueError(f"peers: unknown {sorted(unknown)}; known: pinocchio, casadi")
    if "pinocchio" in peers and pin_model is None:
        raise ValueError("pin_model: a pinocchio.Model is needed to time Pinocchio")
    workdir.mkdir(parents=True, exist_ok=True)
    n = chain.n
    inputs = workdir / f"inputs{n}.bin"
    write_inputs(inputs, chain, states)
    tools: dict[str, Path] = {}
    extra: dict[str, tuple[str, ...]] = {}
    result: dict = {"n": n, "count": states.count, "tools": {}, "skipped": {}, "frames": frames_code(chain)[2]}
    if "pinocchio" in peers:
        model_file = workdir / "pin_model.bin"
        write_pin_model(model_file, pin_model, pin_frame)
    casadi_c = None
    if "casadi" in peers:
        try:
            log("  generating CasADi's C code from Pinocchio on casadi::SX ...")
            casadi_c = casadi_generate(workdir, inputs)
            result["casadi_ops"] = json.loads((casadi_c / "ops.json").read_text())
        except (RuntimeError, subprocess.CalledProcessError) as exc:
            result["skipped"]["casadi"] = str(exc)
    for opt in opts:
        log(f"  building at {opt} ...")
        tools[f"apair {opt}"] = apair_build(chain, workdir, opt, derivatives)
        if specialised:
            tools[f"apair_specialised {opt}"] = specialised_build(chain, workdir, opt)
        if "pinocchio" in peers:
            try:
                tools[f"pinocchio {opt}"] = pinocchio_build(workdir, opt)
                extra[f"pinocchio {opt}"] = (str(model_file),)
            except (RuntimeError, subprocess.CalledProcessError) as exc:
                result["skipped"]["pinocchio"] = str(exc)
        if casadi_c is not None:
            tools[f"casadi_baked {opt}"] = casadi_build(workdir, casadi_c, n, False, opt, derivatives)
            tools[f"casadi_design {opt}"] = casadi_build(workdir, casadi_c, n, True, opt, derivatives)
    outputs = {}
    for name, exe in tools.items():
        run_program(exe, inputs, workdir / "out.bin", 1, extra.get(name, ()))
        with_derivatives = derivatives and not name.startswith("apair_specialised")
        outputs[name] = read_outputs(workdir / "out.bin", n, with_derivatives)
    ref = outputs[f"apair {opts[0]}"]
    best: dict[str, dict] = {name: {} for name in tools}
    for _r in range(rounds):
        for name, exe in tools.items():
            times = run_program(exe, inputs, workdir / "out.bin", 1, extra.get(name, ()))
            for op, t in times.items():
                if op != "sink":
                    best[name][op] = min(best[name].get(op, np.inf), t)
    for name in tools:
        result["tools"][name] = {"ns": best[name], "difference": _agreement(ref, outputs[name])}
    return result
