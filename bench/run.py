"""`make bench`: the generated kernels against the tools users would pick instead, in one run.

First the compiled comparison (bench/native.py), what a C user would pick instead: for a 6-joint
chain with random DH constants and links (R-pairs, so every tool models the same chain) and 10 000
random states, apair's generated C (each joint's law kernel, then the chain kernel's batch) against
Pinocchio's C++ compiled from its headers and CasADi's C code generated from Pinocchio's
algorithms on casadi::SX (design baked in, and design as inputs), same gcc flags (-std=c99 or
c++17, -O2 and -O3, -DNDEBUG, no fast-math, no -march), one pinned core, agreement checked first,
minimum over round-robin rounds; the derivatives of the inverse and forward dynamics too (apair's
kernels with the law kernels they need, Pinocchio's computeRNEADerivatives and
computeABADerivatives, CasADi's C code of the jacobians of its rnea and aba); then the A-chain case
(sinusoidal pairs with leg mass), where no peer can follow. Before it (alone: --panda-only) the Panda of example-robot-data imported by
apair.load_urdf (7 joints, base and tool frames) against Pinocchio's C++ on the model it builds from
the same URDF (the fingers locked), and `apair import urdf` of it in a fresh process. Then, from
Python:

For chains of n = 2, 4, 6 joints (random DH constants and links; R-pairs, i.e. A-pairs with h = 0,
so that Pinocchio models exactly the same chain) it times forward kinematics, the Jacobian, the
mass matrix, inverse and forward dynamics with

- the generated C, batched (one call for many poses) and single-call from Python;
- the generated NumPy kernels, batched;
- sympy `lambdify` of the derivation's own expressions (its steps as the common subexpressions),
  called in a Python loop, one pose per call, as a sympy user would;
- symengine `Lambdify` of the same expressions (LLVM backend, with CSE), batched and single-call;
- Pinocchio (`pin`), one call per pose from Python (it has no batched API);

checks that they all agree, and reports per-evaluation medians with min-max over repeats, ratios,
the operation count of each generated kernel after CSE, growth with n and with the batch size,
the time of a whole `make generate`, and inverse kinematics of 4A-chains. And `AChain.ik_local`
one pose and one seed per call, as a controller calls it (alone: --ik-local-only): single calls and
first calls on new chains, against Pinocchio's damped least-squares CLIK loop of its
examples/inverse-kinematics.py on the R-twin chain, same poses and seeds. And the derivatives of
the dynamics one state per call (alone: --derivatives-only) against Pinocchio's binding. Results go to
bench/results.json (or --out). Nothing here is asserted: the targets are reported as met or missed.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import ik_closed  # bench/ is sys.path[0] when run as a script
import numpy as np
from design_bench import design_targets, time_design

import apair
from apair import kernels
from apair.generated.numpy import KERNELS as NUMPY_KERNELS

ROOT = Path(__file__).resolve().parent.parent
OPS = ("fk", "jacobian", "mass_matrix", "inverse_dynamics", "forward_dynamics")


# ------------------------------------------------------------------------------------ timing
def per_item(fn, items: int, repeats: int) -> dict:
    """Median, min and max over `repeats` runs of fn() (which evaluates `items` items) [ns/item]."""
    fn()  # warm-up (first-call set-up, caches)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) / items * 1e9)
    return {"median_ns": float(np.median(times)), "min_ns": float(min(times)), "max_ns": float(max(times))}


def loop(fn, args_list):
    """fn(*args) for every args in the list, as a Python loop."""

    def run():
        for args in args_list:
            fn(*args)

    return run


# ------------------------------------------------------------------------------------ chains
def random_chain(n: int, rng) -> apair.AChain:
    """Random DH constants and solid-box links; R-pairs, so Pinocchio models the same chain."""
    links = []
    for _ in range(n):
        m = rng.uniform(0.5, 3.0)
        x, y, z = rng.uniform(0.05, 0.5, 3)
        principal = m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        links.append(apair.Link(m, rng.uniform(-0.3, 0.3, 3), Q @ np.diag(principal) @ Q.T))
    return apair.AChain(
        [apair.APair.revolute() for _ in range(n)],
        rng.uniform(0.1, 0.5, n),
        rng.uniform(-np.pi, np.pi, n),
        rng.uniform(-0.3, 0.3, n),
        rng.uniform(-np.pi, np.pi, n),
        links=links,
        gravity=(0.0, 0.0, -9.81),
    )


def pin_model(chain: apair.AChain):
    """The chain as a Pinocchio model (revolute joints about z) with a frame "end" at frame n."""
    import pinocchio as pin

    model = pin.Model()
    parent, placement = 0, pin.SE3.Identity()
    for i in range(chain.n):
        parent = model.addJoint(parent, pin.JointModelRZ(), placement, f"r{i}")
        a, alpha, c, phi = chain.a[i], chain.alpha[i], chain.offset[i], chain.theta_offset[i]
        D = (
            pin.SE3(pin.utils.rotate("z", phi), np.zeros(3))
            * pin.SE3(np.eye(3), np.array([0, 0, c]))
            * pin.SE3(np.eye(3), np.array([a, 0, 0]))
            * pin.SE3(pin.utils.rotate("x", alpha), np.zeros(3))
        )
        L = chain.links[i]
        model.appendBodyToJoint(parent, D.act(pin.Inertia(L.mass, L.com, L.inertia)), pin.SE3.Identity())
        placement = D
    model.addFrame(pin.Frame("end", parent, 0, placement, pin.FrameType.OP_FRAME))
    model.gravity = pin.Motion(chain.gravity, np.zeros(3))
    return model


def pin_functions(chain):
    """Per-pose Pinocchio calls returning the same quantities as the kernels."""
    import pinocchio as pin

    model = pin_model(chain)
    data = model.createData()
    fid = model.getFrameId("end")
    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

    def fk_pose(q):  # for the check; the timing leaves the pose in data (kinder to Pinocchio)
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[fid].homogeneous

    timed = {
        "fk": lambda q: pin.framesForwardKinematics(model, data, q),
        "jacobian": lambda q: pin.computeFrameJacobian(model, data, q, fid, world),
        "mass_matrix": lambda q: pin.crba(model, data, q),  # the upper triangle only
        "inverse_dynamics": lambda q, qd, qdd: pin.rnea(model, data, q, qd, qdd),
        "forward_dynamics": lambda q, qd, tau: pin.aba(model, data, q, qd, tau),
    }
    return timed, dict(timed, fk=fk_pose)


# ------------------------------------------------------------------------------------ the same expressions
def specs(n: int) -> dict:
    """The derivation's kernel specs for n joints (fk, jacobian; mass matrix, bias, tau)."""
    from derivations import chain_dynamics, chain_kinematics

    out = {f"fk{n}": chain_kinematics.fk_spec(n), f"jacobian{n}": chain_kinematics.jacobian_spec(n)}
    out.update({s.name: s.flattened() for s in chain_dynamics.specs_for(n)})
    return out


def flat_inputs(spec, inputs: list[np.ndarray]) -> np.ndarray:
    """The kernel inputs as one row of scalars per item, in the spec's symbol order."""
    batch = np.broadcast_shapes(*(x.shape[: x.ndim - len(a.shape)] for x, a in zip(inputs, spec.inputs)))
    cols = [np.broadcast_to(x, batch + tuple(a.shape)).reshape(batch + (a.size,)) for x, a in zip(inputs, spec.inputs)]
    return np.ascontiguousarray(np.concatenate(cols, axis=-1))


def sympy_function(spec):
    """sympy.lambdify of the outputs, with the derivation's steps as the common subexpressions."""
    import sympy as sp

    args = [s for a in spec.inputs for s in a.symbols]
    outs = [e for a in spec.outputs for e in a.exprs]
    return sp.lambdify(args, outs, cse=lambda exprs: (list(spec.steps), exprs))


