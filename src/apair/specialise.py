"""Code for one chain with its design built in: `apair codegen CHAIN.toml` writes it (C, NumPy,
CMake, pkg-config, a self-test), `AChain.specialise()` compiles and loads it.

The kernels come from derivations/specialised.py (the generic chain kernels with the design folded
in), lowered and printed by the one emitter (codegen/emitter.py). Both ship inside the installed
package as apair.derivations and apair.codegen. The self-test's reference values are computed here
by the generic runtime, so the generated code is checked against an independent evaluation.

Base and tool frames (docs/conventions.md §9): the kernels are of the DH chain with gravity in its
frame 0 (R_baseᵀ·g); the generated fk, fk_study and jacobian compose the frames around them (their
frame-0 versions stay, as name_fk_dh, ...), and the content hash covers the frames. The runtime's
registry (AChain.specialise) holds the frame-0 kernels: the chain composes its frames itself.
"""

from __future__ import annotations

import hashlib
import keyword
import os
import re
import sys
from collections.abc import Iterable, Sequence
from importlib import resources
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from . import _validate as V
from .files import cache_root, toolkit_digest
from .frames import check_frame

if TYPE_CHECKING:
    from ._typing import ChainLike
    from .kernels import FastPath

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if inline int long "
    "register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while "
    "bool true false class namespace new delete template this operator private public protected".split()
)
SELFTEST_STATES = 4


def _toolkit() -> tuple[ModuleType, ModuleType]:
    """derivations.specialised and codegen.emitter, as installed with the runtime."""
    from .codegen import emitter
    from .derivations import specialised

    return specialised, emitter


def frames_of(chain: ChainLike) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """The chain's base and tool transforms (AChain's `base`, `tool`), validated again
    (apair.frames.check_frame); None for the identity (no frame)."""
    return check_frame("base", getattr(chain, "_base_T", None)), check_frame("tool", getattr(chain, "_tool_T", None))


def check_frames(chain: ChainLike) -> None:
    """Checks the chain's base and tool frames (`frames_of`); a chain with frames is accepted: the
    generated fk, fk_study and jacobian compose them, the dynamics take gravity in frame 0."""
    frames_of(chain)


def design_of(chain: ChainLike) -> Any:
    """The chain's constants as derivations.specialised.Design (plain numbers); gravity in frame 0
    (R_baseᵀ·g with a base frame, as the chain's kernels take it). The frames themselves are
    `frame_constants`."""
    specialised, _ = _toolkit()
    gravity = getattr(chain, "_gravity", None)
    return specialised.Design(
        kinds=tuple(p.kind for p in chain.pairs),
        law=tuple(tuple(float(x) for x in p.law_kernel[1]) for p in chain.pairs),
        dh=tuple(tuple(float(x) for x in row) for row in chain._dh),
        links=tuple(tuple(float(x) for x in row) for row in chain._links),
        legs=tuple(tuple(float(x) for x in row) for row in chain._legs),
        gravity=tuple(float(x) for x in (chain.gravity if gravity is None else gravity)),
    )


def frame_constants(chain: ChainLike) -> dict[str, Any] | None:
    """The constants of the chain's base and tool frames as the generated code builds them in
    (every number the exact double, as Python's repr): base and tool (4 rows of 4; the identity
    for none), their Study points (apair.study.from_matrix, as AChain composes fk_study), the
    tool's translation (None if zero: the Jacobian skips ω × r, as AChain does) and the world's
    gravity; None for a chain without frames (the code is then byte for byte that of the DH chain)."""
    from .study import from_matrix

    base, tool = frames_of(chain)
    if base is None and tool is None:
        return None
    B = np.eye(4) if base is None else base
    T = np.eye(4) if tool is None else tool

    def text(values: NDArray[np.float64]) -> list[str]:
        return [repr(float(x)) for x in np.asarray(values).ravel()]

    return {
        "base": [text(row) for row in B],
        "tool": [text(row) for row in T],
        "base_study": text(from_matrix(B)),
        "tool_study": text(from_matrix(T)),
        "tool_offset": text(T[:3, 3]) if T[:3, 3].any() else None,
        "gravity": text(chain.gravity),
    }


