"""Builds the Python binding of the generated C kernels: the extension module apair._native.

It compiles generated/c (the kernels and their registry) with src/apair/_native*.c, which call
any registered kernel on NumPy arrays. A failed build (no C compiler, most often) stops the
install with a message that says what to do, at install time rather than at the first call:
install gcc, or set APAIR_NO_C=1 to install without the binding (the runtime then uses the
generated NumPy kernels and says so once).

Flags: ISO C (-std=c11, so no floating-point contraction: the results match the NumPy kernels'
rounding) and -fno-math-errno (libm need not set errno, which lets the compiler fuse sin and cos
of one angle into sincos; results are unchanged).
"""

import hashlib
import os
from concurrent.futures import ThreadPoolExecutor
from glob import glob
from pathlib import Path

import numpy
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

C_FILES = sorted(glob("generated/c/*.c") + glob("generated/c/*.h"))
# the binding: the module and the kernel registry's calls, Chain, ClosedIK, the IK marshaller; their private header
NATIVE_SOURCES = [
    "src/apair/_native.c",
    "src/apair/_native_chain.c",
    "src/apair/_native_closed.c",
    "src/apair/_native_ik.c",
]
NATIVE_HEADERS = ["src/apair/_native.h"]


def sources_hash(paths) -> str:
    """SHA-256 of the C files compiled here, as codegen.emitter.sources_hash computes it for the
    manifest (file name, NUL, text, NUL, in name order): the runtime compares the two."""
    h = hashlib.sha256()
    for p in sorted(paths, key=lambda p: Path(p).name):
        h.update(Path(p).name.encode() + b"\0" + Path(p).read_bytes() + b"\0")
    return h.hexdigest()


class BuildExt(build_ext):
    """build_ext that says at install time why the C kernels are missing, or skips them on request."""

    def build_extensions(self):
        """Compile the sources on every core (one file per kernel); setuptools compiles the sources
        of one extension one after the other."""
        cc = self.compiler
        if all(hasattr(cc, f) for f in ("_setup_compile", "_get_cc_args", "_compile")):

            def compile_parallel(
                sources,
                output_dir=None,
                macros=None,
                include_dirs=None,
                debug=0,
                extra_preargs=None,
                extra_postargs=None,
                depends=None,
            ):
                macros, objects, extra, pp_opts, build = cc._setup_compile(
                    output_dir, macros, include_dirs, sources, depends, extra_postargs
                )
                cc_args = cc._get_cc_args(pp_opts, debug, extra_preargs)
                todo = [obj for obj in objects if obj in build]
                with ThreadPoolExecutor(os.cpu_count() or 1) as pool:
                    list(pool.map(lambda obj: cc._compile(obj, *build[obj], cc_args, extra, pp_opts), todo))
                return objects

            cc.compile = compile_parallel
        super().build_extensions()

    def run(self):
        if os.environ.get("APAIR_NO_C"):
            print(
                "apair: APAIR_NO_C is set, installing without the compiled C kernels (the NumPy kernels will be used)"
            )
            self.extensions = []
            return
        try:
            super().run()
        except Exception as exc:  # setuptools' CompileError, a missing compiler's OSError, ...
            raise SystemExit(
                f"apair: the C kernels could not be compiled ({type(exc).__name__}: {exc}). Install a C "
                "compiler (e.g. apt install gcc) and retry, or set APAIR_NO_C=1 to install without them "
                "(the runtime then uses the slower NumPy kernels)."
            ) from None


setup(
    cmdclass={"build_ext": BuildExt},
    ext_modules=[
        Extension(
            "apair._native",
            sources=sorted(glob("generated/c/*.c")) + NATIVE_SOURCES,
            depends=sorted(glob("generated/c/*.h")) + NATIVE_HEADERS,  # rebuild when a header (or the hash) changes
            include_dirs=["generated/c", numpy.get_include()],
            extra_compile_args=["-std=c11", "-O2", "-fno-math-errno"],
            libraries=["m"],
            define_macros=[("APAIR_SOURCES_HASH", f'"{sources_hash(C_FILES)}"')],
        )
    ],
)
