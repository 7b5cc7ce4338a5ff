"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 32c401558f5349ec
"""
