"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: a19cd4b352ab5a1c
"""
