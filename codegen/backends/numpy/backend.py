"""The NumPy backend: one module of vectorised kernels per derivation (numpy/<derivation>.py), and
numpy/__init__.py with every kernel by name. Each kernel broadcasts over leading batch axes."""

from __future__ import annotations

from pathlib import Path

from ...hashing import content_hash
from ...ir import Lowered
from ...templating import Templates, TemplateSource

TEMPLATES = Templates(Path(__file__).parent / "templates")


def module(
    kernels: list[Lowered],
    source: str,
    hash: str,
    constants: list[tuple[str, object]] | None = None,
    template: TemplateSource = TEMPLATES,
    imports: list[tuple[str, str]] | None = None,
) -> str:
    """The text of one module of kernels (`constants`: module-level (name, value) assignments;
    `imports`: (module stem, kernel) of the kernels of other modules that its kernels call)."""
    context: dict[str, object] = {"kernels": kernels, "source": source, "hash": hash}
    if constants is not None:
        context["constants"] = constants
    if imports:
        context["imports"] = imports
    return template("kernels.py.j2")[0].render(**context)


def module_hash(kernels: list[Lowered], template: TemplateSource = TEMPLATES) -> str:
    """The content hash of a derivation's module: of the template and the kernel specs."""
    return content_hash([template("kernels.py.j2")[1]] + [k.fingerprint for k in kernels])


def render(
    lowered: dict[str, list[Lowered]], library_hash: str, template: TemplateSource = TEMPLATES
) -> dict[str, str]:
    """{path under generated/: text} of the modules of `lowered` ({derivation module stem: its
    kernels}) and their index (stamped with the C library's content hash). A kernel that calls one
    of another derivation imports it from that module."""
    home = {k.name: stem for stem, ks in lowered.items() for k in ks}
    files = {}
    for stem, ks in lowered.items():
        imports = sorted({(home[c.kernel], c.kernel) for k in ks for c in k.calls if home[c.kernel] != stem})
        files[f"numpy/{stem}.py"] = module(
            ks, ks[0].spec.source, module_hash(ks, template), template=template, imports=imports
        )
    files["numpy/__init__.py"] = template("numpy_init.py.j2")[0].render(
        modules=sorted(lowered),
        kernels=sorted((k.name, stem) for stem, ks in lowered.items() for k in ks),
        hash=library_hash,
    )
    return files
