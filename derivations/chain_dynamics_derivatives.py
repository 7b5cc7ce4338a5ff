"""Derivatives of the chain dynamics in the joint state, n = 1..7 (issue 39): reverse-mode
differentiation of the recorded steps of derivations/chain_dynamics.py, never finite differences.

- `inverse_dynamics_derivatives{n}`: ∂τ/∂θ and ∂τ/∂θ' of τ = RNEA(θ, θ', θ''), each row one
  gradient (derivations/autodiff.py `gradient`: one backward pass over the recursion's steps).
  Row i is ∇τ_i: the adjoints of the velocity symbols are ∂τ_i/∂θ', those of the law values give
  ∂τ_i/∂θ_k through the law (`Assembly.seeds(k)`: cos(θ/2), sin(θ/2), d, d', and d'' → d''').
  n backward passes give both matrices, where forward mode took 2n passes (one per column, each
  re-running the recursion from link k and the whole backward pass): after CSE, 15818 → 13129
  operations for n = 6 and 21733 → 18058 for n = 7. (∂τ/∂θ'' is M, the mass_matrix kernel's.)
- `forward_dynamics_derivatives{n}`: with θ'' = FD(θ, θ', τ) solving M θ'' = τ − b,
  ∂FD/∂θ = −M⁻¹ ∂ID/∂θ and ∂FD/∂θ' = −M⁻¹ ∂ID/∂θ' at (θ, θ', θ''), and ∂FD/∂τ = M⁻¹. M and the
  bias b = ID(θ, θ', 0) come from the mass_matrix and inverse_dynamics kernels (`Call`), M⁻¹ from
  its Cholesky factor: M⁻¹ = L⁻ᵀ L⁻¹ (NaN where M is not positive definite).

d''' enters only here (the derivative of the RNEA term d''_i θ'_i² e_z): the law kernels give
(cos(θ/2), sin(θ/2), d, d', d''), which every chain kernel takes, so d''' is an extra input
`dddd` (n,) of these kernels alone, from the pairs' law_<kind>_d3 kernels
(derivations/apair_pair.py). Its seed carries the same per-joint factor as d' → d'' does.
"""

from __future__ import annotations

import sympy as sp

from .autodiff import gradient
from .chain_dynamics import Assembly, rnea, specs_for
from .chain_kinematics import MAX_N, _Recorder, revolute, revolute_name
from .spec import Arg, Call, KernelSpec

SOURCE = "derivations/chain_dynamics_derivatives.py"


def dddd_arg(n: int) -> Arg:
    """The derivative kernels' extra per-joint input d'''_i."""
    return Arg(
        "dddd",
        (n,),
        "d'''_i [m/rad^3] per joint from the pair's law (the law_<kind>_d3 kernels)",
        tuple(sp.Symbol(f"dddd_{i}", real=True) for i in range(1, n + 1)),
    )


def needed(steps, exprs) -> list:
    """The steps that `exprs` depend on, in their order (the rest would only be differentiated)."""
    want = set().union(*(sp.S(e).free_symbols for e in exprs))
    keep = []
    for sym, e in reversed(steps):
        if sym in want:
            keep.append((sym, e))
            want |= e.free_symbols
    return keep[::-1]


def angle_seeds(asm: Assembly, k: int, dddd: sp.Symbol) -> dict:
    """d/dθ_k of the inputs: `asm.seeds(k)`, and d'' → d''' with the factor of d' → d''."""
    j = asm.J[k - 1]
    seeds = dict(asm.seeds(k))
    if j["ddd"] not in seeds and j["dd"] in seeds:
        seeds[j["ddd"]] = sp.cancel(sp.S(seeds[j["dd"]]) / j["ddd"]) * dddd
    return seeds


def rnea_derivatives(asm: Assembly, qdd, dddd, prefix: str):
    """(steps, ∂τ/∂θ, ∂τ/∂θ') of τ = RNEA(θ, θ', qdd) with gravity (n x n matrices, [i, k] =
    ∂τ_i/∂x_k); `qdd` are symbols held fixed (inputs, or steps computed before these). Row i is
    one reverse pass: the gradient of τ_i in the law values (then through the law to θ_k) and in
    the velocities, over the steps that depend on them."""
    n = asm.n
    qd = [j["qd"] for j in asm.J]
    id_steps, tau = rnea(asm, qd, qdd, gravity=True, prefix=f"{prefix}id_")
    steps = needed(asm.rec.steps + id_steps, tau)
    live = active(steps, set(asm.args["law"].symbols) | set(qd))
    out = list(steps)
    dq, dqd = sp.zeros(n, n), sp.zeros(n, n)
    seeds = [angle_seeds(asm, k, dddd[k - 1]) for k in range(1, n + 1)]
    for i in range(n):
        new, grads = gradient(live, tau[i], f"{prefix}r{i + 1}_")
        out += new
        for k in range(n):
            dq[i, k] = sum((grads.get(s, 0) * v for s, v in seeds[k].items()), sp.S(0))
            dqd[i, k] = grads.get(qd[k], 0)
    return out, dq, dqd


def active(steps, inputs) -> list:
    """The steps that depend on `inputs`: only they need adjoints (the others, design invariants
    and the held accelerations, are constants of the differentiation)."""
    live, keep = set(inputs), []
    for sym, e in steps:
        if e.free_symbols & live:
            keep.append((sym, e))
            live.add(sym)
    return keep


