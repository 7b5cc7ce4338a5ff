"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: e62a36bd01c09138
"""
