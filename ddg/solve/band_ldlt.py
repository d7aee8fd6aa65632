"""LDL^T of a symmetric band matrix without pivoting, its inertia and solves (compiled, numba).

Storage: LAPACK's lower band form, band[d, j] = A[j + d, j] for 0 <= d <= bandwidth, shape
(bandwidth + 1, n), the layout of ddg.solve.banded.SymmetricBanded.band and of
scipy.linalg.cholesky_banded(lower=True).

    A = L D L^T,  L unit lower triangular with the bandwidth of A,  D = diag(d).

Existence. Without pivoting the elimination divides by d_k = det(A_k) / det(A_{k-1}), where A_k
is the leading k x k principal submatrix. The factorisation therefore exists (and is unique)
whenever all leading principal minors det(A_1), ..., det(A_{n-1}) are nonzero (det(A_n) = 0 only
makes the last pivot zero); it keeps the band because no rows are exchanged. It exists for every
positive or negative definite matrix and every diagonally dominant one; a symmetric indefinite
matrix may have a zero (or tiny) leading minor even when it is nonsingular, e.g. [[0, 1], [1, 0]],
and then this factorisation fails where a pivoting LDL^T (Bunch-Kaufman) would not. Without
pivoting there is no bound on the growth of L for indefinite matrices: the error is small when
the pivots are not small compared with the entries they eliminate (check the residual when in
doubt).

Inertia. A = L D L^T is a congruence (L is nonsingular), so by Sylvester's law of inertia A and D
have the same numbers of negative, zero and positive eigenvalues: the signs of the pivots d_k
count the eigenvalues of A below, at and above zero. The number of negative pivots is the number
of unstable directions of an equilibrium whose Hessian is A; zero negative pivots (and no zero)
means A is positive definite, as a successful Cholesky proves.

Small pivots. A pivot with |d_k| <= n * eps * max_j |A_jj| is counted as zero: at that size it is
rounding error, and it contaminates every later pivot through the Schur complement. The
factorisation then reports itself unreliable (`BandLDLT.reliable` is False, `tiny` lists the
columns); `inertia(..., strict=True)` and `BandLDLT.solve` raise UnreliablePivot instead of
returning numbers that may be wrong. A pivot that is exactly zero stops the elimination (no
division by zero): the remaining pivots are NaN and `stopped_at` is that column.

Cost: about n b^2 flops for bandwidth b (as the banded Cholesky), 4 n b per solve. The kernel
works on the transposed band t (n, b + 1), t[j, r] = A[j + r, j], so that each column's rank-1
update runs over contiguous memory; for b >= BLOCKED_FROM it eliminates PANEL columns at a time
and applies their update to the band on their right as dense matrix products (np.dot, BLAS),
gathered from and scattered back to t (the products also fill part of the upper triangle, so
they do more flops than the unblocked loop, most of them in BLAS). The compiled code is cached
next to this module (__pycache__) by numba.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

__all__ = ["BandLDLT", "Inertia", "UnreliablePivot", "band_ldlt", "inertia", "ldlt_solve"]


class UnreliablePivot(np.linalg.LinAlgError):
    """A pivot of the LDL^T is zero to rounding (a leading principal minor is singular, or nearly)."""


class Inertia(NamedTuple):
    negative: int
    zero: int
    positive: int


# Blocking: panels of PANEL columns, factored LEAF columns at a time; the update of the columns
# to the right of a block is one matrix product per CHUNK target columns (np.dot: BLAS dgemm),
# gathered from and scattered back to the band. Below BLOCKED_FROM the plain loop is faster.
PANEL, LEAF, CHUNK, BLOCKED_FROM = 64, 8, 64, 32


@njit(cache=True)
def _columns(t, j0, j1, tol, state):
    """Eliminate columns j0..j1-1 one at a time, updating only the columns before j1 (right-looking,
    rank-1 per column). t[j, r] = A[j + r, j] on entry; on exit, for the eliminated columns,
    t[j, r] = L[j + r, j] (r >= 1) and t[j, 0] = d_j. state = [number of pivots with |d| <= tol,
    first such column, column of an exactly zero (or non-finite) pivot where the elimination
    stopped]; returns False if it stopped (later pivots set to NaN)."""
    n, w = t.shape
    u = w - 1
    for j in range(j0, j1):
        d = t[j, 0]
        if abs(d) <= tol or not np.isfinite(d):
            state[0] += 1
            if state[1] < 0:
                state[1] = j
            if d == 0.0 or not np.isfinite(d):
                for k in range(j + 1, n):
                    t[k, 0] = np.nan
                state[2] = j
                return False
        m = min(u, n - 1 - j)
        inv = 1.0 / d
        # A[j + r, j + c] -= A[j + r, j] A[j + c, j] / d for 1 <= c <= r <= m, c < j1 - j; row j + c
        # of t holds column j + c of the trailing band, contiguous in r - c
        for c in range(1, min(m, j1 - 1 - j) + 1):
            f = t[j, c] * inv
            if f != 0.0:
                row = t[j + c]
                for r in range(c, m + 1):
                    row[r - c] -= f * t[j, r]
        for r in range(1, m + 1):
            t[j, r] *= inv
    return True


@njit(cache=True)
def _update(t, j0, j1, c0, c1, chunk):
    """Subtract L[:, j] d_j L[:, j]^T of the eliminated columns j0..j1-1 from the columns c0..c1-1
    (c0 >= j1), all rows they reach: one dense product per `chunk` target columns."""
    n, w = t.shape
    u = w - 1
    rows = min(n - 1, j1 - 1 + u) - c0 + 1  # rows c0 .. c0 + rows - 1 reached by the sources
    cols = c1 - c0
    if rows <= 0 or cols <= 0:
        return
    jb = j1 - j0
    lt = np.zeros((jb, rows))   # lt[jj, ii] = L[c0 + ii, j0 + jj]
    ld = np.zeros((cols, jb))   # ld[kk, jj] = L[c0 + kk, j0 + jj] d_j
    for jj in range(jb):
        j = j0 + jj
        d = t[j, 0]
        for ii in range(min(rows, j + u - c0 + 1)):
            v = t[j, c0 + ii - j]
            lt[jj, ii] = v
            if ii < cols:
                ld[ii, jj] = v * d
    for k0 in range(0, cols, chunk):
        k1 = min(cols, k0 + chunk)
        s = np.dot(ld[k0:k1], np.ascontiguousarray(lt[:, k0:]))  # s[kk - k0, ii - k0]
        for kk in range(k0, k1):
            row = t[c0 + kk]
            srow = s[kk - k0]
            for ii in range(kk, rows):
                row[ii - kk] -= srow[ii - k0]


@njit(cache=True)
def ldlt_unblocked(t, tol):
    """ldlt_transposed without the blocked path (column by column, whatever the bandwidth): the same
    factors, for callers whose bands are narrow (below BLOCKED_FROM, where ldlt_transposed takes
    this path too) and whose compile should not carry the blocked update's matrix products (the
    rod family's compiled Newton loop, ddg.solve.compiled_newton). Returns as ldlt_transposed."""
    state = np.array([0, -1, -1])
    _columns(t, 0, t.shape[0], tol, state)
    return state[0], state[1], state[2]


