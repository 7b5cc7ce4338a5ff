"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 48663cdb47501530
"""
