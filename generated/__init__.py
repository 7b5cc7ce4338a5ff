"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 7b6f674dd6753490
"""
