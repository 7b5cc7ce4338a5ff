"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 67f7a1985ee87d5b
"""