def cholesky_inverse(M: sp.Matrix, prefix: str):
    """Steps of L⁻¹ (lower triangular, M = L Lᵀ) and M⁻¹ = L⁻ᵀ L⁻¹ of a symmetric positive
    definite M (a square root of a negative number gives NaN where it is not). Returns (steps,
    L⁻¹, M⁻¹)."""
    rec = _Recorder()
    n = M.shape[0]
    L = sp.zeros(n, n)
    inv = [sp.S(0)] * n
    for j in range(n):
        L[j, j] = rec.name(f"{prefix}L{j}{j}", sp.sqrt(M[j, j] - sum((L[j, k] ** 2 for k in range(j)), sp.S(0))))
        inv[j] = rec.name(f"{prefix}iL{j}", 1 / L[j, j])
        for i in range(j + 1, n):
            L[i, j] = rec.name(
                f"{prefix}L{i}{j}", (M[i, j] - sum((L[i, k] * L[j, k] for k in range(j)), sp.S(0))) * inv[j]
            )
    Li = sp.zeros(n, n)  # L⁻¹ column by column: L Li[:, c] = e_c
    for c in range(n):
        Li[c, c] = inv[c]
        for i in range(c + 1, n):
            Li[i, c] = rec.name(f"{prefix}Li{i}{c}", -sum((L[i, k] * Li[k, c] for k in range(c, i)), sp.S(0)) * inv[i])
    Minv = sp.zeros(n, n)
    for i in range(n):
        for k in range(i, n):
            Minv[i, k] = Minv[k, i] = rec.name(
                f"{prefix}Mi{i}{k}", sum((Li[r, i] * Li[r, k] for r in range(k, n)), sp.S(0))
            )
    return rec.steps, Li, Minv


def specs_for_n(n: int) -> list[KernelSpec]:
    """The two derivative kernels of the n-joint chain, and their forms for chains of R-pairs."""
    base = {s.name: s for s in specs_for(n)}
    mass, inverse = base[f"mass_matrix{n}"], base[f"inverse_dynamics{n}"]
    asm = Assembly(n)
    dddd = dddd_arg(n)
    body = ("dh", "turning", "links", "legs", "gravity")
    qdd = [j["qdd"] for j in asm.J]
    steps, dq, dqd = rnea_derivatives(asm, qdd, dddd.symbols, "")
    id_spec = KernelSpec(
        f"inverse_dynamics_derivatives{n}",
        f"Derivatives dtau/dtheta and dtau/dtheta' ({n} x {n} each) of the inverse dynamics of a "
        f"{n}-joint chain (dtau/dtheta'' is the mass matrix).",
        SOURCE,
        asm.inputs("law") + [dddd] + asm.inputs("qd", "qdd", *body),
        [
            Arg("dtau_dq", (n, n), "d tau_i / d theta_k [N m/rad], row-major", exprs=tuple(dq)),
            Arg("dtau_dqd", (n, n), "d tau_i / d theta'_k [N m s/rad], row-major", exprs=tuple(dqd)),
        ],
        steps,
    )

    M_r = sp.Matrix(n, n, [sp.Symbol(f"rM{k}", real=True) for k in range(n * n)])
    b_r = [sp.Symbol(f"rb{k}", real=True) for k in range(n)]
    taus = [sp.Symbol(f"tau_{k}", real=True) for k in range(1, n + 1)]
    inv_steps, Li, Minv = cholesky_inverse(M_r, "fd_")
    rec = _Recorder()
    y = [rec.name(f"fd_y{i}", sum((Li[i, k] * (taus[k] - b_r[k]) for k in range(i + 1)), sp.S(0))) for i in range(n)]
    acc = [rec.name(f"fd_x{i}", sum((Li[k, i] * y[k] for k in range(i, n)), sp.S(0))) for i in range(n)]
    d_steps, dq, dqd = rnea_derivatives(asm, acc, dddd.symbols, "fd_")
    fd_spec = KernelSpec(
        f"forward_dynamics_derivatives{n}",
        f"Derivatives dtheta''/dtheta, dtheta''/dtheta' and M^-1 = dtheta''/dtau ({n} x {n} each) of the "
        f"forward dynamics of a {n}-joint chain, by a Cholesky factorisation of M (NaN where M is not "
        "positive definite).",
        SOURCE,
        asm.inputs("law")
        + [dddd]
        + asm.inputs("qd")
        + [Arg("tau", (n,), "joint torques tau_i [N m]", tuple(taus))]
        + asm.inputs(*body),
        [
            Arg("dqdd_dq", (n, n), "d theta''_i / d theta_k [1/s^2], row-major", exprs=tuple(-Minv * dq)),
            Arg("dqdd_dqd", (n, n), "d theta''_i / d theta'_k [1/s], row-major", exprs=tuple(-Minv * dqd)),
            Arg("Minv", (n, n), "M^-1 = d theta''_i / d tau_k [1/(kg m^2)], row-major", exprs=tuple(Minv)),
        ],
        inv_steps + rec.steps + d_steps,
        calls=[
            Call(mass, ("law", "dh", "turning", "links", "legs"), tuple(M_r)),
            Call(inverse, ("law", "qd", None, "dh", "turning", "links", "legs", "gravity"), tuple(b_r)),
        ],
    )
    # their forms for chains of R-pairs (chain_kinematics.revolute: about 40 % fewer operations), the
    # forward dynamics' calling the R-chain mass matrix and inverse dynamics
    twins = {k.name: base[revolute_name(k.name)] for k in (mass, inverse)}
    return [id_spec, fd_spec, revolute(id_spec), revolute(fd_spec, twins)]


PARTS = tuple(range(1, MAX_N + 1))  # codegen runs these as parallel jobs


def derive(part=None):
    """(sets, specs, facts) of one part (a chain length n), or of all."""
    if part is None:
        return [], [s for p in PARTS for s in derive(p)[1]], {}
    if part not in PARTS:
        raise ValueError(f"part: expected one of {PARTS}, got {part!r}")
    return [], specs_for_n(part), {}
