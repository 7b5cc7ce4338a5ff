"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: ac70234fc7598465
"""
