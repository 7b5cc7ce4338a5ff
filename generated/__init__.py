"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: fbf32b51be239942
"""
