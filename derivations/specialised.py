"""The kernels of one chain with its design substituted: every constant a number, every term the
design makes zero gone (what `apair codegen CHAIN.toml` and `AChain.specialise()` compile).

The generic kernels (chain_kinematics, chain_dynamics) take the design as inputs, so that one
library serves every chain. For a user's chain, `chain_specs` takes those specs, inlines the
kernels they call, puts each joint's law kernel (apair_pair.law_specs) in front, so that the only
inputs left are the joint values q (and qd, qdd or tau), and substitutes the design into the steps
one after the other. sympy's own evaluation does the folding as the steps are rebuilt: a product
with an exact zero vanishes, and a step that becomes a number or another name is substituted into
the steps after it, so what the design makes zero never reaches the code.

Numbers: zero and other integer values stay exact (a = 0, massless links, an R-pair's d ≡ 0); a
twist or angle offset within 4 ulp of a multiple of 90° is taken as that multiple, so cos 90° is
exactly 0 as the chain file meant it (the generic kernels see cos(1.5707963267948966) ≈ 6e-17);
every other constant is the exact value of its double, carried at 40 digits through the folding
and printed as the nearest double.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp

from . import apair_pair, chain_dynamics, chain_dynamics_derivatives, chain_kinematics
from .spec import Arg, Call, KernelSpec

SOURCE = "derivations/specialised.py"
DIGITS = 40  # precision of the constants folded at generation time
# Public kernel name -> the generic kernel family it specialises, in the order of the output files.
KERNELS = {
    "fk": "fk",
    "fk_study": "fk_study",
    "jacobian": "jacobian",
    "mass_matrix": "mass_matrix",
    "coriolis": "coriolis",
    "gravity_torques": "gravity",
    "bias": "bias",
    "inverse_dynamics": "inverse_dynamics",
    "forward_dynamics": "forward_dynamics",
    "energy": "energy",
    "inverse_dynamics_derivatives": "inverse_dynamics_derivatives",
    "forward_dynamics_derivatives": "forward_dynamics_derivatives",
}
# The dynamics' derivatives (derivations/chain_dynamics_derivatives.py) are made only when asked
# for: their derivation takes minutes for six joints, against seconds for all the others.
DERIVATIVES = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives")
DEFAULT = tuple(k for k in KERNELS if k not in DERIVATIVES)
KINEMATIC = ("fk", "fk_study", "jacobian")
KINDS = ("revolute", "sinusoidal", "general", "helical", "prismatic")
_LAW_ARITY = {"revolute": 0, "sinusoidal": 1, "general": 2, "helical": 1, "prismatic": 0}


@dataclass(frozen=True)
class Design:
    """A chain's constants as plain numbers (the runtime's AChain in this form): per joint the
    pair kind and its law kernel's constants after its variable (() | (h,) | (a, b) | (pitch,)), the DH row
    (a, α, c, φ), the link row (mass, com (3), Ixx, Iyy, Izz, Ixy, Ixz, Iyz) and the legs row
    (leg mass, r_b, r_p); and gravity in the base frame."""

    kinds: tuple[str, ...]
    law: tuple[tuple[float, ...], ...]
    dh: tuple[tuple[float, ...], ...]
    links: tuple[tuple[float, ...], ...]
    legs: tuple[tuple[float, ...], ...]
    gravity: tuple[float, ...]

    def __post_init__(self):
        n = len(self.kinds)
        if not 1 <= n <= chain_kinematics.MAX_N:
            raise ValueError(f"design: a chain has 1 to {chain_kinematics.MAX_N} joints, got {n}")
        for what, rows, width in (("dh", self.dh, 4), ("links", self.links, 10), ("legs", self.legs, 3)):
            if len(rows) != n or any(len(r) != width for r in rows):
                raise ValueError(f"design: {what} needs {n} rows of {width} numbers")
        for i, (kind, params) in enumerate(zip(self.kinds, self.law)):
            if kind not in KINDS or len(params) != _LAW_ARITY[kind]:
                raise ValueError(f"design: joint {i + 1} is a {kind!r} pair with law constants {params}")
        values = [x for rows in (self.law, self.dh, self.links, self.legs) for r in rows for x in r]
        if len(self.gravity) != 3 or not all(math.isfinite(x) for x in values + list(self.gravity)):
            raise ValueError("design: every constant must be a finite number, gravity three of them")

    @property
    def n(self) -> int:
        return len(self.kinds)

    def canonical(self) -> str:
        """The design as text, every number exact (float.hex): what the content hash covers."""

        def row(r):
            return "(" + ", ".join(float(x).hex() for x in r) + ")"

        lines = [
            f"joint {i + 1}: {k} law {row(p)} dh {row(d)} link {row(l)} legs {row(g)}"
            for i, (k, p, d, l, g) in enumerate(zip(self.kinds, self.law, self.dh, self.links, self.legs))
        ]
        return "\n".join(lines + [f"gravity {row(self.gravity)}"]) + "\n"


def _number(x: float) -> sp.Expr:
    """A design constant: exact when it is an integer, else its double's exact value."""
    x = float(x)
    return sp.Integer(int(x)) if x == int(x) else sp.Float(x, DIGITS)