def symengine_function(spec):
    """symengine.Lambdify (LLVM where available) of the same outputs, the steps substituted in as
    shared subtrees; returns (function, backend)."""
    import symengine as se

    env = {}

    def convert(e):
        x = se.sympify(e)
        sub = {se.Symbol(str(s)): env[s] for s in e.free_symbols if s in env}
        return x.subs(sub) if sub else x

    for sym, e in spec.steps:
        env[sym] = convert(e)
    import sympy as sp

    outs = [convert(sp.S(e)) for a in spec.outputs for e in a.exprs]
    args = [se.Symbol(str(s)) for a in spec.inputs for s in a.symbols]
    try:
        return se.Lambdify(args, outs, cse=True, backend="llvm"), "llvm"
    except (RuntimeError, ValueError, TypeError):  # a symengine built without LLVM
        return se.Lambdify(args, outs, cse=True, backend="lambda"), "lambda"


# ------------------------------------------------------------------------------------ one chain
def bench_chain(n: int, rng, batch: int, single: int, slow: int, repeats: int, pin_ok: bool, se_ok: bool) -> dict:
    chain = random_chain(n, rng)
    sp_specs = specs(n)
    q = rng.uniform(-np.pi, np.pi, (batch, n))
    qd = rng.normal(size=(batch, n))
    qdd = rng.normal(size=(batch, n))
    tau = rng.normal(size=(batch, n))
    design = {
        "dh": chain._dh,
        "turning": chain._turning,
        "links": chain._links,
        "legs": chain._legs,
        "gravity": chain.gravity,
    }
    per_pose = {"law": chain._law(q), "qd": qd, "qdd": qdd, "tau": tau}
    pin_f, pin_check = pin_functions(chain) if pin_ok else ({}, {})
    specialised = chain.specialise()  # compiled once, then found in the cache
    out = {}
    for op in OPS:
        row = {}
        name = f"{op}{n}"
        spec_j = kernels.manifest()["kernels"][name]
        row["kernel"] = name
        row["ops"] = spec_j["ops_per_item"]
        inputs = [per_pose.get(a["name"], design.get(a["name"])) for a in spec_j["inputs"]]
        one = lambda k: [x[k] if a["name"] in per_pose else x for x, a in zip(inputs, spec_j["inputs"])]
        row["c_batched"] = per_item(lambda: kernels.call(name, *inputs), batch, repeats)
        row["c_single"] = per_item(loop(kernels.call, [(name, *one(k)) for k in range(single)]), single, repeats)
        api_args = {
            "fk": lambda k: (q[k],),
            "jacobian": lambda k: (q[k],),
            "mass_matrix": lambda k: (q[k],),
            "inverse_dynamics": lambda k: (q[k], qd[k], qdd[k]),
            "forward_dynamics": lambda k: (q[k], qd[k], tau[k]),
        }[op]
        method = getattr(chain, op)
        row["c_single_api"] = per_item(loop(method, [api_args(k) for k in range(single)]), single, repeats)
        if specialised.specialised:
            row["specialised_single_api"] = per_item(
                loop(getattr(specialised, op), [api_args(k) for k in range(single)]), single, repeats
            )
        row["numpy_batched"] = per_item(lambda: NUMPY_KERNELS[name](*inputs), batch, repeats)
        spec = sp_specs[name]
        flat = flat_inputs(spec, inputs)
        sfun = sympy_function(spec)
        row["lambdify_loop"] = per_item(loop(sfun, [tuple(flat[k]) for k in range(slow)]), slow, repeats)
        reference = kernels.call(
            name, *[x[:10] if a["name"] in per_pose else x for x, a in zip(inputs, spec_j["inputs"])]
        )[0]
        checks = {
            "lambdify": np.array([sfun(*flat[k]) for k in range(10)]),
            "numpy": NUMPY_KERNELS[name](
                *[x[:10] if a["name"] in per_pose else x for x, a in zip(inputs, spec_j["inputs"])]
            ),
        }
        if se_ok:
            efun, backend = symengine_function(spec)
            row["symengine_backend"] = backend
            row["symengine_batched"] = per_item(lambda: efun(flat), batch, repeats)
            row["symengine_single"] = per_item(loop(efun, [(flat[k],) for k in range(single)]), single, repeats)
            checks["symengine"] = efun(flat[:10])
        if pin_ok:
            row["pinocchio_per_call"] = per_item(loop(pin_f[op], [api_args(k) for k in range(single)]), single, repeats)
            got = np.array([pin_check[op](*api_args(k)) for k in range(10)])
            if op == "mass_matrix":
                got = np.triu(got) + np.swapaxes(np.triu(got, 1), -1, -2)
            checks["pinocchio"] = got
        ref = np.asarray(reference).reshape(10, -1)
        row["max_abs_difference"] = {
            k: float(np.max(np.abs(np.asarray(v, dtype=float).reshape(10, -1) - ref))) for k, v in checks.items()
        }
        c = row["c_batched"]["median_ns"]
        ratios = {}
        for peer in ("numpy_batched", "lambdify_loop", "symengine_batched", "pinocchio_per_call"):
            if peer in row:
                ratios[peer] = row[peer]["median_ns"] / c
        row["peer_over_c_batched"] = ratios
        # best of the repeats for both: the overhead itself, without the machine's noise
        row["single_call_overhead_ns"] = row["c_single"]["min_ns"] - row["c_batched"]["min_ns"]
        out[op] = row
    return out


DERIVATIVE_CALLS = {  # the chain's method: Pinocchio's binding, and the state's third argument
    "inverse_dynamics_derivatives": ("computeRNEADerivatives", "qdd"),
    "forward_dynamics_derivatives": ("computeABADerivatives", "tau"),
}


def _symmetric_upper(A: np.ndarray) -> np.ndarray:
    """A's upper triangle mirrored (Pinocchio fills only that part of M and Minv)."""
    return np.triu(A) + np.triu(A, 1).T


def derivatives_single(quick: bool, pin_ok: bool) -> dict:
    """chain.inverse_dynamics_derivatives and chain.forward_dynamics_derivatives, one state per call
    from Python, on a 6-joint R-chain (random_chain's), against Pinocchio's Python binding
    (pin.computeRNEADerivatives, pin.computeABADerivatives, bound to the model and its data) on
    pin_model of the same chain and the same states; per call as bench_chain times the other
    single calls (a loop of calls, median over repeats). All three results of each call are
    compared first (Pinocchio's M and Minv symmetrised), largest |difference| relative to the
    largest value over the first states."""
    from functools import partial

    rng = np.random.default_rng(39)  # its own: the other sections' draws stay as they were
    single, repeats, checked = (200, 3, 10) if quick else (2000, 7, 50)
    n = 6
    chain = random_chain(n, rng)
    state = {
        "q": rng.uniform(-np.pi, np.pi, (single, n)),
        "qd": rng.normal(size=(single, n)),
        "qdd": rng.normal(size=(single, n)),
        "tau": rng.normal(size=(single, n)),
    }
    out: dict = {"n": n, "calls": single}
    model = pin_model(chain) if pin_ok else None
    for op, (pin_name, third) in DERIVATIVE_CALLS.items():
        args = [(state["q"][k], state["qd"][k], state[third][k]) for k in range(single)]
        method = getattr(chain, op)
        row: dict = {"c_single_api": per_item(loop(method, args), single, repeats)}
        if model is not None:
            import pinocchio as pin

            peer = partial(getattr(pin, pin_name), model, model.createData())
            worst = 0.0
            for a in args[:checked]:
                mine = method(*a)
                theirs = [np.array(x) for x in peer(*a)]
                theirs[2] = _symmetric_upper(theirs[2])  # M (dtau_da) or Minv
                for x, y in zip(mine, theirs):
                    worst = max(worst, float(np.abs(x - y).max() / max(np.abs(x).max(), 1.0)))
            row["pinocchio_per_call"] = per_item(loop(peer, args), single, repeats)
            row["max_relative_difference"] = worst
            row["apair_over_pinocchio"] = row["c_single_api"]["median_ns"] / row["pinocchio_per_call"]["median_ns"]
        out[op] = row
    return out


