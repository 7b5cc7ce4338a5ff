"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: f3af65019d7558fb
"""
