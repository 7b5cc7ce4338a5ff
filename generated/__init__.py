"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 4cd7e5652fe13d9b
"""
