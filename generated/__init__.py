"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 8118403fc1af3232
"""