def derivatives_single_targets(r: dict) -> list[dict]:
    """Issue 39's: the Python single calls <= 1.0 x Pinocchio's binding, and the same results."""
    out = []
    for op, (pin_name, _) in DERIVATIVE_CALLS.items():
        row = r.get(op, {})
        if "apair_over_pinocchio" not in row:
            continue
        ratio = row["apair_over_pinocchio"]
        out.append(
            {
                "target": f"Python single call, chain.{op}, n = 6: <= 1.0 x pin.{pin_name}",
                "measured": ratio,
                "met": ratio <= 1.0,
            }
        )
        out.append(
            {
                "target": f"chain.{op} agrees with pin.{pin_name} to {DERIVATIVE_AGREE:g} relative",
                "measured": row["max_relative_difference"],
                "met": row["max_relative_difference"] <= DERIVATIVE_AGREE,
            }
        )
    return out


def print_derivatives_single(r: dict) -> None:
    print(f"\nderivatives of the dynamics from Python, n = {r['n']} R-chain, one state per call ({r['calls']} calls):")
    for op, (pin_name, _) in DERIVATIVE_CALLS.items():
        row = r[op]
        line = f"  chain.{op:30s}median {fmt(row['c_single_api']['median_ns'])}"
        if "pinocchio_per_call" in row:
            line += (
                f"; pin.{pin_name} {fmt(row['pinocchio_per_call']['median_ns'])} "
                f"(apair / pin {row['apair_over_pinocchio']:.2f}); largest difference "
                f"{row['max_relative_difference']:.1e} relative"
            )
        print(line)


def batch_scaling(n: int, rng, repeats: int) -> dict:
    """ns per item of the C kernels against the batch size (one call per batch)."""
    chain = random_chain(n, rng)
    out = {}
    for op in ("fk", "inverse_dynamics"):
        name = f"{op}{n}"
        rows = {}
        for size in (1, 10, 100, 1000, 10_000, 100_000):
            q = rng.uniform(-np.pi, np.pi, (size, n))
            args = {
                "law": chain._law(q),
                "qd": q,
                "qdd": q,
                "dh": chain._dh,
                "turning": chain._turning,
                "links": chain._links,
                "legs": chain._legs,
                "gravity": chain.gravity,
            }
            inputs = [args[a["name"]] for a in kernels.manifest()["kernels"][name]["inputs"]]
            calls = max(1, 20_000 // size)
            rows[size] = per_item(loop(kernels.call, [(name, *inputs)] * calls), size * calls, repeats)
        out[name] = rows
    return out


def time_generate() -> float:
    """Seconds for the whole derivation and code generation (`make generate`), into a scratch folder."""
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "codegen", "--out", tmp],
            cwd=ROOT,
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        return time.perf_counter() - t0


def time_codegen(chain) -> float:
    """Wall time of `apair codegen` (every kernel) for a 6-joint chain in a fresh process: the chain
    is written as a chain file first."""
    num = lambda x: repr(float(x))
    lines = [f"gravity = [{', '.join(map(num, chain.gravity))}]", ""]  # top-level keys before the tables
    for p, a, al, c, ph, link in zip(chain.pairs, chain.a, chain.alpha, chain.offset, chain.theta_offset, chain.links):
        lines += ["[[joint]]", f'pair = "{p.kind}"']
        if p.kind != "revolute":
            lines += [
                f"base_radius = {num(p.base_radius)}",
                f"platform_radius = {num(p.platform_radius)}",
                f"leg_mass = {num(p.leg_mass)}",
            ]
        I = link.inertia
        lines += [
            f"a = {num(a)}",
            f"alpha = {num(al)}",
            f"offset = {num(c)}",
            f"theta_offset = {num(ph)}",
            f"mass = {num(link.mass)}",
            f"com = [{', '.join(map(num, link.com))}]",
            f"inertia = [{', '.join(map(num, (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])))}]",
            "",
        ]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "arm6.toml"
        path.write_text("\n".join(lines))
        t0 = time.perf_counter()
        res = subprocess.run(
            [sys.executable, "-m", "apair", "codegen", str(path), "--out", str(Path(tmp) / "out")],
            capture_output=True,
            text=True,
        )
        if res.returncode != 0:
            raise RuntimeError(f"apair codegen failed: {res.stderr.strip()}")
        return time.perf_counter() - t0


def random_achain(n: int, rng) -> apair.AChain:
    """random_chain's kind of design with sinusoidal A-pairs whose legs have mass."""
    r = random_chain(n, rng)
    pairs = [apair.APair(*rng.uniform(0.03, 0.08, 2), leg_mass=rng.uniform(0.02, 0.1)) for _ in range(n)]
    return apair.AChain(pairs, r.a, r.alpha, r.offset, r.theta_offset, links=r.links, gravity=r.gravity)


def native_section(rng, quick: bool) -> dict:
    """The compiled comparison (bench/native.py) for n = 6: the R-chain with every peer, and an
    A-chain with apair alone, both with the derivatives of the dynamics; and examples/4a_chain.toml."""
    from bench import native

    count, rounds = (2000, 3) if quick else (10_000, 7)
    work = ROOT / "build" / "bench"
    out = {}
    example = apair.load(ROOT / "examples" / "4a_chain.toml")
    for label, chain in (
        ("R-chain", random_chain(6, rng)),
        ("A-chain", random_achain(6, rng)),
        ("examples/4a_chain.toml", example),
    ):
        n = chain.n
        lim = np.array([min(p.theta_limit or np.pi, np.pi) * 0.95 for p in chain.pairs])
        states = native.States(
            rng.uniform(-lim, lim, (count, n)),
            rng.normal(size=(count, n)),
            rng.normal(size=(count, n)),
            rng.normal(size=(count, n)),
        )
        print(f"compiled comparison, {label} (n = {n}, {count} states):", file=sys.stderr, flush=True)
        peers = ("pinocchio", "casadi") if label == "R-chain" and _has_pinocchio() else ()
        out[label] = native.compare(
            chain,
            states,
            work / label,
            rounds=rounds,
            peers=peers,
            log=lambda m: print(m, file=sys.stderr, flush=True),
            pin_model=pin_model(chain) if peers else None,
            derivatives=label != "examples/4a_chain.toml",  # the two n = 6 chains
        )
    manifest = kernels.manifest()["kernels"]
    out["apair_ops_per_item"] = {  # the R-chain's kernels
        op: manifest[kernels.chain_kernel(op, 6, revolute=True)]["ops_per_item"]
        for op in (*native.OPERATIONS, *native.DERIVATIVES)
    }
    return out


def _has_pinocchio() -> bool:
    try:
        import pinocchio  # noqa: F401
    except ImportError:
        return False
    return True


PANDA_TIP = "panda_link8"
PANDA_JOINTS = [f"panda_joint{i}" for i in range(1, 8)]


def panda_urdf() -> Path | None:
    """The Panda's URDF of the example-robot-data wheel (in the cmeel prefix), or None."""
    from bench import native

    prefix = native.cmeel_prefix()
    path = None if prefix is None else prefix / "share/example-robot-data/robots/panda_description/urdf/panda.urdf"
    return path if path is not None and path.is_file() else None


def panda_pin_model(path: Path):
    """Pinocchio's model of the Panda's URDF with the joints off the arm's path (the fingers) locked
    at their neutral value, as tests/chain7 builds it: the seven arm joints, the tip's frame."""
    import pinocchio as pin

    full = pin.buildModelFromUrdf(str(path))
    lock = [full.getJointId(name) for name in full.names[1:] if name not in PANDA_JOINTS]
    return pin.buildReducedModel(full, lock, pin.neutral(full))


def time_import_urdf(path: Path, runs: int) -> dict:
    """`apair import urdf` of the Panda, each run a fresh process (the console script next to this
    Python, else python -m apair): min and median wall time [s]."""
    script = Path(sys.executable).with_name("apair")
    cmd = [str(script)] if script.is_file() else [sys.executable, "-m", "apair"]
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(runs):
            t0 = time.perf_counter()
            subprocess.run(
                [
                    *cmd,
                    "import",
                    "urdf",
                    str(path),
                    "--tip",
                    PANDA_TIP,
                    "--out",
                    str(Path(tmp) / "panda.toml"),
                    "--force",
                ],
                check=True,
                capture_output=True,
            )
            times.append(time.perf_counter() - t0)
    return {"runs": runs, "min_s": float(min(times)), "median_s": float(np.median(times))}