def _frames_canonical(chain: ChainLike) -> str:
    """The base and tool as text, every number exact (float.hex), for the content hash; empty
    without frames (the hash of a frameless chain is unchanged)."""
    base, tool = frames_of(chain)
    if base is None and tool is None:
        return ""
    rows = [("base", np.eye(4) if base is None else base), ("tool", np.eye(4) if tool is None else tool)]
    return "".join(f"{what} ({', '.join(float(x).hex() for x in T.ravel())})\n" for what, T in rows)


def kernels_for(chain: ChainLike, kernels: Iterable[str] | None) -> tuple[str, ...]:
    """`check_kernels`, and with a tool frame that has a translation, fk with jacobian (the
    Jacobian of the tool's origin needs frame n's rotation, which the DH fk gives)."""
    chosen = check_kernels(kernels)
    offset = frame_constants(chain)
    if offset is not None and offset["tool_offset"] is not None and "jacobian" in chosen and "fk" not in chosen:
        chosen = check_kernels(("fk", *chosen))
    return chosen


def content_hash(chain: ChainLike, kernels: Iterable[str]) -> str:
    """16 hex digits identifying the generated code: the design (with the base and tool frames),
    the kernels chosen, the toolkit."""
    kernels = kernels_for(chain, kernels)
    h = hashlib.sha256((design_of(chain).canonical() + _frames_canonical(chain)).encode())
    h.update((",".join(kernels) + "\0" + toolkit_digest()).encode())
    return h.hexdigest()[:16]


# Names a prefix must not take: the generated NAME.py beside NAME.h would shadow a module of Python's
# standard library (the generated code imports numpy, numpy imports os, sys, math, ...) or a
# third-party module it imports; NAME.h would shadow a standard C or POSIX header on an include path.
_C_HEADERS = (
    "assert complex ctype errno fenv float inttypes iso646 limits locale math setjmp signal stdalign stdarg "
    "stdatomic stdbool stddef stdint stdio stdlib stdnoreturn string tgmath threads time uchar wchar wctype "
    "unistd fcntl dlfcn pthread strings alloca malloc memory features endian"
).split()
_TAKEN_NAMES = frozenset(n.lower() for n in (*sys.stdlib_module_names, "numpy", "ctypes", "apair", *_C_HEADERS))


def check_prefix(name: str) -> str:
    """A prefix usable as C identifier stem and Python module name, or a ValueError."""
    if not isinstance(name, str) or not _IDENT.match(name) or len(name) > 48:
        raise ValueError(
            f"prefix: expected a C identifier (letters, digits, _; not starting with a digit; at most "
            f"48 characters), got {V.shorten(repr(name))}"
        )
    if name in _C_KEYWORDS or keyword.iskeyword(name) or name.startswith("apair"):
        raise ValueError(f"prefix: {name!r} is a C, C++ or Python keyword or apair's own prefix")
    if name.lower() in _TAKEN_NAMES:
        raise ValueError(
            f"prefix: {name!r} would shadow a module Python or the generated code imports, or a standard "
            f"C header, when the output folder is on the import or include path; choose another name"
        )
    return name


def prefix_from(path: str | os.PathLike[str]) -> str:
    """The default prefix of a chain file: its name without .toml, made an identifier."""
    stem = re.sub(r"[^A-Za-z0-9_]", "_", Path(path).stem) or "chain"
    if stem[0].isdigit():
        stem = "chain_" + stem
    stem = stem[:42]  # an identifier by now: check_prefix can refuse it only as a reserved name
    try:
        return check_prefix(stem)
    except ValueError:
        return check_prefix("chain_" + stem)  # math.toml gives chain_math, not a math.h beside the user's code


