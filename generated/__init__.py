"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: d088880e31b4c953
"""