def _angle(x: float) -> sp.Expr:
    """An angle: a multiple of π/2 when within 4 ulp of one (exact trigonometry), else `_number`."""
    k = round(x / (math.pi / 2))
    if abs(x - k * math.pi / 2) <= 4 * math.ulp(max(abs(x), math.pi / 2)):
        return sp.pi * sp.Rational(k, 2)
    return _number(x)


def _floats(e: sp.Expr) -> sp.Expr:
    """e with every numeric subexpression that is not a rational (√2/2, cos 0.3, π) as a Float."""
    if e.is_Rational or e.is_Float or e.is_Symbol:
        return e
    if e.is_number:
        return sp.Float(e.evalf(DIGITS), DIGITS)
    args = [_floats(a) for a in e.args]
    return e.func(*args) if any(a is not b for a, b in zip(args, e.args)) else e


def _trivial(e: sp.Expr) -> bool:
    return e.is_Number or e.is_Symbol


def design_values(design: Design, inputs: list[Arg]) -> dict:
    """The numbers of the generic spec's design inputs (dh, turning, links, legs, gravity)."""
    rows = {
        "dh": design.dh,
        "turning": (tuple(0.0 if k == "prismatic" else 1.0 for k in design.kinds),),
        "links": design.links,
        "legs": design.legs,
        "gravity": (design.gravity,),
    }
    env = {}
    for a in inputs:
        if not a.design:
            continue
        flat = [x for r in rows[a.name] for x in r]
        width = a.shape[-1]
        for k, (s, x) in enumerate(zip(a.symbols, flat)):
            angle = a.name == "dh" and k % width in (1, 3)  # alpha_i, phi_i
            env[s] = _angle(x) if angle else _number(x)
    return env


def joint_values(n: int) -> Arg:
    syms = tuple(sp.Symbol(f"q_{i}", real=True) for i in range(1, n + 1))
    return Arg("q", (n,), "joint values q_i: angles theta_i [rad], slides d_i [m] of prismatic pairs", syms)


def law_steps(design: Design, law_symbols, q: Arg, dddd_symbols=()) -> tuple[list, dict]:
    """Each joint's law kernel with its constants substituted, its input θ → q_i: the steps and
    the bindings of the chain kernels' law symbols (ch, sh, d, d', d'' per joint), and of
    `dddd_symbols` (d''' per joint, the law_<kind>_d3 kernels', whose steps are the law kernel's
    and are not repeated). An R-pair keeps the half angle too: with sincos of θ instead, the
    bench's 6R fk took 120 ns instead of 95 (libm is faster on the smaller half angles than the
    three operations saved)."""
    laws = {s.name: s for s in apair_pair.law_specs()}
    thirds = {s.name: s for s in apair_pair.law_d3_specs()}
    steps, env = [], {}
    for i, (kind, params) in enumerate(zip(design.kinds, design.law)):
        sub: dict = {}
        for spec, symbols, width in (
            (laws[f"law_{kind}"], law_symbols, 5),
            (thirds[f"law_{kind}_d3"], dddd_symbols, 1),
        ):
            if not len(symbols):
                continue
            sub[spec.inputs[0].symbols[0]] = q.symbols[i]
            sub.update({a.symbols[0]: _number(x) for a, x in zip(spec.inputs[1:], params)})
            more, sub = _fold([(s, e) for s, e in spec.steps if s not in sub], sub, suffix=f"_{i + 1}")
            steps += more
            for s, e in zip(symbols[width * i : width * i + width], spec.outputs[0].exprs):
                env[s] = _floats(sp.S(e).xreplace(sub))
    return steps, env


def _fold(steps, env: dict, suffix: str = "") -> tuple[list, dict]:
    """The steps with env substituted: those that become a number or a name are substituted into
    the later ones instead of kept; `suffix` renames the kept ones. Returns (steps, env)."""
    env = dict(env)
    out = []
    for sym, e in steps:
        v = _floats(e.xreplace(env))
        if _trivial(v):
            env[sym] = v
            continue
        new = sp.Symbol(sym.name + suffix, real=True) if suffix else sym
        out.append((new, v))
        if new is not sym:
            env[sym] = new
    return out, env


