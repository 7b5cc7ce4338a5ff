"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: e68f5b0f94357c15
"""
