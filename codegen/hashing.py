"""The digests stamped into generated files."""

from __future__ import annotations

import hashlib


def content_hash(parts: list[str]) -> str:
    """The 16-hex-digit SHA-256 of the parts (NUL-separated) that a generated file is made from."""
    h = hashlib.sha256()
    for p in parts:
        h.update(p.encode())
        h.update(b"\0")
    return h.hexdigest()[:16]


def sources_hash(texts: dict[str, str]) -> str:
    """SHA-256 of the C files the binding compiles ({file name: text}, in name order). setup.py
    computes the same digest of the files it actually compiles and builds it into apair._native,
    so the runtime notices a build from other sources than the manifest's (even a hand edit)."""
    h = hashlib.sha256()
    for name in sorted(texts):
        h.update(name.encode() + b"\0" + texts[name].encode() + b"\0")
    return h.hexdigest()