STATE = ("qd", "qdd", "tau")


def specialise(spec: KernelSpec, design: Design, name: str, doc: str, zeros=(), law_input: bool = False) -> KernelSpec:
    """`spec` (a generic chain kernel) for this design: inputs q and the spec's own qd, qdd or
    tau (those in `zeros` are zero and gone); the law kernels in front (or, with `law_input`,
    the law values as the input `law`), the design folded in.

    A kernel that calls two or more others (forward dynamics: the mass matrix and the bias) keeps
    them as calls of its own specialised parts, after a first part that evaluates the laws once
    for all of them, so that a batch runs each part over a block of items while its code is in
    the instruction cache (one function of all of it ran 1.5-2.5x slower); any other kernel's
    calls are inlined and folded with it."""
    keep = len(spec.calls) >= 2
    flat = spec if keep else spec.flattened()
    by_name = {a.name: a for a in flat.inputs}
    law = by_name["law"]
    q = joint_values(design.n)
    if law_input:
        head, steps, env = [law], [], {}
    else:
        head = [q]
        thirds = by_name["dddd"].symbols if "dddd" in by_name and not keep else ()
        steps, env = law_steps(design, law.symbols, q, thirds)
    env.update(design_values(design, flat.inputs))
    env.update({s: sp.S(0) for z in zeros for s in by_name[z].symbols})
    inputs = head + [a for a in flat.inputs if a.name in STATE and a.name not in zeros]
    calls = []
    if keep:
        laws = KernelSpec(
            f"{name}_law",
            f"Part of {name}: the joints' law values at q.",
            SOURCE,
            [q],
            [Arg("law", law.shape, law.doc, exprs=tuple(env[s] for s in law.symbols))],
            steps,
        )
        steps = []
        results = tuple(sp.Symbol(f"{s.name}_v", real=True) for s in law.symbols)
        calls.append(Call(laws, ("q",), results))
        env.update(zip(law.symbols, results))  # the kernel's own steps take the law values of the first part
        if "dddd" in by_name:  # and d3 of the laws (derivative kernels) in its own steps, from q
            steps, more = law_steps(design, (), q, by_name["dddd"].symbols)
            env.update(more)
        for c in flat.calls:
            passed = {a.name: arg for arg, a in zip(c.args, c.kernel.inputs)}
            part_zeros = [a for a, arg in passed.items() if arg is None]
            family = c.kernel.name.rstrip("0123456789")
            part = specialise(
                c.kernel,
                design,
                f"{name}_{family}",
                f"Part of {name}: "
                + c.kernel.doc.replace(f" of a {design.n}-joint chain", "")
                + "".join(f" With {z} = 0." for z in part_zeros),
                zeros=part_zeros,
                law_input=True,
            )
            args = tuple("r0" if a.name == "law" else passed[a.name] for a in part.inputs)
            calls.append(Call(part, args, c.results))
    more, env = _fold(flat.steps, env)
    outputs = [
        Arg(a.name, a.shape, a.doc, exprs=tuple(_floats(sp.S(e).xreplace(env)) for e in a.exprs)) for a in flat.outputs
    ]
    return KernelSpec(name, doc, SOURCE, inputs, outputs, steps + more, calls)


def generic_specs(n: int, families) -> dict[str, KernelSpec]:
    """The generic kernels of an n-joint chain for the requested families, by family."""
    out = {}
    if any(f in KINEMATIC for f in families):
        out.update(
            {
                "fk": chain_kinematics.fk_spec(n),
                "fk_study": chain_kinematics.fk_study_spec(n),
                "jacobian": chain_kinematics.jacobian_spec(n),
            }
        )
    if any(f not in out and f not in DERIVATIVES for f in families):
        for s in chain_dynamics.specs_for(n):
            out[s.name[: -len(str(n))]] = s
    if any(f in DERIVATIVES for f in families):
        for s in chain_dynamics_derivatives.specs_for_n(n):
            out[s.name[: -len(str(n))]] = s
    return out


def chain_specs(design: Design, kernels=DEFAULT) -> list[KernelSpec]:
    """The specialised kernels (public names, in KERNELS order) of the design."""
    unknown = [k for k in kernels if k not in KERNELS]
    if unknown:
        raise ValueError(f"kernels: unknown {unknown}; choose from {list(KERNELS)}")
    todo = [k for k in KERNELS if k in kernels]
    generic = generic_specs(design.n, [KERNELS[k] for k in todo])
    out = []
    for k in todo:
        g = generic[KERNELS[k]]
        doc = g.doc.replace(f"of a {design.n}-joint chain", "of this chain").replace(
            f"a {design.n}-joint chain", "this chain"
        )
        out.append(specialise(g, design, k, doc))
    return out
