"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 56ab015abc5774c7
"""
