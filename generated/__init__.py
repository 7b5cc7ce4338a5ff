"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 6070616e24c047f7
"""
