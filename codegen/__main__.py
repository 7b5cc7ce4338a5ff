"""`python -m codegen [--out DIR] [--only NAME ...]`: run the derivations and write generated/."""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from derivations import apair_collisions, apair_dynamics, apair_pair, chain_dynamics, chain_kinematics, chain_variety

from .emitter import Emitter, write
from .varieties import PREFIX as VARIETY_PREFIX

DERIVATIONS = {
    "apair_collisions": apair_collisions,
    "apair_pair": apair_pair,
    "apair_dynamics": apair_dynamics,
    "chain_kinematics": chain_kinematics,
    "chain_dynamics": chain_dynamics,
    "chain_variety": chain_variety,
}
ROOT = Path(__file__).resolve().parent.parent


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m codegen", description=__doc__)
    ap.add_argument("--out", type=Path, default=ROOT / "generated", help="output folder (default: generated/)")
    ap.add_argument("--only", nargs="*", choices=sorted(DERIVATIONS), help="run only these derivations (no clean-up)")
    args = ap.parse_args(argv)
    names = args.only or sorted(DERIVATIONS)
    groups, poly_sets = {}, []
    for name in names:
        t0 = time.perf_counter()
        sets, specs, facts = DERIVATIONS[name].derive()
        groups[name] = specs
        poly_sets += sets
        print(f"derived {name}: {len(specs)} kernels, {len(sets)} polynomial sets "
              f"({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    t0 = time.perf_counter()
    files = Emitter().render(groups, poly_sets)
    changed = write(files, args.out, clean=args.only is None, keep=(f"polynomials/{VARIETY_PREFIX}",))
    print(f"emitted {len(files)} files ({time.perf_counter() - t0:.1f} s); changed: {len(changed)}", file=sys.stderr)
    for c in changed:
        print(f"  {c}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
