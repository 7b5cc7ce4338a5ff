"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 89e0954d8ba60280
"""
