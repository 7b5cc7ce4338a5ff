"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: a9e0c1ccc788bfcc
"""
