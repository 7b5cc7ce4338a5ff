"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: d65977d38fd3b62b
"""
