"""The C backend: the generated kernels as a self-contained C99 library (libm only) in c/.

Its files: apair.h (the one public header, the registry's types and every kernel's declarations),
apair_internal.h (the split form of the kernels other kernels call, the extended-precision
kernels), apair_registry.c (every kernel by name), one source per kernel (a program that links the
library takes only the kernels it calls), the hand-written solvers copied from src/csrc (every .c
and .h there: the sources, and their private header), and CMakeLists.txt and apair.pc.in to build
and install it. The header's content hash covers every C source and header, so it identifies the
library; the manifest records it with the sources' digest.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...hashing import content_hash, sources_hash
from ...ir import Lowered
from ...templating import VERSION, Templates, TemplateSource

TEMPLATES = Templates(Path(__file__).parent / "templates")
PREFIX = "apair_"
ROOT = Path(__file__).resolve().parents[3]
HAND_WRITTEN = "src/csrc"  # the hand-written C of the library (every .c and .h), relative to the source tree


@dataclass
class Library:
    """The C backend's output: files under c/, and what the manifest records of them."""

    files: dict[str, str]  # {path under generated/: text}
    content_hash: str  # the header's: of the kernel specs, the templates and every C source
    sources_hash: str  # of the C files the binding compiles (hashing.sources_hash)
    ops_per_item: dict[str, int]  # per item of a batch that shares its design, callees counted in


def invariant_size(k: Lowered, by_name: dict[str, Lowered]) -> int:
    """Doubles of a kernel's split form: its own invariants after those of the kernels it calls."""
    own = len(k.hoisted.stored) if k.hoisted else 0
    return own + sum(len(by_name[c.kernel].hoisted.stored) for c in k.calls)


def ops_per_item(k: Lowered, by_name: dict[str, Lowered]) -> int:
    """Operations per item of a batch that shares its design, those of the kernels it calls counted in."""
    own = k.hoisted.core_ops if k.hoisted else k.ops
    return own + sum(ops_per_item(by_name[c.kernel], by_name) for c in k.calls)


def copies(template: TemplateSource = TEMPLATES) -> dict[str, str]:
    """{file name: text} of the hand-written C files (the sources and private headers in
    src/csrc, in name order), each under a banner that names its origin."""
    banner, banner_src = template("copied.c.j2")
    folder = ROOT / HAND_WRITTEN
    paths = sorted(p for p in folder.glob("*") if p.suffix in (".c", ".h")) if folder.is_dir() else []
    if not any(p.suffix == ".c" for p in paths):
        raise FileNotFoundError(
            f"{HAND_WRITTEN}: the C library's hand-written sources are read from the source "
            f"tree ({ROOT}), which this installation does not have"
        )
    out = {}
    for path in paths:
        origin = f"{HAND_WRITTEN}/{path.name}"
        text = path.read_text()
        out[path.name] = banner.render(origin=origin, hash=content_hash([banner_src, text])) + text
    return out


def render(kernels: list[Lowered], template: TemplateSource = TEMPLATES) -> Library:
    """The library of `kernels` (every derivation's, in derivation order)."""
    fingerprints = {k.name: k.fingerprint for k in kernels}
    by_name = {k.name: k for k in kernels}
    inv_sizes = {k.name: invariant_size(k, by_name) for k in kernels if k.hoisted or k.calls}
    sources = sorted({k.spec.source for k in kernels})
    files: dict[str, str] = {}

    registry_t, registry_src = template("registry.c.j2")
    files["c/apair_registry.c"] = registry_t.render(
        kernels=sorted(kernels, key=lambda k: k.name),
        prefix=PREFIX,
        sources=sources,
        inv_sizes=inv_sizes,
        hash=content_hash([registry_src] + [fingerprints[k.name] for k in kernels]),
    )

    called = sorted({c.kernel for k in kernels for c in k.calls})
    for name in called:
        if by_name[name].hoisted is None:
            raise ValueError(f"{name} is called by another kernel but has no design-only part to share")
    wide = [k for k in kernels if k.spec.wide]
    internal = sorted(set(called) | {k.name for k in wide})
    internal_t, internal_src = template("apair_internal.h.j2")
    files["c/apair_internal.h"] = internal_t.render(
        kernels=[by_name[c] for c in called],
        wide=wide,
        prefix=PREFIX,
        sources=sorted({by_name[c].spec.source for c in internal}) or ["no derivation (no internal kernel)"],
        hash=content_hash([internal_src] + [fingerprints[c] for c in internal]),
    )

    src_t, src_src = template("kernels.c.j2")
    for k in kernels:
        c_hash = content_hash([src_src, fingerprints[k.name]] + [fingerprints[c.kernel] for c in k.calls])
        files[f"c/{k.name}.c"] = src_t.render(
            kernels=[k],
            source=k.spec.source,
            hash=c_hash,
            prefix=PREFIX,
            by_name=by_name,
            called=called,
            inv_sizes=inv_sizes,
        )
    hand_written = copies(template)
    files.update({f"c/{name}": text for name, text in hand_written.items()})

    hand_headers = sorted(name for name in hand_written if name.endswith(".h"))  # private: not installed
    c_sources = sorted(
        ["apair_registry.c"] + [n for n in hand_written if n.endswith(".c")] + [f"{k.name}.c" for k in kernels]
    )
    header_t, header_src = template("apair.h.j2")
    header_hash = content_hash(
        [header_src, VERSION]
        + [fingerprints[k.name] for k in kernels]
        + [files[f"c/{c}"] for c in c_sources]
        + [files["c/apair_internal.h"]]
        + [files[f"c/{h}"] for h in hand_headers]
    )
    files["c/apair.h"] = header_t.render(
        kernels=kernels, hash=header_hash, sources=sources, prefix=PREFIX, version=VERSION, inv_sizes=inv_sizes
    )
    for name in ("CMakeLists.txt", "apair.pc.in"):
        t, src = template(f"{name}.j2")
        files[f"c/{name}"] = t.render(
            sources=sources, c_sources=c_sources, version=VERSION, hash=content_hash([src, VERSION] + c_sources)
        )
    compiled = {rel[2:]: text for rel, text in files.items() if rel.endswith((".c", ".h"))}
    return Library(files, header_hash, sources_hash(compiled), {k.name: ops_per_item(k, by_name) for k in kernels})
