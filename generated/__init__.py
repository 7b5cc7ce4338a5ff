"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 98ccb36936ce00d4
"""