def panda_section(rng, quick: bool) -> dict:
    """The Panda of example-robot-data imported by apair.load_urdf (7 R-pairs, base and tool
    frames): apair's generic C kernels against Pinocchio's C++ on the model Pinocchio builds from
    the same URDF (fingers locked), the same states (q inside the limits), agreement first
    (bench/native.py); and the time of `apair import urdf` of it in a fresh process."""
    from bench import native

    path = panda_urdf()
    if path is None:
        return {"skipped": "example-robot-data's Panda URDF is not installed: pip install '.[test]'"}
    count, rounds, runs = (2000, 3, 3) if quick else (10_000, 7, 7)
    chain = apair.load_urdf(path, tip=PANDA_TIP)
    lim = chain.limits
    n = chain.n
    states = native.States(
        rng.uniform(lim[:, 0], lim[:, 1], (count, n)),
        rng.normal(size=(count, n)),
        rng.normal(size=(count, n)),
        rng.normal(size=(count, n)),
    )
    pin_ok = _has_pinocchio()
    print(f"compiled comparison, the Panda (n = {n}, {count} states):", file=sys.stderr, flush=True)
    out = native.compare(
        chain,
        states,
        ROOT / "build" / "bench" / "panda",
        rounds=rounds,
        peers=("pinocchio",) if pin_ok else (),
        log=lambda m: print(m, file=sys.stderr, flush=True),
        pin_model=panda_pin_model(path) if pin_ok else None,
        pin_frame=PANDA_TIP,
        specialised=False,
        derivatives=False,
    )
    out["urdf"] = str(path)
    out["tip"] = PANDA_TIP
    out["import_urdf"] = time_import_urdf(path, runs)
    return out


def panda_targets(panda: dict) -> list[dict]:
    """Issue 38's: the generic kernels <= 0.5 x Pinocchio's C++ on the imported Panda, every
    operation and opt level; `apair import urdf` of it < 1 s (fresh process, min of the runs)."""
    out = []
    tools = panda.get("tools", {})
    for opt in ("-O2", "-O3"):
        me, other = tools.get(f"apair {opt}"), tools.get(f"pinocchio {opt}")
        if me is None or other is None:
            continue
        for op in OPS:
            r = me["ns"][op] / other["ns"][op]
            out.append({"target": f"Panda {op} {opt}: apair <= 0.5 x pinocchio", "measured": r, "met": r <= 0.5})
    if "import_urdf" in panda:
        t = panda["import_urdf"]["min_s"]
        out.append({"target": "apair import urdf of the Panda < 1 s (fresh process)", "measured": t, "met": t < 1.0})
    return out


def print_panda(panda: dict) -> None:
    if "skipped" in panda and "tools" not in panda:
        print(f"\nthe Panda: skipped ({panda['skipped']})")
        return
    names = list(panda["tools"])
    print(
        f"\nthe Panda ({panda['tip']}, n = {panda['n']}, frames {panda['frames']}), ns per evaluation, ratio = apair / peer:"
    )
    print(f"{'':18s}" + "".join(f"{n:>17s}" for n in names))
    for op in OPS:
        cells = []
        for name in names:
            t = panda["tools"][name]["ns"][op]
            mine = panda["tools"][f"apair {name.split()[-1]}"]["ns"][op]
            cells.append(f"{t:8.0f}" + (f" ({mine / t:.2f})" if not name.startswith("apair") else "       "))
        print(f"{op:18s}" + "".join(f"{c:>17s}" for c in cells))
    worst = max(v for t in panda["tools"].values() for v in t["difference"].values())
    print(f"largest difference from apair (relative to the largest value): {worst:.1e}")
    for tool, why in panda["skipped"].items():
        print(f"skipped {tool}: {why}")
    r = panda["import_urdf"]
    print(
        f"apair import urdf (fresh process): min {r['min_s']:.3f} s, median {r['median_s']:.3f} s over {r['runs']} runs"
    )


def native_targets(native_res: dict) -> list[dict]:
    """Issue 15's targets: per opt level, M, ID, FD <= 0.7 x Pinocchio C++ and <= 1.0 x CasADi with
    the design as inputs; fk and Jacobian <= 0.8 x Pinocchio and <= 1.3 x their trigonometric calls.
    Issue 16's: the specialised code <= 0.8 x CasADi with the design baked in (R-chain) and
    <= 0.6 x apair's generic kernels on examples/4a_chain.toml, for all five operations."""
    tools = native_res["R-chain"]["tools"]
    out = []
    from bench.native import OPERATIONS

    for opt in ("-O2", "-O3"):
        for label, peer, bound in (("R-chain", "casadi_baked", 0.8), ("examples/4a_chain.toml", "apair", 0.6)):
            spec = native_res[label]["tools"].get(f"apair_specialised {opt}")
            other = native_res[label]["tools"].get(f"{peer} {opt}")
            if spec is None or other is None:
                continue
            for op in OPERATIONS:
                r = spec["ns"][op] / other["ns"][op]
                out.append(
                    {
                        "target": f"{op} {opt}, {label}: specialised <= {bound} x {peer}",
                        "measured": r,
                        "met": r <= bound,
                    }
                )
    for opt in ("-O2", "-O3"):
        me = tools.get(f"apair {opt}")
        if me is None:
            continue
        floor = me["ns"]["trig_floor"]
        for op in ("mass_matrix", "inverse_dynamics", "forward_dynamics", "fk", "jacobian"):
            limits = [("pinocchio", 0.7 if op not in ("fk", "jacobian") else 0.8)]
            if op not in ("fk", "jacobian"):
                limits.append(("casadi_design", 1.0))
            for peer, bound in limits:
                other = tools.get(f"{peer} {opt}")
                if other is None:
                    continue
                r = me["ns"][op] / other["ns"][op]
                out.append({"target": f"{op} {opt}: apair <= {bound} x {peer}", "measured": r, "met": r <= bound})
            if op in ("fk", "jacobian"):
                r = me["ns"][op] / floor
                out.append(
                    {"target": f"{op} {opt}: apair <= 1.3 x its sincos calls alone", "measured": r, "met": r <= 1.3}
                )
    return out + derivative_targets(tools)


DERIVATIVE_PEERS = {  # Pinocchio's algorithm of each derivative operation, and the outputs compared
    "inverse_dynamics_derivatives": ("computeRNEADerivatives", ("dtau_dq", "dtau_dqd")),
    "forward_dynamics_derivatives": ("computeABADerivatives", ("dqdd_dq", "dqdd_dqd", "Minv")),
}
DERIVATIVE_AGREE = 1e-9  # relative: a larger difference means the tools compute different things


def derivative_targets(tools: dict) -> list[dict]:
    """Issue 39's, per opt level on the n = 6 R-chain: apair's derivatives of the inverse and
    forward dynamics <= 0.5 x Pinocchio's computeRNEADerivatives / computeABADerivatives and
    <= 0.7 x CasADi's C code of the jacobians of its rnea / aba (design as inputs, as apair's
    kernels take it); and every peer's derivatives agree with apair's to DERIVATIVE_AGREE."""
    out = []
    for opt in ("-O2", "-O3"):
        me = tools.get(f"apair {opt}")
        if me is None or "inverse_dynamics_derivatives" not in me["ns"]:
            continue
        for op, (pin_name, names) in DERIVATIVE_PEERS.items():
            for peer, bound, what in (("pinocchio", 0.5, pin_name), ("casadi_design", 0.7, "CasADi's jacobian C")):
                other = tools.get(f"{peer} {opt}")
                if other is None or op not in other["ns"]:
                    continue
                r = me["ns"][op] / other["ns"][op]
                out.append({"target": f"{op} {opt}: apair <= {bound} x {what}", "measured": r, "met": r <= bound})
                worst = max(other["difference"][name] for name in names)
                out.append(
                    {
                        "target": f"{op} {opt}: {peer} agrees with apair ({', '.join(names)}) to "
                        f"{DERIVATIVE_AGREE:g} relative",
                        "measured": worst,
                        "met": worst <= DERIVATIVE_AGREE,
                    }
                )
    return out


