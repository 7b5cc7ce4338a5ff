"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 8807fcd79a4d6cd6
"""
