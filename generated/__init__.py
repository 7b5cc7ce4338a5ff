"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: ed7cba9e46ff1468
"""
