"""Builds the Python binding of the generated C kernels: the extension module apair._native.

It compiles generated/c (the kernels and their registry) with src/apair/_native.c, which calls
any registered kernel on NumPy arrays. The extension is optional: without a C compiler the install
still succeeds and the runtime falls back to the generated NumPy kernels (and says so).

Flags: ISO C (-std=c11, so no floating-point contraction: the results match the NumPy kernels'
rounding) and -fno-math-errno (libm need not set errno, which lets the compiler fuse sin and cos
of one angle into sincos; results are unchanged).
"""
import hashlib
from glob import glob
from pathlib import Path

import numpy
from setuptools import Extension, setup

C_FILES = sorted(glob("generated/c/*.c") + glob("generated/c/*.h"))


def sources_hash(paths) -> str:
    """SHA-256 of the C files compiled here, as codegen.emitter.sources_hash computes it for the
    manifest (file name, NUL, text, NUL, in name order): the runtime compares the two."""
    h = hashlib.sha256()
    for p in sorted(paths, key=lambda p: Path(p).name):
        h.update(Path(p).name.encode() + b"\0" + Path(p).read_bytes() + b"\0")
    return h.hexdigest()


setup(
    ext_modules=[
        Extension(
            "apair._native",
            sources=sorted(glob("generated/c/*.c")) + ["src/apair/_native.c"],
            depends=sorted(glob("generated/c/*.h")),  # rebuild when the header (and its hash) changes
            include_dirs=["generated/c", numpy.get_include()],
            extra_compile_args=["-std=c11", "-O2", "-fno-math-errno"],
            libraries=["m"],
            define_macros=[("APAIR_SOURCES_HASH", f'"{sources_hash(C_FILES)}"')],
            optional=True,
        )
    ]
)
