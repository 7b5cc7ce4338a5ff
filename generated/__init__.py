"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 45992f3230f49ece
"""