def print_native(native_res: dict) -> None:
    r = native_res["R-chain"]
    names = list(r["tools"])
    print("\ncompiled, n = 6 R-chain, ns per evaluation (min over rounds); ratio = apair / peer at the same -O:")
    print(f"{'':18s}" + "".join(f"{n:>17s}" for n in names))
    short = {"inverse_dynamics_derivatives": "d inverse_dyn", "forward_dynamics_derivatives": "d forward_dyn"}
    for op in OPS + tuple(DERIVATIVE_PEERS):
        cells = []
        for name in names:
            t = r["tools"][name]["ns"].get(op)
            mine = r["tools"][f"apair {name.split()[-1]}"]["ns"].get(op)
            if t is None or mine is None:
                cells.append("-")
                continue
            cells.append(f"{t:8.0f}" + (f" ({mine / t:.2f})" if not name.startswith("apair") else "       "))
        print(f"{short.get(op, op):18s}" + "".join(f"{c:>17s}" for c in cells))
    for opt in ("-O2", "-O3"):
        me = r["tools"].get(f"apair {opt}")
        if me:
            d3 = me["ns"].get("law_d3_kernels")
            print(
                f"apair {opt}: sincos of the 6 half angles alone {me['ns']['trig_floor']:.0f} ns, "
                f"the 6 law kernels {me['ns']['law_kernels']:.0f} ns"
                + ("" if d3 is None else f", the 6 law_<kind>_d3 kernels {d3:.0f} ns (both in the derivatives' times)")
            )
    derived = {name for _, names in DERIVATIVE_PEERS.values() for name in names}
    worst = max(v for t in r["tools"].values() for k, v in t["difference"].items() if k not in derived)
    print(f"largest difference from apair (relative to the largest value): {worst:.1e}")
    for op, (_, outputs) in DERIVATIVE_PEERS.items():
        diffs = [
            f"{name} " + ", ".join(f"{k} {t['difference'][k]:.1e}" for k in outputs)
            for name, t in r["tools"].items()
            if not name.startswith("apair") and all(k in t["difference"] for k in outputs)
        ]
        if diffs:
            print(f"{op}, largest difference from apair (relative): " + "; ".join(diffs))
    print(
        "operations per evaluation: apair " + ", ".join(f"{k} {v}" for k, v in native_res["apair_ops_per_item"].items())
    )
    if "casadi_ops" in r:
        print("CasADi SX operations: " + ", ".join(f"{k} {v}" for k, v in r["casadi_ops"].items()))
    for tool, why in r["skipped"].items():
        print(f"skipped {tool}: {why}")
    for label in ("A-chain", "examples/4a_chain.toml"):
        a = native_res[label]
        print(
            f"{label} (n = {a['n']}, sinusoidal pairs with leg mass), apair only, ns: "
            + "; ".join(
                f"{name}: " + ", ".join(f"{op} {t:.0f}" for op, t in a["tools"][name]["ns"].items())
                for name in a["tools"]
            )
        )


def random_4a(rng) -> apair.AChain:
    pairs = [apair.APair(*rng.uniform(0.03, 0.1, 2)) for _ in range(4)]
    return apair.AChain(
        pairs, rng.uniform(0.1, 0.4, 4), rng.uniform(-1.5, 1.5, 4), rng.uniform(-0.1, 0.1, 4), rng.uniform(-1.0, 1.0, 4)
    )


def _plain(x):
    """NumPy scalars as Python numbers for json (anything else is refused as json would)."""
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"Object of type {type(x).__name__} is not JSON serializable")


def time_ik(chains, poses_per_chain: int, rng) -> dict:
    """Median wall time per pose of AChain.ik (every real solution, verified), after set-up."""
    times, setup, solutions = [], [], []
    for chain in chains:
        Ts = chain.fk(rng.uniform(-np.pi, np.pi, (poses_per_chain, chain.n)))
        t0 = time.perf_counter()
        chain.ik(Ts[0])  # first call: builds the chain's solver
        setup.append(time.perf_counter() - t0)
        for T in Ts:
            t0 = time.perf_counter()
            q = chain.ik(T)
            times.append(time.perf_counter() - t0)
            solutions.append(len(q))
    ms = np.array(times) * 1e3
    return {
        "poses": len(times),
        "median_ms": float(np.median(ms)),
        "min_ms": float(ms.min()),
        "max_ms": float(ms.max()),
        "p90_ms": float(np.percentile(ms, 90)),
        "first_call_ms": float(np.median(setup) * 1e3),
        "solutions_per_pose": float(np.mean(solutions)),
    }


def random_pattern_chain(pattern: str, rng) -> apair.AChain:
    n = len(pattern)
    pairs = [apair.APair.revolute() if c == "R" else apair.APair(*rng.uniform(0.05, 0.12, 2)) for c in pattern]
    return apair.AChain(
        pairs, rng.uniform(0.1, 0.5, n), rng.uniform(-1.5, 1.5, n), rng.uniform(-0.2, 0.2, n), rng.uniform(-1.0, 1.0, n)
    )


TRACE_MAX = 48  # start sets the bench certifies by the trace test (larger ones: see apair.ik.homotopy.trace)


def time_ik6(pattern: str, poses: int, rng) -> dict:
    """6-joint IK: the start system's preparation (into an empty cache) and, for sets of up to
    TRACE_MAX solutions, its trace test; then every real solution at `poses` random poses: median
    and worst per pose, and whether each pose's solution was found."""
    chain = random_pattern_chain(pattern, rng)
    old = os.environ.get("APAIR_CACHE")
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["APAIR_CACHE"] = tmp
        try:
            t0 = time.perf_counter()
            start = chain.prepare_ik()
            prep = time.perf_counter() - t0
            trace_s = None
            if start.count <= TRACE_MAX:
                t0 = time.perf_counter()
                start = chain.prepare_ik(trace=True)
                trace_s = time.perf_counter() - t0
            qs = rng.uniform(-np.pi, np.pi, (poses, 6))
            t0 = time.perf_counter()
            chain.ik(chain.fk(qs[0]))  # the first call loads the start system from the cache
            first = time.perf_counter() - t0
            times, found, certified, methods = [], 0, 0, {}
            for q in qs:
                T = chain.fk(q)
                t0 = time.perf_counter()
                sol = chain.ik(T, full=True)
                times.append(time.perf_counter() - t0)
                per = np.array([2 * np.pi if p.kind == "revolute" else 4 * np.pi for p in chain.pairs])
                d = np.abs((sol.q - q + per / 2) % per - per / 2)
                found += bool(len(sol.q)) and bool(np.any(np.all(d < 1e-7, axis=1)))
                certified += sol.certified
                methods[sol.method] = methods.get(sol.method, 0) + 1
        finally:
            if old is None:
                os.environ.pop("APAIR_CACHE", None)
            else:
                os.environ["APAIR_CACHE"] = old
    ms = np.array(times) * 1e3
    return {
        "pattern": pattern,
        "poses": poses,
        "median_ms": float(np.median(ms)),
        "max_ms": float(ms.max()),
        "prepare_s": prep,
        "first_call_ms": first * 1e3,
        "start_count": start.count,
        "start_certified": start.certified,
        "start_how": start.how,
        "trace_s": trace_s,
        "trace_deviation": start.trace if start.traced else None,
        "witnesses": start.witnesses,
        "round_trips_found": found,
        "certified_poses": certified,
        "methods": methods,
    }


def time_ik_local(rng, count: int = 2000) -> dict:
    """ik_local, n = 6 R-chain, seeds within 0.3 rad of a solution: µs per converged solve."""
    chain = random_pattern_chain("RRRRRR", rng)
    q = rng.uniform(-np.pi + 0.3, np.pi - 0.3, (count, 6))  # the seeds stay inside the limits (−π, π)
    T = chain.fk(q)
    seeds = q + rng.uniform(-0.3, 0.3, q.shape)
    chain.ik_local(T[:10], seeds[:10])
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        res = chain.ik_local(T, seeds)
        best = min(best, time.perf_counter() - t0)
    return {
        "count": count,
        "us_per_solve": best / count * 1e6,
        "converged": float(res.converged.mean()),
        "us_per_converged": best / max(res.converged.sum(), 1) * 1e6,
    }


