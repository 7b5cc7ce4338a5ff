"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 9531a14ec32d3534
"""
