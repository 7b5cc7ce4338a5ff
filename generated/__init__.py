"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: ca60a5ea4e272431
"""