@njit(cache=True)
def ldlt_transposed(t, tol, panel, leaf, chunk, blocked_from):
    """In place on t (n, w), t[j, r] = A[j + r, j]: on return t[j, r] = L[j + r, j] for r >= 1 and
    t[j, 0] = d_j. Returns (number of pivots with |d| <= tol, first such column or -1, column of an
    exactly zero pivot where the elimination stopped or -1)."""
    n, w = t.shape
    state = np.array([0, -1, -1])
    if w - 1 < blocked_from:
        _columns(t, 0, n, tol, state)
        return state[0], state[1], state[2]
    for j0 in range(0, n, panel):
        j1 = min(n, j0 + panel)
        for s0 in range(j0, j1, leaf):
            s1 = min(j1, s0 + leaf)
            if not _columns(t, s0, s1, tol, state):
                return state[0], state[1], state[2]
            _update(t, s0, s1, s1, j1, chunk)  # the rest of the panel
        _update(t, j0, j1, j1, min(n, j1 + w - 1), chunk)  # the band to the right of the panel
    return state[0], state[1], state[2]


@njit(cache=True)
def solve_transposed(t, x):
    """x (n, k) overwritten with A^-1 x, A = L D L^T from ldlt_transposed's output t."""
    n, w = t.shape
    u = w - 1
    k = x.shape[1]
    for j in range(n):  # L y = x (unit diagonal)
        m = min(u, n - 1 - j)
        for r in range(1, m + 1):
            lower = t[j, r]
            for c in range(k):
                x[j + r, c] -= lower * x[j, c]
    for j in range(n):  # D z = y
        inv = 1.0 / t[j, 0]
        for c in range(k):
            x[j, c] *= inv
    for j in range(n - 1, -1, -1):  # L^T x = z
        m = min(u, n - 1 - j)
        for r in range(1, m + 1):
            lower = t[j, r]
            for c in range(k):
                x[j, c] -= lower * x[j + r, c]
    return x


@njit(cache=True)
def solve_transposed_1(t, x):
    """x (n,) overwritten with A^-1 x (one right-hand side: the backward dot products with four partial
    sums, so that they do not wait on one another)."""
    n, w = t.shape
    u = w - 1
    for j in range(n):  # L y = x
        m = min(u, n - 1 - j)
        xj = x[j]
        for r in range(1, m + 1):
            x[j + r] -= t[j, r] * xj
    for j in range(n):  # D z = y
        x[j] /= t[j, 0]
    for j in range(n - 1, -1, -1):  # L^T x = z
        m = min(u, n - 1 - j)
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        s3 = 0.0
        r = 1
        while r + 3 <= m:
            s0 += t[j, r] * x[j + r]
            s1 += t[j, r + 1] * x[j + r + 1]
            s2 += t[j, r + 2] * x[j + r + 2]
            s3 += t[j, r + 3] * x[j + r + 3]
            r += 4
        while r <= m:
            s0 += t[j, r] * x[j + r]
            r += 1
        x[j] -= (s0 + s1) + (s2 + s3)
    return x


