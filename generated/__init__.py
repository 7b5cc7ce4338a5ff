"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 0c8beb2c00656460
"""
