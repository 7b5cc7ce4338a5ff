"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: ba0d3c61deb5abbd
"""
