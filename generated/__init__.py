"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 963347a4ac0efa69
"""
