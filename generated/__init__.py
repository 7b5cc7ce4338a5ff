"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: d015a4275e9a1fb8
"""
