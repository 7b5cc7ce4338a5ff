"""The eigenvalues of a square matrix polynomial M(τ) = Σ_p τ^p M_p whose determinant carries a
factor (1 + τ²)^m (the isotropic points of a half-angle chart): the factor is divided out of its
columns before the linearisation, so the eigenproblem is 2m smaller.

Where M(±i) has a real null vector v, the column combination M(τ)·v vanishes at ±i and is
divisible by 1 + τ²: it replaces the column of highest degree in v's support, divided once (the
column degrees' sum drops by 2, and det M loses one factor). Repeated until M(±i) (of the current
columns) has no real null vector, this gives M(τ)·N(τ)·diag((1 + τ²)^−e) with column degrees δ,
N a polynomial matrix. Where the operations depend on the design only (as for the elimination of
apair.ik1a5r), they are found once and kept as one linear map of M's coefficients; every use
checks that the divisions are still exact. The result is linearised by column degrees (Kailath's
column companion form): Σ δ states, its leading column coefficients inverted.
"""
from __future__ import annotations

import numpy as np
from numpy.polynomial import polynomial as poly
from scipy.linalg import lapack

NULL_TOL = 1e-9  # singular values of M(±i) under this fraction of the largest span its null space
EXACT = 1e-8  # the largest remainder of a division, relative to M, that still counts as exact
_ONE_PLUS = np.array([1.0, 0.0, 1.0])  # 1 + τ²


def _real_null(A: np.ndarray) -> np.ndarray:
    """A real basis (n, r) of the real vectors v with A v = 0 (A complex, m × n)."""
    B = np.vstack([A.real, A.imag])
    _, s, Vt = np.linalg.svd(B)
    rank = int(np.count_nonzero(s > NULL_TOL * s[0])) if s.size and s[0] > 0 else 0
    return Vt[rank:].T


class Linearisation:
    """The column operations and degrees for one kind of M(τ) (degree D, n × n): `columns` are,
    per final column, (N_c (deg + 1, n) coefficients of τ^j, e_c): column c is M·N_c/(1 + τ²)^e_c."""

    def __init__(self, degree: int, n: int, columns: list[tuple[np.ndarray, int]]):
        self.degree, self.n = degree, n
        divided = any(e for _, e in columns)
        # G maps a row of M (coefficients (D + 1) × n, row-major) to the row's final columns'
        # coefficients (Σ (δ_c + 1)); R to the divisions' remainders
        blocks, rems, deg = [], [], []
        for N, e in columns:
            div = poly.polypow(_ONE_PLUS, e) if e else np.array([1.0])
            quo, rem = [], []
            for p in range(degree + 1):
                for j in range(n):
                    num = np.convolve(np.eye(degree + 1)[p], N[:, j])
                    q, r = poly.polydiv(np.pad(num, (0, max(0, len(div) - len(num)))), div)
                    quo.append(q)
                    rem.append(np.pad(r, (0, max(0, len(div) - 1 - len(r))))[:max(len(div) - 1, 1)])
            width = max(len(q) for q in quo)
            # the final degree: the highest power with a coefficient in the map
            Q = np.array([np.pad(q, (0, width - len(q))) for q in quo])
            nz = np.flatnonzero(np.abs(Q).max(axis=0) > 0)
            d = int(nz[-1]) if len(nz) else 0
            blocks.append(Q[:, :d + 1])
            rems.append(np.array(rem))
            deg.append(d)
        self.degrees = np.array(deg)
        self.G = np.concatenate(blocks, axis=1)
        self.size = int(self.degrees.sum())
        self.R = np.concatenate(rems, axis=1) if divided else None
        off = np.concatenate([[0], np.cumsum(self.degrees + 1)])
        self._top = off[1:] - 1  # each column's leading coefficient in G's output
        self._low = np.concatenate([np.arange(off[c], off[c + 1] - 1) for c in range(n)])
        state = np.concatenate([[0], np.cumsum(self.degrees)])
        self._rows = state[1:] - 1  # the state rows the leading coefficients solve for
        shift = np.concatenate([np.arange(state[c], state[c + 1] - 1) for c in range(n)])
        self._shift = (shift, shift + 1)

    @property
    def removed(self) -> int:
        """The factors (1 + τ²) divided out of the determinant."""
        return (self.degree * self.n - self.size) // 2

    @staticmethod
    def plain(degree: int, n: int) -> "Linearisation":
        """No columns divided: the block companion form ((degree · n) states)."""
        return Linearisation(degree, n, [(np.eye(n)[None, c], 0) for c in range(n)])

    @staticmethod
    def of(M: np.ndarray, limit: int) -> "Linearisation":
        """The operations found on M (D + 1, n, n), at most `limit` divisions."""
        D, n = M.shape[0] - 1, M.shape[1]
        cols = [M[:, :, c].copy() for c in range(n)]  # the current columns' coefficients (deg + 1, n)
        ops = [(np.eye(n)[None, c], 0) for c in range(n)]
        ipow = 1j ** np.arange(2 * D + 2)
        for _ in range(limit):
            Mi = np.stack([ipow[:len(c)] @ c for c in cols], axis=1)
            W = _real_null(Mi)
            if W.shape[1] == 0:
                break
            v = W[:, 0]
            degs = np.array([len(c) - 1 for c in cols])
            support = np.flatnonzero(np.abs(v) > NULL_TOL * np.abs(v).max())
            pivot = support[np.argmax(degs[support])]
            width = max(len(cols[c]) for c in support)
            comb = sum(v[c] * np.pad(cols[c], ((0, width - len(cols[c])), (0, 0))) for c in support)
            quo, rem = _divide(comb)
            if np.abs(rem).max() > EXACT * np.abs(comb).max():
                break
            E = max(ops[c][1] for c in support)
            width = max(len(ops[c][0]) + 2 * (E - ops[c][1]) for c in support)
            N = np.zeros((width, n))
            for c in support:
                Nc = ops[c][0]
                for _ in range(E - ops[c][1]):
                    Nc = np.array([np.convolve(_ONE_PLUS, Nc[:, j]) for j in range(n)]).T
                N[:len(Nc)] += v[c] * Nc
            cols[pivot], ops[pivot] = quo, (N, E + 1)
        return Linearisation(D, n, ops)

    def companion(self, M: np.ndarray) -> np.ndarray | None:
        """The real companion matrix (size, size) of M (D + 1, n, n) after the column operations,
        or None where a division is not exact for this M or the leading column coefficients are
        singular."""
        rows = M.transpose(1, 0, 2).reshape(self.n, -1)  # row r: (p, j) row-major
        if self.R is not None and np.abs(rows @ self.R).max() > EXACT * np.abs(rows).max():
            return None
        F = rows @ self.G
        _, _, A, info = lapack.dgesv(F[:, self._top], F[:, self._low])
        if info or not np.isfinite(A).all():
            return None
        K = np.zeros((self.size, self.size))
        K[self._shift] = 1.0
        K[self._rows] = -A
        return K


def _divide(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quotient and remainder of the polynomial vector c (deg + 1, n) by 1 + τ²."""
    c = c.copy()
    d = len(c) - 1
    if d < 2:
        return np.zeros((1, c.shape[1])), c
    q = np.zeros((d - 1, c.shape[1]))
    for j in range(d, 1, -1):
        q[j - 2] = c[j]
        c[j - 2] -= c[j]
    return q, c[:2]
