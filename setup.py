"""Builds the generated C kernels into a shared library that the runtime loads with ctypes.

It is declared as an optional extension module so that setuptools compiles it with the platform's
compiler; it has no Python entry point. Without a C compiler the install still succeeds and the
runtime falls back to the generated NumPy kernels (and says so).
"""
from glob import glob

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "apair._libapair",
            sources=sorted(glob("generated/c/*.c")),
            include_dirs=["generated/c"],
            extra_compile_args=["-std=c99", "-O2"],
            libraries=["m"],
            optional=True,
        )
    ]
)
