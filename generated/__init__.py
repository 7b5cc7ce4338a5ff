"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: f53197dd22b7e472
"""
