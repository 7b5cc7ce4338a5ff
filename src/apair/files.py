"""The files apair writes, and where.

Pictures, models and pages go where the caller says, by one set of rules (`target`, `write`,
`write_text`): a suffix is added where the name has none, a folder is refused, and an existing
file is replaced only with overwrite=True (never written through a symlink; the refusal is a
`Refusal`, which a command line words with its own option). What apair computes
once and keeps (compiled specialised chains, inverse-kinematics start systems) goes into the cache
(`cache_root`), keyed by content hashes that include the toolkit that made it (`toolkit_digest`).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
from collections.abc import Callable
from functools import cache
from importlib import resources
from pathlib import Path

from ._validate import flag, shorten
from ._version import __version__


class Refusal(ValueError):
    """A refusal that an argument of the call lifts (overwrite=True replaces an existing file): the
    message tells the caller of the API to pass it; a command line names its own option instead
    (`told`), so that neither speaks the other's language."""

    def __init__(self, reason: str, argument: str, effect: str) -> None:
        self.reason, self.argument, self.effect = reason, argument, effect
        super().__init__(f"{reason}; pass {argument}=True {effect}")

    def told(self, option: str) -> str:
        """The message for a command line whose `option` lifts the refusal."""
        return f"{self.reason}; use {option} {self.effect}"

    def __reduce__(self) -> tuple[type[Refusal], tuple[str, str, str]]:
        return type(self), (self.reason, self.argument, self.effect)  # picklable (its own arguments)


_KINDS = {".png": "a PNG picture", ".gif": "a GIF animation", ".xml": "an XML model", ".html": "an HTML page"}


def target(path: str | os.PathLike[str], overwrite: bool, suffix: str = ".png") -> Path:
    """The file an output goes to, checked before any work, by one rule for every command: the
    name as given must not be empty, a folder or anything but a regular file (a device such as
    /dev/null included); `suffix` is added when the name has none (so the file checked is the file
    written); an existing file or any symlink (dangling ones too) is refused unless overwrite=True."""
    overwrite = flag("overwrite", overwrite)
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"path: expected a file name, got {shorten(repr(path))}")
    given = os.fspath(path)
    if not isinstance(given, str) or given.strip() == "":
        raise ValueError(f"path: expected a file name, got {shorten(repr(given))}")
    p = Path(given)
    if p.is_dir() or given.endswith(("/", os.sep)) or p.name in ("", ".", ".."):
        raise ValueError(f"path: {given!r} is a folder; give a file name in it")
    if p.exists() and not p.is_file():
        raise ValueError(f"path: {given!r} is not a regular file")
    if p.suffix == "":
        p = p.with_suffix(suffix)
    if p.suffix.lower() != suffix:
        kind = _KINDS.get(suffix, f"a {suffix[1:].upper()} file")
        raise ValueError(f"path: {str(p)!r} must end in {suffix} (the output is {kind})")
    if p.is_dir():
        raise ValueError(f"path: {str(p)!r} is a folder")
    if p.exists() and not p.is_file() and not p.is_symlink():
        raise ValueError(f"path: {str(p)!r} is not a regular file")
    if (p.exists() or p.is_symlink()) and not overwrite:
        raise Refusal(f"path: {str(p)!r} exists", "overwrite", "to replace it")
    if not p.parent.is_dir():
        raise ValueError(f"path: folder {str(p.parent)!r} does not exist")
    return p


def write_text(path: str | os.PathLike[str], text: str, overwrite: bool, suffix: str) -> Path:
    """Text (a MuJoCo model, a viewer page) to path by the rules of the pictures: `suffix` added
    where the name has none; an existing file only with overwrite=True."""
    p = target(path, overwrite, suffix)

    def save(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)

    return write(p, overwrite, save)


def write(p: Path, overwrite: bool, save: Callable[[str], object]) -> Path:
    """save(tmp) writes the picture to a new file beside p, which then becomes p: copied into a
    file created exclusively (what appeared in between is never replaced), or, with overwrite,
    renamed over p (a symlink is replaced itself; what it pointed to is never written)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.stem}-", suffix=p.suffix, dir=p.parent)
    except OSError as exc:
        raise ValueError(f"path: cannot write in folder {str(p.parent)!r} ({exc.strerror})") from None
    os.close(fd)
    try:
        save(tmp)
        os.chmod(tmp, 0o644)
        if overwrite:
            os.replace(tmp, p)
        else:
            try:
                out = open(p, "xb")  # exclusive: never replaces what is there
            except FileExistsError:
                raise ValueError(f"path: {str(p)!r} appeared while the output was made; not replaced") from None
            with out, open(tmp, "rb") as src:
                shutil.copyfileobj(src, out)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return p


def cache_root() -> Path:
    """Where compiled specialised chains and inverse-kinematics start systems are kept:
    $APAIR_CACHE, else $XDG_CACHE_HOME/apair, else ~/.cache/apair."""
    if os.environ.get("APAIR_CACHE"):
        return Path(os.environ["APAIR_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "apair"


@cache
def toolkit_digest() -> str:
    """SHA-256 of what turns a design into code: the derivations, the code generator with its
    templates, apair's and sympy's versions (sympy's printing and evaluation shape the output)."""
    import sympy

    h = hashlib.sha256(f"apair {__version__} sympy {sympy.__version__}\0".encode())
    for package in ("derivations", "codegen"):
        root = Path(str(resources.files(f"apair.{package}")))
        for path in sorted(root.rglob("*")):
            if path.is_file() and path.suffix in (".py", ".j2", ".c", ".h") and "__pycache__" not in path.parts:
                h.update(f"{package}/{path.relative_to(root).as_posix()}\0".encode() + path.read_bytes() + b"\0")
    return h.hexdigest()
