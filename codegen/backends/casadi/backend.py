"""The CasADi backend: the pair laws and the chain kernels as functions that build CasADi SX
expression graphs (casadi/<derivation>.py, and casadi/__init__.py with every kernel by name), from
the same lowered kernels as C and NumPy. `AChain.to_casadi` (apair.symbolic) assembles a chain's
casadi.Function objects from them, so CasADi's own derivatives, code generation and solvers work
through apair's equations. Kernels of the derivations in SOURCES only."""

from __future__ import annotations

from pathlib import Path

from ...hashing import content_hash
from ...ir import Lowered
from ...templating import Templates, TemplateSource

TEMPLATES = Templates(Path(__file__).parent / "templates")
SOURCES = ("derivations/apair_pair.py", "derivations/chain_kinematics.py", "derivations/chain_dynamics.py")


def render(lowered: dict[str, list[Lowered]], template: TemplateSource = TEMPLATES) -> dict[str, str]:
    """{path under generated/: text}: a module per derivation of SOURCES and their index, if
    `lowered` has them all (not all derivations run with `python -m codegen --only`), else nothing."""
    mine = {stem: ks for stem, ks in lowered.items() if ks and ks[0].casadi is not None}
    if sorted(ks[0].spec.source for ks in mine.values()) != sorted(SOURCES):
        return {}
    t, src = template("casadi_kernels.py.j2")
    files = {
        f"casadi/{stem}.py": t.render(
            kernels=ks, source=ks[0].spec.source, hash=content_hash([src] + [k.fingerprint for k in ks])
        )
        for stem, ks in mine.items()
    }
    init, init_src = template("casadi_init.py.j2")
    files["casadi/__init__.py"] = init.render(
        modules=sorted(mine),
        kernels=sorted((k.name, stem) for stem, ks in mine.items() for k in ks),
        hash=content_hash([src, init_src] + [k.fingerprint for ks in mine.values() for k in ks]),
    )
    return files
