"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 3ddd53ef58df1483
"""
