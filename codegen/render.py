"""The files of generated/: each backend's, then the package's __init__.py and manifest.json.

Output is deterministic: the same lowered kernels give byte-identical files, each naming the
derivation that produced it and a content hash of its inputs (the kernel specs and the templates).
"""

from __future__ import annotations

import json

from .backends import c, casadi, js, numpy
from .ir import Lowered
from .templating import TemplateSource

INIT = (
    '"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.\n\n'
    'Content hash: {hash}\n"""\n'
)


def manifest_entry(stem: str, k: Lowered, ops_per_item: int) -> dict:
    """What the runtime reads of a kernel in manifest.json."""
    return {
        "module": stem,
        "source": k.spec.source,
        "doc": k.spec.doc,
        "inputs": [{"name": a.name, "shape": list(a.shape), "doc": a.doc} for a in k.spec.inputs],
        "outputs": [{"name": a.name, "shape": list(a.shape), "doc": a.doc} for a in k.spec.outputs],
        "ops": k.ops,
        "ops_per_item": ops_per_item,  # per item of a batch that shares its design (callees counted in)
        "fingerprint": k.fingerprint[:16],
    }


def render_all(
    lowered: dict[str, list[Lowered]], poly_files: dict[str, str], template: TemplateSource | None = None
) -> dict[str, str]:
    """lowered: {derivation module stem: its lowered kernels}; poly_files: the rendered polynomial
    sets (backends.polynomials.render) -> {path under generated/: text}. `template`: where the
    backends find their templates (default: each its own folder)."""
    own = {} if template is None else {"template": template}
    lowered = {stem: ks for stem, ks in lowered.items() if ks}  # skip set-only derivations
    kernels = [k for ks in lowered.values() for k in ks]
    library = c.render(kernels, **own)
    files = dict(poly_files, **library.files)
    files.update(numpy.render(lowered, library.content_hash, **own))
    files.update(js.render(kernels, **own))
    files.update(casadi.render(lowered, **own))
    files["__init__.py"] = INIT.format(hash=library.content_hash)
    manifest = {
        "content_hash": library.content_hash,
        "prefix": c.PREFIX,
        "sources_hash": library.sources_hash,
        "kernels": {
            k.name: manifest_entry(stem, k, library.ops_per_item[k.name]) for stem, ks in lowered.items() for k in ks
        },
    }
    files["manifest.json"] = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
    return files
