"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 79a0155b9108e372
"""
