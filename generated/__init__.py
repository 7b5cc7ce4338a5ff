"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: ad35696682d1dab4
"""
