"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: bb17d567f9e11922
"""
