"""Inverse kinematics of A-chains (`AChain.ik`, `AChain.ik_local`, `AChain.prepare_ik`): every real
solution of a pose, each verified, by the cheapest exact method that fits the chain.

- `solver`: the front (`Solver`, `Solution`), which picks the method by the chain's shape;
- `elimination4`: 1 to 4 joints by kinematic mapping (the joints as curves in the Study algebra in
  `joints`, the polynomial and pencil algebra in `pencil`);
- `elimination6r`, `elimination1a5r`: six joints (and five, with a virtual joint), all R-pairs or
  one A-pair, by the Raghavan-Roth elimination;
- `homotopy`: every complex solution of 5 and 6 joints by parameter homotopy from the design's
  start system (tracker, monodromy, start sets, the trace test, the patterns' counts);
- `families`: the chain's kinematic family (which axes are parallel or meet; EAIK's families);
- `poses`: poses in and the verification of candidates; `local`: Levenberg-Marquardt searches
  (the fallback, the nearest reachable pose `distance`, and `ik_local` in C).

Nothing here imports `apair.chain` (the chain delegates to this package, never the other way)
but the `make ik-counts` script `homotopy.counts`, which draws a random chain of every pattern.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .local import LocalSolution, distance, ik_local
    from .solver import Solution, Solver

__all__ = ["LocalSolution", "Solution", "Solver", "distance", "ik_local"]


# The public names, loaded on first access (PEP 562): the solvers pull in SciPy's LAPACK and every
# elimination, which a module that needs only `poses` (apair.hold, apair.compare: the chain itself)
# should not pay for at import.
def __getattr__(name: str) -> Any:
    module: Any
    if name in ("LocalSolution", "distance", "ik_local"):
        from . import local as module
    elif name in ("Solution", "Solver"):
        from . import solver as module
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
