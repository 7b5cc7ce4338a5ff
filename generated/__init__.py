"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: b2dc4f0a25274b9d
"""
