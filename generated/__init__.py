"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: fe33eaad017dd2c7
"""
