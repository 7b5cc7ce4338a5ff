"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: d3341f82ae451eb8
"""
