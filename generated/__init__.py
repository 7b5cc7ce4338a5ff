"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: e6d7866099b3212f
"""