class BandLDLT:
    """A = L D L^T of a symmetric band matrix, without pivoting (see the module docstring).

    factor: the unit lower band factor in band storage, factor[r, j] = L[j + r, j] (factor[0] = 1),
    shape (bandwidth + 1, n) like the input; d: the pivots D; tolerance: n eps max|A_jj|; tiny: the
    columns whose pivot is within the tolerance of zero (counted as zero); stopped_at: the column of
    an exactly zero pivot where the elimination stopped (later pivots NaN), or None.
    """

    def __init__(self, band: np.ndarray):
        band = np.asarray(band, dtype=float)
        if band.ndim != 2 or band.shape[0] < 1:
            raise ValueError(f"band must be (bandwidth + 1, n), got shape {band.shape}")
        n = band.shape[1]
        self.n = n
        self.bandwidth = band.shape[0] - 1
        diag = np.abs(band[0])
        diag_max = float(np.max(diag, initial=0.0, where=np.isfinite(diag)))  # a NaN pivot is caught below
        self.tolerance = n * np.finfo(float).eps * diag_max
        self._t = np.array(band.T, order="C", copy=True)  # (n, w), t[j, r] = A[j + r, j]
        count, first, stop = (ldlt_transposed(self._t, self.tolerance, PANEL, LEAF, CHUNK, BLOCKED_FROM)
                               if n else (0, -1, -1))
        self.d = self._t[:, 0].copy()
        self.stopped_at = None if stop < 0 else int(stop)
        if count:
            small = np.abs(self.d) <= self.tolerance
            small |= ~np.isfinite(self.d)
            self.tiny = np.flatnonzero(small)
        else:
            self.tiny = np.empty(0, dtype=np.int64)
        self._first_tiny = None if first < 0 else int(first)

    @property
    def reliable(self) -> bool:
        """No pivot within rounding of zero: the factor, the inertia and solves can be trusted."""
        return self._first_tiny is None

    @property
    def factor(self) -> np.ndarray:
        """The unit lower band factor L in band storage (a new array, factor[0] = 1)."""
        out = self._t.T.copy()
        out[0] = 1.0
        return out

    def _problem(self) -> str:
        j = self._first_tiny
        what = ("is exactly zero: the elimination stopped there" if self.stopped_at == j
                else f"has |d| = {abs(self.d[j]):.3e} <= n eps max|A_jj| = {self.tolerance:.3e}")
        return (f"LDL^T without pivoting: pivot {j} of {self.n} {what} (the leading {j + 1} x {j + 1} principal "
                f"minor is singular to rounding; {len(self.tiny)} such pivot(s))")

    def inertia(self, strict: bool = True) -> Inertia:
        """(negative, zero, positive) pivot counts = eigenvalue counts of A (Sylvester).

        strict (default): raise UnreliablePivot if any pivot is zero to rounding. strict=False:
        count such pivots as zero (the later ones may be contaminated); still raises if the
        elimination stopped at an exactly zero pivot (the later pivots do not exist)."""
        if not self.reliable and (strict or self.stopped_at is not None):
            raise UnreliablePivot(self._problem())
        d = self.d
        small = np.zeros(self.n, dtype=bool)
        small[self.tiny] = True
        neg = int(np.count_nonzero((d < 0) & ~small))
        pos = int(np.count_nonzero((d > 0) & ~small))
        return Inertia(neg, int(np.count_nonzero(small)), pos)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """A^-1 rhs for rhs of shape (n,) or (n, k); raises UnreliablePivot if a pivot is zero to rounding."""
        if not self.reliable:
            raise UnreliablePivot(self._problem())
        rhs = np.asarray(rhs, dtype=float)
        if rhs.ndim not in (1, 2) or rhs.shape[0] != self.n:
            raise ValueError(f"rhs must have shape ({self.n},) or ({self.n}, k), got {rhs.shape}")
        if rhs.ndim == 1:
            return solve_transposed_1(self._t, np.array(rhs, dtype=float, copy=True))
        return solve_transposed(self._t, np.array(rhs, dtype=float, order="C", copy=True))


def band_ldlt(band: np.ndarray) -> BandLDLT:
    """Factor the symmetric matrix of lower band storage `band` as L D L^T without pivoting."""
    return BandLDLT(band)


def inertia(band: np.ndarray, strict: bool = True) -> Inertia:
    """(negative, zero, positive) eigenvalue counts of the symmetric band matrix, from the signs of
    the LDL^T pivots (Sylvester's law of inertia). Raises UnreliablePivot when a pivot is zero to
    rounding (strict), or counts it as zero (strict=False); see BandLDLT.inertia."""
    return BandLDLT(band).inertia(strict=strict)


def ldlt_solve(band: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve A x = rhs by the LDL^T of the band (raises UnreliablePivot on a pivot zero to rounding)."""
    return BandLDLT(band).solve(rhs)
