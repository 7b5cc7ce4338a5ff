"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: ee0d9714e852d8e7
"""
