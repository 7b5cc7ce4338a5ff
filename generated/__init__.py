"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 304d74b27e3136ee
"""