def check_kernels(kernels: Iterable[str] | None) -> tuple[str, ...]:
    """The kernels chosen, in the order of the output, or by default all but the dynamics'
    derivatives (derivations.specialised.DEFAULT: those take minutes to derive, so are made only
    when named); a ValueError for an unknown name or none."""
    specialised, _ = _toolkit()
    if kernels is None:
        return tuple(specialised.DEFAULT)
    chosen = tuple(kernels)
    unknown = [k for k in chosen if k not in specialised.KERNELS]
    if unknown or not chosen:
        raise ValueError(
            f"kernels: expected names from {', '.join(specialised.KERNELS)}, got {', '.join(chosen) or 'none'}"
        )
    return tuple(k for k in specialised.KERNELS if k in chosen)


def lowered(chain: ChainLike, kernels: Iterable[str]) -> tuple[list[Any], dict[str, Any]]:
    """The chain's specialised kernels, derived and lowered (CSE, printed), and the parts they
    call by name."""
    specialised, emitter = _toolkit()
    specs = specialised.chain_specs(design_of(chain), kernels)
    parts = {c.kernel.name: emitter.lower(c.kernel) for s in specs for c in s.calls}
    return [emitter.lower(s) for s in specs], parts


def _states(chain: ChainLike, count: int, seed: int) -> dict[str, NDArray[np.float64]]:
    """The self-test's states: q = 0, then random joint values well inside the limits; random qd,
    qdd, tau."""
    rng = np.random.default_rng(seed)
    lim = chain.limits
    mid, half = lim.mean(axis=1), (lim[:, 1] - lim[:, 0]) / 2
    q = mid + 0.9 * half * rng.uniform(-1, 1, (count, chain.n))
    q[0] = np.clip(0.0, lim[:, 0] + 0.05 * half, lim[:, 1] - 0.05 * half)
    return {
        "q": q,
        "qd": rng.normal(size=(count, chain.n)),
        "qdd": rng.normal(size=(count, chain.n)),
        "tau": rng.normal(size=(count, chain.n)),
    }


def references(
    chain: ChainLike, kernels: list[Any], count: int = SELFTEST_STATES, seed: int = 0
) -> list[dict[str, Any]]:
    """Inputs and generic-runtime outputs of each kernel on the self-test's states (every output of
    a kernel of several: the method's first ones, inverse_dynamics_derivatives' M being the
    mass_matrix kernel's); a kernel whose reference cannot be computed (forward dynamics of a chain
    without inertia) is left out."""
    states = _states(chain, count, seed)
    methods = {"coriolis": "coriolis_matrix"}
    tests = []
    for k in kernels:
        ins = [states[a.name] for a in k.spec.inputs]
        try:
            want = getattr(chain, methods.get(k.name, k.name))(*ins)
        except ValueError:
            continue
        wants = want if isinstance(want, tuple) else (want,)
        tests.append(
            {
                "name": k.name,
                "inputs": [(a, [f"{x:.17g}" for x in v.ravel()]) for a, v in zip(k.spec.inputs, ins)],
                "outputs": [(a, [f"{x:.17g}" for x in np.asarray(w).ravel()]) for a, w in zip(k.spec.outputs, wants)],
            }
        )
    return tests


def _describe(chain: ChainLike) -> tuple[str, str]:
    joints = ", ".join(f"{i + 1} {p.kind}" for i, p in enumerate(chain.pairs))
    ranges = "; ".join(
        f"|q_{i + 1}| <= {p.theta_limit!r} (mod 2 pi)" for i, p in enumerate(chain.pairs) if p.theta_limit is not None
    )
    return joints, ranges


def _ascii(text: str, keep: str, fill: str) -> str:
    """text for the comments and strings of the generated C, CMake and Python: ASCII letters,
    digits, _ and the characters of `keep` as they are, any other ASCII character as `fill` (so
    nothing ends a comment, forms a trigraph or a line splice, or is read by CMake), and a
    character beyond ASCII as <U+XXXX> (no compiler sees it, and none is lost)."""

    def one(m: re.Match[str]) -> str:
        ch = m.group()
        return fill if ch.isascii() else f"<U+{ord(ch):04X}>"

    return re.sub(f"[^A-Za-z0-9_{re.escape(keep)}]", one, text)


