"""Builds the Python binding of the generated C kernels: the extension module apair._native.

It compiles generated/c (the kernels and their registry) with src/apair/_native.c, which calls
any registered kernel on NumPy arrays. The extension is optional: without a C compiler the install
still succeeds and the runtime falls back to the generated NumPy kernels (and says so).

Flags: ISO C (-std=c11, so no floating-point contraction: the results match the NumPy kernels'
rounding) and -fno-math-errno (libm need not set errno, which lets the compiler fuse sin and cos
of one angle into sincos; results are unchanged).
"""
from glob import glob

import numpy
from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "apair._native",
            sources=sorted(glob("generated/c/*.c")) + ["src/apair/_native.c"],
            depends=sorted(glob("generated/c/*.h")),  # rebuild when the header (and its hash) changes
            include_dirs=["generated/c", numpy.get_include()],
            extra_compile_args=["-std=c11", "-O2", "-fno-math-errno"],
            libraries=["m"],
            optional=True,
        )
    ]
)