# ------------------------------------------------------------------------------------ ik_local, one pose per call
def pin_clik(model, data, joint: int, tip, dt: float, eps: float, it_max: int):
    """Pinocchio's damped least-squares CLIK loop as its examples/inverse-kinematics.py writes it
    (forwardKinematics, the log6 error in the joint frame, computeJointJacobian, Jlog6, a 6 x 6
    solve with damping 1e-12, integrate by dt), toward the pose T (4 x 4) of the frame `tip` placed
    on joint `joint`: solve(T, q0) -> (q, converged)."""
    import pinocchio as pin

    tip_inv, eye = tip.inverse(), np.eye(6)

    def solve(T, q):
        goal = pin.SE3(T) * tip_inv  # the joint frame's pose
        for i in range(it_max + 1):
            pin.forwardKinematics(model, data, q)
            iMd = data.oMi[joint].actInv(goal)
            err = pin.log(iMd).vector
            if np.linalg.norm(err) < eps:
                return q, True
            if i == it_max:
                break
            J = -pin.Jlog6(iMd.inverse()) @ pin.computeJointJacobian(model, data, q, joint)
            q = pin.integrate(model, q, -dt * (J.T @ np.linalg.solve(J @ J.T + 1e-12 * eye, err)))
        return q, False

    return solve


# the example's constants, and the same loop with full steps to ik_local's accuracy (kinder to it)
CLIK = {"pinocchio_clik_example": (0.1, 1e-4, 1000), "pinocchio_clik_full_step": (1.0, 1e-10, 100)}


def per_call(fn, args_list) -> dict:
    """Median, 90th percentile and min of single calls fn(*args) [µs], one timing per call."""
    fn(*args_list[0])
    times = []
    for args in args_list:
        t0 = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - t0)
    us = np.array(times) * 1e6
    return {
        "calls": len(us),
        "median_us": float(np.median(us)),
        "p90_us": float(np.percentile(us, 90)),
        "min_us": float(us.min()),
    }


def _twin(chain: apair.AChain) -> apair.AChain:
    """A new chain object of the same design (new pairs: nothing computed yet)."""
    pairs = [
        apair.APair.revolute() if p.kind == "revolute" else apair.APair(p.base_radius, p.platform_radius)
        for p in chain.pairs
    ]
    return apair.AChain(pairs, chain.a, chain.alpha, chain.offset, chain.theta_offset, links=chain.links)


def _first_calls(make, T, seed, repeats: int) -> dict:
    """Median [ms] of the first ik_local call on `repeats` new chains (make()), and of making them."""
    build, first = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        chain = make()
        t1 = time.perf_counter()
        chain.ik_local(T, seed)
        build.append(t1 - t0)
        first.append(time.perf_counter() - t1)
    return {"first_call_ms": float(np.median(first) * 1e3), "build_ms": float(np.median(build) * 1e3)}


FRESH_PROCESS = """
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import apair
t1 = time.perf_counter()
chain = apair.load(sys.argv[1]) if sys.argv[1].endswith(".toml") else apair.AChain(
    [apair.APair.revolute()] * 6, *json.loads(sys.argv[1]))
q = np.full(chain.n, 0.3)
T, seed = chain.fk(q), q + 0.05
t2 = time.perf_counter()
import apair.ik
t3 = time.perf_counter()
chain.limits
t4 = time.perf_counter()
chain.ik_local(T, seed)
t5 = time.perf_counter()
chain.ik_local(T, seed)
t6 = time.perf_counter()
print(json.dumps({"import_apair_ms": (t1 - t0) * 1e3, "import_apair_ik_ms": (t3 - t2) * 1e3,
                  "limits_ms": (t4 - t3) * 1e3, "first_call_ms": (t5 - t4) * 1e3,
                  "first_call_total_ms": (t5 - t2) * 1e3, "second_call_us": (t6 - t5) * 1e6}))
"""


def _fresh_process(arg: str, repeats: int) -> dict:
    """The first ik_local call in a new Python process (after import apair and building the chain),
    split into importing apair.ik, the chain's limits and the call itself: medians over runs [ms]."""
    runs = []
    for _ in range(repeats):
        out = subprocess.run(
            [sys.executable, "-c", FRESH_PROCESS, arg], cwd=ROOT, check=True, capture_output=True, text=True
        )
        runs.append(json.loads(out.stdout.splitlines()[-1]))
    return {key: float(np.median([r[key] for r in runs])) for key in runs[0]}


