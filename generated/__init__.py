"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: c382efabdcacc3a9
"""
