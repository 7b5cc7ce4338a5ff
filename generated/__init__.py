"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 9e7215679404dceb
"""
