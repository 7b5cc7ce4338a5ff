"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 3bdfd61232df863f
"""
