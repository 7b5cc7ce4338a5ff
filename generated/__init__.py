"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: b0f854044ab46d58
"""