def _title(title: str | None, n: int) -> str:
    """The chain's title as the generated files print it: one line of at most 80 characters,
    `_ascii` (no code point cut in two); the chain's size if it has none or nothing printable."""
    default = f"{n}-joint chain"
    if title is None:
        return default
    short = " ".join(_ascii(V.text("title", title), " .,:()+-", " ").split())[:80]
    return re.sub(r"<U\+[0-9A-F]*$", "", short).rstrip() or default


def render(
    chain: ChainLike,
    name: str,
    origin: str,
    kernels: Iterable[str] | None = None,
    title: str | None = None,
    code: tuple[list[Any], dict[str, Any]] | None = None,
) -> dict[str, str]:
    """{file name: text} of the chain's code (see codegen.emitter.Emitter.render_chain); `code`:
    the lowered kernels if already at hand."""
    _, emitter = _toolkit()
    name = check_prefix(name)
    kernels = kernels_for(chain, kernels)
    lowered_kernels, parts = code or lowered(chain, kernels)
    frames = frame_constants(chain)
    tests = [dict(t, kernel=k) for k, t in _tests(chain, lowered_kernels, frames is not None)]
    joints, ranges = _describe(chain)
    # the title and origin go into C comments, CMake strings and Python: `_ascii`
    title = _title(title, chain.n)
    origin = _ascii(origin, " .,:+/-", "_")[:120]
    meta = {
        "title": title,
        "origin": origin,
        "joints": joints,
        "ranges": ranges,
        "n": chain.n,
        "hash": content_hash(chain, kernels),
    }
    if frames is not None:  # a frameless chain's meta, and so its code, stays as it was
        meta["frames"] = frames
    return emitter.Emitter().render_chain(lowered_kernels, parts, name, meta, tests)


def _tests(chain: ChainLike, kernels: list[Any], framed: bool) -> list[tuple[Any, dict[str, Any]]]:
    """The self-test's (kernel, reference) pairs: each kernel's against the chain's method (with
    base and tool frames, the tool's in the world); with frames, after fk, fk_study and jacobian
    their frame-0 versions (name_dh, codegen.backends.chain.dh_kernel) against the DH chain's."""
    from .codegen.backends.chain import backend

    by_name = {k.name: k for k in kernels}
    tests = references(chain, kernels)
    if not framed:
        return [(by_name[t["name"]], t) for t in tests]
    plain = cast(Any, chain)._dh_chain()  # the DH chain, gravity in frame 0 (AChain._dh_chain)
    dh = {t["name"]: t for t in references(plain, [k for k in kernels if k.name in backend.FRAMED])}
    out = []
    for t in tests:
        out.append((by_name[t["name"]], t))
        if t["name"] in dh:
            k = backend.dh_kernel(by_name[t["name"]])
            out.append((k, dict(dh[t["name"]], name=k.name)))
    return out


def write_code(
    chain: ChainLike,
    out: str | os.PathLike[str],
    name: str,
    origin: str,
    kernels: Iterable[str] | None = None,
    title: str | None = None,
    force: bool = False,
) -> list[str]:
    """Write the chain's code into the folder `out` (created if need be). A file there that an
    earlier run did not write (a user's own, a symbolic link) is refused unless `force`; stale
    files of an earlier run are removed only while unedited (codegen/output.py). Returns the
    changes."""
    _, emitter = _toolkit()
    files = render(chain, name, origin, kernels, title)
    try:
        return emitter.write(files, Path(out), force=force)
    except emitter.OutputError as exc:
        raise ValueError(str(exc)) from None


# ------------------------------------------------------------------------------------ AChain.specialise
_warned: set[str] = set()


def _compiler() -> str | None:
    import os
    import shutil

    cc = os.environ.get("CC") or "cc"
    return shutil.which(cc) or shutil.which("gcc")


def _warn_once(key: str, message: str) -> None:
    import warnings

    if key not in _warned:
        _warned.add(key)
        warnings.warn(message, RuntimeWarning, stacklevel=4)


