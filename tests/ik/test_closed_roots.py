"""The closed forms' real roots (closed_real_roots in src/csrc/apair_ik_closed.h, and its NumPy twin
apair.ik.closed.real_roots) on polynomials with the roots poses give: two real roots close together
but distinct (the critical point between them is no root, though the polynomial nearly vanishes
there: on a PUMA's pose such a point verified on fk to 3e-11, a spurious solution), a double root
(its critical point is the candidate), a double root split by rounding, and simple roots, at
degrees 2, 4, 8 and 12. Every true root has a candidate near it, and no candidate lies away from
every true root."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from apair.ik.closed import real_roots

ROOT = Path(__file__).resolve().parents[2]
CDIR = ROOT / "generated" / "c"

# real roots (the polynomial's; a repeated value is a double root) and complex pairs (re, im)
CASES = {
    "quadratic, two roots 2e-5 apart": ([0.7, 0.70002], []),
    "quartic, two roots 2e-5 apart": ([1.0, 1.00002, -3.0, 5.0], []),
    "quartic, two roots 2e-5 apart, a complex pair": ([-0.4, -0.39998], [(2.0, 1.5)]),
    "quartic, a double root": ([1.0, 1.0, -3.0, 5.0], []),
    "quartic, a double root split by rounding": ([1.0, 1.0 + 1e-9, -3.0, 5.0], []),
    "degree 8, two roots 3e-5 apart": ([0.2, 0.20003, -0.7, 1.3, 2.5, -4.0], [(0.5, 0.8)]),
    "degree 8, a double root": ([0.2, 0.2, -0.7, 1.3], [(0.5, 0.8), (-1.0, 0.3)]),
    "degree 12, simple roots": ([-2.5, -1.2, -0.3, 0.4, 0.9, 1.6, 3.1, 4.4], [(0.1, 1.0), (-0.6, 0.2)]),
    "degree 12, two roots 2e-5 apart": ([-1.2, -0.3, 0.4, 0.40002, 1.6, 3.1], [(0.1, 1.0), (-0.6, 0.2), (2.0, 2.0)]),
}


def coefficients(real, pairs) -> np.ndarray:
    """Σ c_k t^k (lowest degree first) with these roots, scaled to a largest coefficient of 1."""
    pairs = [complex(r, i) for r, i in pairs]
    c = np.real(np.poly(np.concatenate([np.asarray(real, complex), pairs, np.conj(pairs)])))[::-1]
    return c / np.abs(c).max()


def check(name: str, real, candidates) -> None:
    truth = np.unique(np.asarray(real, float))
    cand = np.asarray(candidates, float)
    for r in truth:
        assert np.min(np.abs(cand - r)) <= 1e-6 * (1 + abs(r)), (name, r, cand)
    for x in cand:
        assert np.min(np.abs(truth - x)) <= 1e-6 * (1 + abs(x)), (name, "spurious", x, truth)


@pytest.mark.parametrize("name", list(CASES))
def test_numpy_twin(name):
    real, pairs = CASES[name]
    roots, at_infinity = real_roots(coefficients(real, pairs), 1.0)
    assert not at_infinity
    check(name, real, roots)


def program() -> str:
    lines = ["#include <stdio.h>", '#include "apair_ik_closed.h"', "int main(void)", "{"]
    lines.append("    double roots[CLOSED_ROOTS];")
    for k, (real, pairs) in enumerate(CASES.values()):
        c = coefficients(real, pairs)
        lines.append(f"    static const double c{k}[] = {{{', '.join(repr(float(x)) for x in c)}}};")
        lines.append(f"    int n{k} = closed_real_roots({len(c) - 1}, c{k}, roots);")
        lines.append(f'    for (int j = 0; j < n{k}; j++) printf("%.17g ", roots[j]);')
        lines.append('    printf("\\n");')
    lines += ["    (void)closed_solve6;", "    return 0;", "}"]
    return "\n".join(lines) + "\n"


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is required")
def test_c_twin(tmp_path):
    src = tmp_path / "roots.c"
    src.write_text(program())
    exe = tmp_path / "roots"
    flags = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", f"-I{CDIR}"]
    subprocess.run(["gcc", *flags, str(src), "-o", str(exe), "-lm"], check=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout.split("\n")
    for (name, (real, _pairs)), line in zip(CASES.items(), out):
        check(name, real, [float(x) for x in line.split()])
