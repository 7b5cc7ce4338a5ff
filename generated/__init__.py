"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: fbb0f6529330ba95
"""
