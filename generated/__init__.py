"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 85f14830db18faca
"""
