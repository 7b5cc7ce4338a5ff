"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 6ac8f192f0430abc
"""
