"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 7fb7fe1823892faf
"""
