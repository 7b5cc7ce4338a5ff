"""Code generation: kernel specs -> lowering (CSE, ...) -> one backend per target -> generated/.

codegen and derivations are sibling packages: top-level in the source tree (`python -m codegen`
regenerates generated/), `apair.codegen` and `apair.derivations` in an installed apair, which
generates code for a user's own chain (`apair codegen`). `derivation(name)` imports the sibling's
module either way.
"""

import importlib

_DERIVATIONS = "derivations" if __name__ == "codegen" else __name__.rpartition(".")[0] + ".derivations"


def derivation(name: str):
    """The module derivations.`name` beside this package."""
    return importlib.import_module(f"{_DERIVATIONS}.{name}")
