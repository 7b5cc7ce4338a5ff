"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 1b3a3f30a7cbc752
"""
