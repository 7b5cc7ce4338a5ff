"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 951d2452e461a5eb
"""