def time_ik_local_single(quick: bool, pin_ok: bool) -> dict:
    """AChain.ik_local one pose and one seed per call from Python, as a controller calls it, on a
    6-joint R-chain (the R-twin that Pinocchio models), seeds within 0.3 rad of a solution: single
    calls, the batched call per pose, first calls on new chains (warm process and new process; the
    4A example too, whose first call computes the collision limits of its pairs), and Pinocchio's
    CLIK loop on the same poses and seeds."""
    rng = np.random.default_rng(36)  # its own: the other sections' draws stay as they were
    count, peer_count, repeats = (200, 50, 3) if quick else (2000, 300, 9)
    chain = random_chain(6, rng)
    q = rng.uniform(-np.pi + 0.3, np.pi - 0.3, (count, 6))  # the seeds stay inside the limits (-π, π)
    T = chain.fk(q)
    seeds = q + rng.uniform(-0.3, 0.3, q.shape)
    out: dict = {"n": 6, "poses": count}
    out["single"] = per_call(chain.ik_local, list(zip(T, seeds)))
    batched = chain.ik_local(T, seeds)
    best = min(_timed(lambda: chain.ik_local(T, seeds)) for _ in range(5))
    out["batched_per_pose_us"] = best / count * 1e6
    out["converged"] = float(batched.converged.mean())
    ones = [chain.ik_local(Tk, sk) for Tk, sk in zip(T, seeds)]
    out["single_equals_batched"] = bool(all(np.array_equal(o.q, b) for o, b in zip(ones, batched.q)))
    out["first_call_r_twin"] = _first_calls(lambda: _twin(chain), T[0], seeds[0], repeats)
    example = apair.load(ROOT / "examples/4a_chain.toml")
    qe = np.full(4, 0.3)
    out["first_call_4a_example"] = _first_calls(
        lambda: apair.load(ROOT / "examples/4a_chain.toml"), example.fk(qe), qe + 0.05, repeats
    )
    fresh = min(repeats, 3)
    design = json.dumps([chain.a.tolist(), chain.alpha.tolist(), chain.offset.tolist(), chain.theta_offset.tolist()])
    out["fresh_process_r_twin"] = _fresh_process(design, fresh)
    out["fresh_process_4a_example"] = _fresh_process(str(ROOT / "examples/4a_chain.toml"), fresh)
    if pin_ok:
        out.update(_pin_clik_rows(chain, T, seeds, batched, peer_count, repeats))
    return out


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _pin_clik_rows(chain, T, seeds, apair_result, peer_count: int, repeats: int) -> dict:
    """Pinocchio's CLIK loops on the first peer_count poses and seeds: per call, the first call on a
    new model (building it included), and how their solutions agree with ik_local's."""
    rows = {}
    model = pin_model(chain)
    tip = model.frames[model.getFrameId("end")].placement
    args = list(zip(T[:peer_count], seeds[:peer_count]))
    for name, (dt, eps, it_max) in CLIK.items():
        solve = pin_clik(model, model.createData(), chain.n, tip, dt, eps, it_max)
        row = per_call(solve, args)
        got = [solve(Tk, sk) for Tk, sk in args]
        q_peer, conv = np.array([qk for qk, _ in got]), np.array([c for _, c in got])
        diff = np.abs((q_peer - apair_result.q[:peer_count] + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
        both = conv & apair_result.converged[:peer_count]
        row["converged"] = float(conv.mean())
        # the peer's solutions checked by apair's fk, and how often both found the same one
        row["peer_pose_error_max"] = float(np.abs(chain.fk(q_peer[conv]) - T[:peer_count][conv]).max())
        row["same_solution"] = float(np.mean(diff[both] < 1e-3)) if both.any() else None  # branches differ more
        first = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            m = pin_model(chain)
            pin_clik(m, m.createData(), chain.n, m.frames[m.getFrameId("end")].placement, dt, eps, it_max)(*args[0])
            first.append(time.perf_counter() - t0)
        row["first_call_ms"] = float(np.median(first) * 1e3)
        rows[name] = row
    return rows


def ik_local_targets(r: dict) -> list[dict]:
    """Issue 36 item 3's targets for ik_local from Python, each met or missed."""
    out = [
        {
            "target": "ik_local single call from Python (one pose, one seed), n = 6: <= 20 µs median",
            "measured": r["single"]["median_us"],
            "met": r["single"]["median_us"] <= 20,
        },
        {
            "target": "ik_local first call on a new chain (6-joint R-twin, warm process): <= 50 ms",
            "measured": r["first_call_r_twin"]["first_call_ms"],
            "met": r["first_call_r_twin"]["first_call_ms"] <= 50,
        },
        {
            "target": "ik_local first call on a new chain (examples/4a_chain.toml: its collision limits): <= 50 ms",
            "measured": r["first_call_4a_example"]["first_call_ms"],
            "met": r["first_call_4a_example"]["first_call_ms"] <= 50,
        },
    ]
    for name in CLIK:
        if name in r:
            ratio = r[name]["median_us"] / r["single"]["median_us"]
            out.append(
                {
                    "target": f"ik_local single call faster than Pinocchio's Python CLIK ({name}): peer / apair >= 1",
                    "measured": ratio,
                    "met": ratio >= 1,
                }
            )
    return out


def print_ik_local_single(r: dict) -> None:
    s = r["single"]
    print(
        f"\nik_local from Python, n = {r['n']}, one pose and one seed per call ({r['poses']} poses, seeds within 0.3 rad):"
    )
    print(
        f"  apair single call       median {s['median_us']:.2f} µs (p90 {s['p90_us']:.2f}, min {s['min_us']:.2f}); "
        f"batched {r['batched_per_pose_us']:.2f} µs per pose; {r['converged']:.1%} converged; single = batched: "
        f"{r['single_equals_batched']}"
    )
    for name in CLIK:
        if name in r:
            p = r[name]
            same = "-" if p["same_solution"] is None else f"{p['same_solution']:.1%}"
            print(
                f"  {name:26s}median {p['median_us']:.1f} µs (p90 {p['p90_us']:.1f}) = {p['median_us'] / s['median_us']:.1f}x "
                f"apair; {p['converged']:.1%} converged; largest |fk(q) - T| {p['peer_pose_error_max']:.1e}; the same solution as apair's: {same}; first call {p['first_call_ms']:.2f} ms "
                "(model built)"
            )
    for key, what in (("first_call_r_twin", "6-joint R-twin"), ("first_call_4a_example", "examples/4a_chain.toml")):
        f = r[key]
        print(
            f"  first call on a new chain, {what}: {f['first_call_ms']:.2f} ms (making the chain {f['build_ms']:.2f} ms)"
        )
    for key, what in (
        ("fresh_process_r_twin", "6-joint R-twin"),
        ("fresh_process_4a_example", "examples/4a_chain.toml"),
    ):
        f = r[key]
        print(
            f"  new process, {what}: first call {f['first_call_total_ms']:.0f} ms = import apair.ik "
            f"{f['import_apair_ik_ms']:.0f} ms + limits {f['limits_ms']:.1f} ms + the call {f['first_call_ms']:.2f} ms "
            f"(import apair before: {f['import_apair_ms']:.0f} ms); second call {f['second_call_us']:.1f} µs"
        )


# ------------------------------------------------------------------------------------ report
def fmt(ns: float) -> str:
    return f"{ns / 1e6:.3g} ms" if ns >= 1e6 else f"{ns / 1e3:.3g} µs" if ns >= 1e3 else f"{ns:.3g} ns"


def targets(results: dict) -> list[dict]:
    """The issue's targets, each met or missed with the measured numbers."""
    out = []
    six = results["kernels"].get("6", {})
    for op in ("fk", "jacobian", "mass_matrix", "inverse_dynamics"):
        row = six.get(op, {})
        if "pinocchio_per_call" in row:
            r = row["peer_over_c_batched"]["pinocchio_per_call"]
            out.append(
                {
                    "target": f"batched C >= 2x faster than Pinocchio per call, {op}, n = 6",
                    "measured": r,
                    "met": r >= 2.0,
                }
            )
    for op in ("fk", "jacobian", "mass_matrix", "inverse_dynamics", "forward_dynamics"):
        row = six.get(op, {})
        for mine, what in (("c_single_api", "generic"), ("specialised_single_api", "specialised")):
            if "pinocchio_per_call" in row and mine in row:
                r = row[mine]["median_ns"] / row["pinocchio_per_call"]["median_ns"]
                out.append(
                    {
                        "target": f"Python single call, {what} chain.{op}, n = 6: <= 1.0 x Pinocchio's Python call",
                        "measured": r,
                        "met": r <= 1.0,
                    }
                )
    if results.get("codegen_6_s") is not None:
        g = results["codegen_6_s"]
        out.append({"target": "apair codegen of a 6-joint chain, every kernel, < 60 s", "measured": g, "met": g < 60})
    worst = max(row["single_call_overhead_ns"] for rows in results["kernels"].values() for row in rows.values())
    out.append(
        {
            "target": "single-call Python overhead (apair.kernels.call, best of repeats) < 2 µs, worst kernel",
            "measured": worst / 1e3,
            "met": worst < 2000,
        }
    )
    worst_np = min(
        row["peer_over_c_batched"]["lambdify_loop"] / row["peer_over_c_batched"]["numpy_batched"]
        for rows in results["kernels"].values()
        for row in rows.values()
    )
    out.append(
        {
            "target": "batched NumPy >= 10x faster than a Python loop over lambdify, worst case",
            "measured": worst_np,
            "met": worst_np >= 10,
        }
    )
    if results.get("make_generate_s") is not None:
        g = results["make_generate_s"]
        out.append({"target": "make generate < 120 s", "measured": g, "met": g < 120})
    for pattern, bound in (("RRRRRR", 1.0), ("ARRRRR", 5.0), ("AAAAAA", 1000.0)):
        r = results.get("ik6", {}).get(pattern)
        if r:
            out.append(
                {
                    "target": f"ik of a 6-joint {pattern} chain, all solutions, median per pose <= {bound:g} ms",
                    "measured": r["median_ms"],
                    "met": r["median_ms"] <= bound,
                }
            )
    if results.get("ik_local"):
        r = results["ik_local"]["us_per_converged"]
        out.append(
            {
                "target": "ik_local, n = 6, seed within 0.3 rad: <= 20 µs per converged solve",
                "measured": r,
                "met": r <= 20,
            }
        )
    for name, r in results.get("ik", {}).items():
        out.append(
            {"target": f"4-joint ik ({name}) <= 1 ms median", "measured": r["median_ms"], "met": r["median_ms"] <= 1.0}
        )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="bench/run.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small batches and few repeats (a smoke run)")
    ap.add_argument("--no-generate", action="store_true", help="skip timing make generate")
    ap.add_argument("--native-only", action="store_true", help="only the compiled comparison with the C/C++ peers")
    ap.add_argument(
        "--ik-local-only", action="store_true", help="only ik_local from Python, one pose per call, against Pinocchio"
    )
    ap.add_argument(
        "--panda-only", action="store_true", help="only the imported Panda against Pinocchio's C++, and its import time"
    )
    ap.add_argument(
        "--derivatives-only",
        action="store_true",
        help="only the derivatives of the dynamics from Python, one state per call, against Pinocchio's binding",
    )
    ap.add_argument(
        "--ik-closed-only",
        action="store_true",
        help="only the closed-form IK of arms with a spherical wrist, against EAIK and IK-Geo",
    )
    ap.add_argument("--out", type=Path, default=ROOT / "bench" / "results.json")
    args = ap.parse_args(argv)
    try:
        import pinocchio  # noqa: F401

        pin_ok = True
    except ImportError:
        pin_ok = False
    try:
        import symengine  # noqa: F401

        se_ok = True
    except ImportError:
        se_ok = False
    rng = np.random.default_rng(0)
    batch, single, slow, repeats = (1000, 200, 20, 3) if args.quick else (10_000, 2000, 200, 7)
    results = {
        "machine": {
            "python": sys.version.split()[0],
            "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(),
            "numpy": np.__version__,
            "apair_backend": apair.backend(),
            "pinocchio": pin_ok,
            "symengine": se_ok,
        },
        "settings": {"batch": batch, "single_calls": single, "lambdify_calls": slow, "repeats": repeats},
        "kernels": {},
    }
    if not (pin_ok and se_ok):
        print("note: install the bench extra (pip install .[bench]) for Pinocchio and symengine", file=sys.stderr)
    if args.ik_local_only:
        results["ik_local_single"] = time_ik_local_single(args.quick, pin_ok)
        results["ik_local_targets"] = ik_local_targets(results["ik_local_single"])
        print_ik_local_single(results["ik_local_single"])
        print("\ntargets (ik_local from Python):")
        for t in results["ik_local_targets"]:
            print(f"  [{'met' if t['met'] else 'MISSED'}] {t['target']}: {t['measured']:.3g}")
        args.out.write_text(json.dumps(results, indent=1, default=_plain) + "\n")
        print(f"written to {args.out}")
        return 0
    if args.ik_closed_only or not (args.derivatives_only or args.panda_only or args.native_only):
        print("closed-form IK, spherical wrists and UR arms (apair, EAIK, IK-Geo; same poses):", flush=True)
        results["ik_closed"] = ik_closed.section(args.quick)
        results["ik_closed_targets"] = ik_closed.targets(results["ik_closed"])
        print(f"targets (closed-form IK; load average {results['ik_closed']['load_average']:.2f}):")
        for t in results["ik_closed_targets"]:
            print(f"  [{'met' if t['met'] else 'MISSED'}] {t['target']}: {t['measured']:.3g}")
        if args.ik_closed_only:
            args.out.write_text(json.dumps(results, indent=1, default=_plain) + "\n")
            print(f"written to {args.out}")
            return 0
    if args.derivatives_only:
        results["derivatives_single"] = derivatives_single(args.quick, pin_ok)
        results["derivatives_single_targets"] = derivatives_single_targets(results["derivatives_single"])
        print_derivatives_single(results["derivatives_single"])
        print("\ntargets (derivatives from Python):")
        for t in results["derivatives_single_targets"]:
            print(f"  [{'met' if t['met'] else 'MISSED'}] {t['target']}: {t['measured']:.3g}")
        args.out.write_text(json.dumps(results, indent=1, default=_plain) + "\n")
        print(f"written to {args.out}")
        return 0
    results["panda"] = panda_section(np.random.default_rng(38), args.quick)  # its own draws
    results["panda_targets"] = panda_targets(results["panda"])
    print_panda(results["panda"])
    print("\ntargets (the Panda):")
    for t in results["panda_targets"]:
        print(f"  [{'met' if t['met'] else 'MISSED'}] {t['target']}: {t['measured']:.3g}")
    if args.panda_only:
        args.out.write_text(json.dumps(results, indent=1, default=_plain) + "\n")
        print(f"written to {args.out}")
        return 0
    results["native"] = native_section(rng, args.quick)
    results["native_targets"] = native_targets(results["native"])
    print_native(results["native"])
    print("\ntargets (compiled):")
    for t in results["native_targets"]:
        print(f"  [{'met' if t['met'] else 'MISSED'}] {t['target']}: {t['measured']:.3g}")
    if args.native_only:
        args.out.write_text(json.dumps(results, indent=1, default=_plain) + "\n")
        print(f"written to {args.out}")
        return 0
    for n in (2, 4, 6):
        print(f"n = {n}: deriving the expressions for lambdify/symengine and timing ...", file=sys.stderr, flush=True)
        results["kernels"][str(n)] = bench_chain(n, rng, batch, single, slow, repeats, pin_ok, se_ok)
    results["derivatives_single"] = derivatives_single(args.quick, pin_ok)
    results["batch_scaling"] = batch_scaling(6, rng, repeats)
    cases = {
        "4A random generic designs": (
            [random_4a(rng) for _ in range(3 if args.quick else 10)],
            10 if args.quick else 50,
        ),
        "examples/4a_chain.toml": ([apair.load(ROOT / "examples/4a_chain.toml")], 20 if args.quick else 200),
    }
    results["ik"] = {name: time_ik(chains, k, rng) for name, (chains, k) in cases.items()}
    results["ik6"] = {
        p: time_ik6(p, 20 if args.quick else 100, rng)
        for p in ("RRRRRR", "ARRRRR") + (() if args.quick else ("AAAAAA",))
    }
    results["ik_local"] = time_ik_local(rng)
    results["ik_local_single"] = time_ik_local_single(args.quick, pin_ok)
    results["make_generate_s"] = None if args.no_generate else time_generate()
    results["codegen_6_s"] = time_codegen(random_achain(6, rng))
    results["design"] = time_design(quick=args.quick)
    results["targets"] = (
        targets(results)
        + derivatives_single_targets(results["derivatives_single"])
        + ik_local_targets(results["ik_local_single"])
        + design_targets(results["design"])
    )

    print("\nper evaluation, median over repeats (ratio = peer time / batched C time):")
    cols = [
        ("c_batched", "C batched"),
        ("c_single", "C 1 call"),
        ("c_single_api", "API 1 call"),
        ("specialised_single_api", "specialised 1"),
        ("numpy_batched", "NumPy batch"),
        ("lambdify_loop", "lambdify loop"),
        ("symengine_batched", "symengine"),
        ("pinocchio_per_call", "Pinocchio"),
    ]
    print(f"{'kernel':24s}{'ops':>7s}" + "".join(f"{c[1]:>15s}" for c in cols))
    for n, rows in results["kernels"].items():
        for op, row in rows.items():
            cells = []
            for key, _ in cols:
                if key not in row:
                    cells.append(f"{'-':>15s}")
                    continue
                r = row["peer_over_c_batched"].get(key)
                cells.append(
                    f"{fmt(row[key]['median_ns']) + (f' ({r:.0f}x)' if r and r >= 10 else f' ({r:.1f}x)' if r else ''):>15s}"
                )
            print(f"{op + ' n=' + n:24s}{row['ops']:>7d}" + "".join(cells))
    print("\nbatch scaling (C, ns per item):")
    for name, rows in results["batch_scaling"].items():
        print(f"  {name:20s}" + "  ".join(f"{size}: {fmt(r['median_ns'])}" for size, r in rows.items()))
    print("\ninverse kinematics per pose (all real solutions, verified):")
    for name, r in results["ik"].items():
        print(
            f"  {name:30s} median {r['median_ms']:.2f} ms (min {r['min_ms']:.2f}, max {r['max_ms']:.2f}; "
            f"{r['solutions_per_pose']:.1f} solutions)"
        )
    for p, r in results["ik6"].items():
        print(
            f"  6-joint {p:24s} median {r['median_ms']:.2f} ms, worst {r['max_ms']:.2f} ms over {r['poses']} poses "
            f"({r['round_trips_found']} round trips found, {r['certified_poses']} certified; "
            + ", ".join(f"{k} {v}" for k, v in sorted(r["methods"].items()))
            + "); start system "
            f"{r['start_count']} solutions prepared in {r['prepare_s']:.1f} s, "
            + (
                f"trace test {'passed' if r['start_certified'] else 'FAILED'} in {r['trace_s']:.1f} s (deviation "
                f"{r['trace_deviation']:.0e}, {r['witnesses']} witnesses)"
                if r["trace_s"] is not None
                else f"no trace test ({'' if r['start_certified'] else 'not '}certified: {r['start_how']})"
            )
        )
    r = results["ik_local"]
    print(f"  ik_local n = 6: {r['us_per_converged']:.2f} µs per converged solve ({r['converged']:.1%} converged)")
    print_ik_local_single(results["ik_local_single"])
    print_derivatives_single(results["derivatives_single"])
    if results["make_generate_s"] is not None:
        print(f"\nmake generate (derivations + code generation): {results['make_generate_s']:.1f} s")
    worst = max(
        v for rows in results["kernels"].values() for row in rows.values() for v in row["max_abs_difference"].values()
    )
    print(f"largest difference between the tools' results: {worst:.2e}")
    print("\ntargets:")
    for t in results["targets"]:
        print(f"  [{'met' if t['met'] else 'MISSED'}] {t['target']}: {t['measured']:.3g}")
    args.out.write_text(json.dumps(results, indent=1, default=_plain) + "\n")
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
