"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: c640f436824a301d
"""
