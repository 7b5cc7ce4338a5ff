"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 6ac56c393ad3dbf6
"""