def build(chain: ChainLike, kernels: Iterable[str] | None = None) -> tuple[Path, str, tuple[str, ...]] | None:
    """The chain's specialised kernels compiled into a shared library in the cache (built on
    first use; the folder is named by the content hash, so a build of other code is never
    taken). Returns (library, symbol prefix, kernel names), or None without a C compiler."""
    import subprocess
    import tempfile

    kernels = kernels_for(chain, kernels)
    digest = content_hash(chain, kernels)
    name = f"spec_{digest}"
    folder = cache_root() / "specialised" / digest
    library = folder / f"lib{name}.so"
    if library.is_file():
        return library, name, kernels
    cc = _compiler()
    if cc is None:
        _warn_once(
            "cc",
            "apair: AChain.specialise() found no C compiler (set CC, or install gcc); the chain "
            "uses the generic kernels",
        )
        return None
    _, emitter = _toolkit()
    from .codegen.backends.chain import backend as chain_backend

    code = lowered(chain, kernels)
    files = render(chain, name, "AChain.specialise()", kernels, code=code)
    # the runtime's registry holds the frame-0 kernels: AChain composes the base and tool itself
    # (AChain._framed_call), exactly as for its generic kernels
    registry = code[0] if frame_constants(chain) is None else [chain_backend.dh_of(k) for k in code[0]]
    files[f"{name}_registry.c"] = emitter.Emitter().render_chain_registry(registry, name, digest)
    folder.parent.mkdir(parents=True, exist_ok=True)
    include = Path(str(resources.files("apair.generated"))) / "c"
    with tempfile.TemporaryDirectory(dir=folder.parent, prefix=f".{digest}-") as tmp:
        work = Path(tmp) / digest
        work.mkdir()
        for rel, text in files.items():
            (work / rel).write_text(text)
        cmd = [
            cc,
            "-std=c99",
            "-O2",
            "-fno-math-errno",
            "-fPIC",
            "-shared",
            f"-I{include}",
            f"{name}.c",
            f"{name}_registry.c",
            "-o",
            library.name,
            "-lm",
        ]
        res = subprocess.run(cmd, cwd=work, capture_output=True, text=True)
        if res.returncode != 0:
            raise RuntimeError(
                f"specialise: compiling the chain's kernels failed ({' '.join(cmd)}): "
                f"{' '.join(res.stderr.split())[:400]}"
            )
        try:
            os.rename(work, folder)  # atomic: another process may have won the race, which is fine
        except OSError:
            if not library.is_file():
                raise
    return library, name, kernels


def load(
    chain: ChainLike, methods: Sequence[tuple[str, bool]], kernels: Iterable[str] | None = None
) -> FastPath | None:
    """The native fast path of the chain's specialised kernels (kernels.native_chain) for the
    chain's `methods` ((kernel family, strict) in the order of its fast path: apair.chain.METHODS)
    and the loaded library, or None (no compiler, or the C backend is not installed). A method
    whose kernel was not chosen (or has no specialised form: jacobian_dot) gets the chain's
    kernel of it (AChain._kernel), fed by the law kernels, as on the chain's generic fast path."""
    import ctypes

    from . import kernels as _kernels
    from .derivatives import kernels_of

    if not _kernels.c_available():
        _warn_once(
            "native",
            "apair: AChain.specialise() needs the compiled C kernels (apair._native); the "
            "chain uses the generic kernels",
        )
        return None
    built = build(chain, kernels)
    if built is None:
        return None
    library, name, names = built
    lib = ctypes.CDLL(str(library))
    count = ctypes.c_int.in_dll(lib, f"{name}_registry_count").value
    if count != len(names):
        raise RuntimeError(f"specialise: {library} holds {count} kernels, expected {len(names)}: remove it")
    base = ctypes.addressof(ctypes.c_char.in_dll(lib, f"{name}_registry"))
    families = {f: k for k, f in _toolkit()[0].KERNELS.items()}
    kernel = lambda family: families[family] if families.get(family) in names else chain._kernel(family)
    fast = _kernels.native_chain(
        chain.n,
        [(tuple(kernel(f) for f in kernels_of(family)), strict) for family, strict in methods],
        [p.law_kernel for p in chain.pairs],
        [p.theta_limit if p.theta_limit is not None else float("inf") for p in chain.pairs],
        dict(zip(("dh", "turning", "links", "legs", "gravity"), chain._body)),
        keep=lib,
        table=(base, names),
    )
    return fast
