"""One backend per target, each with its expression printer (printer.py), its list of files and
their template context computed in Python (backend.py), and its templates (templates/):

    c/            the C99 library in generated/c (public header, registry, one source per kernel,
                  the hand-written solvers copied from src/csrc, CMake and pkg-config files)
    numpy/        the NumPy kernels in generated/numpy
    js/           the browser viewer's kernels in generated/js
    polynomials/  the derived polynomial sets in generated/polynomials (text, LaTeX, JSON)
    chain/        the code of one chain with its design built in (`apair codegen`)

codegen/render.py asks the first four for the files of generated/; printing.py holds what the
printers share.
"""
