"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: d51cc9c33c7b2c11
"""
