"""Kernels and polynomials derived by derivations/, emitted by codegen/. Do not edit.

Content hash: 8536d35009d48de7
"""
