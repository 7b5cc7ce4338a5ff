"""Writing generated files into a folder that may hold a user's own files: nothing of theirs is lost.

The generator owns exactly the files its last run recorded in the folder's manifest.json, each with
the SHA-256 of what it wrote. Everything else in the folder belongs to the user:

- a file that is not ours is never replaced (OutputError naming it) unless `force` is given;
- a symbolic link is never followed: a file is written as a temporary file in its folder and
  renamed over the path, so a link is replaced by a file, never written through; a folder on the
  way that is a link is refused;
- the manifest is untrusted input: only plain relative names inside the folder count, and a stale
  file of an earlier run is removed only while its content still has the recorded hash (a file
  the user edited since is kept, and said so);
- one run at a time: an advisory lock (flock) on the folder, so that two runs into one folder
  take turns instead of deleting each other's files; every file is written atomically.
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import json
import os
import tempfile
import time
from pathlib import Path, PurePosixPath

MANIFEST = "manifest.json"
LOCK_WAIT = 120.0  # seconds a second run waits for the first before it gives up


class OutputError(Exception):
    """The output folder, or a file in it, is not one the generator may write."""


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def plain_name(rel: object) -> str | None:
    """`rel` as a relative POSIX path of plain components inside the folder, or None (absolute
    paths, '..', '.', empty components, backslashes and NUL are not plain)."""
    if not isinstance(rel, str) or not rel or "\\" in rel or "\0" in rel:
        return None
    path = PurePosixPath(rel)
    if path.is_absolute() or any(part in ("", ".", "..") for part in rel.split("/")):
        return None
    return path.as_posix()


def owned_files(out: Path) -> dict[str, str | None] | None:
    """The files an earlier run recorded in `out`'s manifest, {name: sha256 or None when the
    manifest has no hash for it}, or None when `out` holds no manifest of ours. Entries that are
    not plain names inside `out` are dropped."""
    path = out / MANIFEST
    if path.is_symlink() or not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    if not isinstance(data, dict) or "kernels" not in data or "content_hash" not in data:
        return None
    files = data.get("files", {})
    if isinstance(files, list):  # a manifest of an earlier version: names without hashes
        files = {name: None for name in files}
    if not isinstance(files, dict):
        return {}
    owned: dict[str, str | None] = {}
    for name, sha in files.items():
        plain = plain_name(name)
        if plain is not None and plain != MANIFEST:
            owned[plain] = sha if isinstance(sha, str) else None
    return owned


def _inside(out: Path, rel: str) -> Path:
    """out/rel, refusing a folder on the way that is a symbolic link (it would lead outside)."""
    path = out
    for part in PurePosixPath(rel).parts[:-1]:
        path = path / part
        if path.is_symlink():
            raise OutputError(f"--out: {path} is a symbolic link: the generator does not write through links")
        if path.exists() and not path.is_dir():
            raise OutputError(f"--out: {path} is not a folder")
    return out / rel


def _atomic_write(path: Path, data: bytes) -> None:
    """Write `data` to a temporary file beside `path` and rename it over `path` (a link there is
    replaced, never followed; a reader never sees half a file)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _same(path: Path, data: bytes) -> bool:
    if path.is_symlink() or not path.is_file():
        return False
    try:
        return path.read_bytes() == data
    except OSError:
        return False


class _Lock:
    """An exclusive advisory lock on the folder itself (no lock file is left behind)."""

    def __init__(self, out: Path, wait: float):
        self.out, self.wait, self.fd = out, wait, -1

    def __enter__(self) -> _Lock:
        self.fd = os.open(self.out, os.O_RDONLY | os.O_DIRECTORY)
        deadline = time.monotonic() + self.wait
        while True:
            try:
                fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return self
            except OSError as exc:
                if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise
                if time.monotonic() > deadline:
                    os.close(self.fd)
                    raise OutputError(
                        f"--out: {self.out} is being written by another run (waited {self.wait:.0f} s for its lock)"
                    ) from None
                time.sleep(0.05)

    def __exit__(self, *exc) -> None:
        os.close(self.fd)  # closing releases the lock


def write(
    files: dict[str, str], out: Path, clean: bool = True, force: bool = False, wait: float = LOCK_WAIT
) -> list[str]:
    """Write `files` ({relative name: text}) under `out`. Where they include MANIFEST, the files
    are recorded in it with their hashes (key "files"), the manifest written last; without it
    (files added to a folder whose manifest another run keeps) the manifest is left alone. With
    `clean`, remove the files the previous manifest recorded that are no longer produced and
    still hold what was written. A non-empty
    `out` without a manifest of ours, or a file in it that is not ours, is refused unless `force`.
    Returns the changes, one line each (notes of kept files start with 'kept')."""
    out = Path(out)
    if out.is_symlink() and not out.is_dir():
        raise OutputError(f"--out: {out} is a symbolic link to something that is not a folder")
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out: {out} is not a folder")
    payload = {}
    for rel, text in files.items():
        plain = plain_name(rel)
        if plain is None:
            raise ValueError(f"files: {rel!r} is not a plain relative name")
        payload[plain] = text.encode()
    out.mkdir(parents=True, exist_ok=True)
    with _Lock(out, wait):
        return _write_locked(payload, out, clean, force)


def _write_locked(payload: dict[str, bytes], out: Path, clean: bool, force: bool) -> list[str]:
    previous = owned_files(out)
    if previous is None and not force and any(out.iterdir()):
        raise OutputError(
            f"--out: {out} is not empty and was not written by codegen (no manifest.json of "
            "ours): give an empty or new folder, or --force"
        )
    previous = previous or {}
    manifest_text = payload.pop(MANIFEST, None)
    # Refuse before writing anything: every file to write is ours, new, or identical already.
    for rel, data in sorted(payload.items()):
        path = _inside(out, rel)
        if force or rel in previous or not (path.exists() or path.is_symlink()) or _same(path, data):
            continue
        kind = "a symbolic link" if path.is_symlink() else "a file"
        raise OutputError(
            f"--out: {path} is {kind} that an earlier run did not write: move it away, or --force to replace it"
        )
    changed = []
    for rel, data in sorted(payload.items()):
        path = _inside(out, rel)
        if not _same(path, data):
            _atomic_write(path, data)
            changed.append(rel)
    if clean:
        for rel in sorted(set(previous) - set(payload)):
            path = _inside(out, rel)
            if path.is_symlink() or not path.is_file():
                continue
            sha = previous[rel]
            if sha is None or digest(path.read_bytes()) != sha:
                changed.append(f"kept {rel}: no longer generated, but changed since it was written")
                continue
            path.unlink()
            changed.append(f"removed {rel}")
    if manifest_text is not None:  # written last: a run cut short leaves the previous record
        manifest = json.loads(manifest_text)
        manifest["files"] = {rel: digest(data) for rel, data in sorted(payload.items())}
        text = json.dumps(manifest, indent=1, sort_keys=True).encode() + b"\n"
        if not _same(out / MANIFEST, text):
            _atomic_write(out / MANIFEST, text)
            changed.append(MANIFEST)
    return changed
