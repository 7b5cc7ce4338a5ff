"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 710a31d516dd1dca
"""
