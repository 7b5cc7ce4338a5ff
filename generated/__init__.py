"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: ac1541d91be1e1ad
"""
