"""`python -m codegen.varieties [--out DIR]`: the constraint varieties of the example 2-pair chains.

Each example in examples/ with two joints and rational constants gets its variety computed exactly
by the installed runtime's engine (apair.variety: FLINT nullspaces on points of the chain's
rational image) and written, like every derived set, as generated/polynomials/variety_<stem>.{txt,
tex,json}; `apair show variety_2a_chain` prints it. This runs after `make install` (the engine is
part of the runtime); `python -m codegen` leaves these files in place.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from . import derivation
from .backends.polynomials import render_polynomial_set
from .hashing import content_hash
from .output import OutputError, write

_spec = derivation("spec")
Entry, PolynomialSet = _spec.Entry, _spec.PolynomialSet

ROOT = Path(__file__).resolve().parent.parent
PREFIX = "variety_"


def variety_set(path: Path) -> PolynomialSet | None:
    """The example's variety as a polynomial set, or None when it is not an exact 2-pair case."""
    import apair
    from apair.variety import VARS

    chain = apair.load(path)
    if chain.n != 2:
        return None
    V = chain.constraint_variety()
    if not V.exact:
        return None
    entries = [Entry(f"F{i}", P.as_expr(), tuple(VARS), note=f"degree {P.total_degree()}") for i, P in enumerate(V)]
    hf = ", ".join(f"HF({k}) = {v}" for k, v in V.hilbert.items())
    return PolynomialSet(
        name=f"{PREFIX}{path.stem}",
        title=f"Constraint variety of {chain.name} ({path.name}) in Study parameters",
        source=f"examples/{path.name} by codegen/varieties.py (the exact engine apair.variety)",
        description=(
            f"Homogeneous forms in x0..y3 generating every form of degree <= 4 that vanishes on all "
            f"poses of the chain (the Study quadric included). A surface of degree {V.degree}; "
            f"Hilbert function {hf}."
        ),
        entries=entries,
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m codegen.varieties", description=__doc__)
    ap.add_argument("--out", type=Path, default=ROOT / "generated", help="output folder (default: generated/)")
    args = ap.parse_args(argv)
    files = {}
    for path in sorted((ROOT / "examples").glob("*.toml")):
        t0 = time.perf_counter()
        ps = variety_set(path)
        if ps is not None:
            files.update(render_polynomial_set(ps, content_hash))
            print(
                f"variety of {path.name}: {len(ps.entries)} equations ({time.perf_counter() - t0:.1f} s)",
                file=sys.stderr,
            )
    try:
        # the variety files are this generator's own, beside generated/'s manifest (not in it)
        changed = write(files, args.out, clean=False, force=True)
    except OutputError as exc:
        print(f"python -m codegen.varieties: error: {exc}", file=sys.stderr)
        return 2
    for c in changed:
        print(f"  {c}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
