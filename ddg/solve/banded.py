"""Symmetric banded matrices (lower storage): Cholesky, solves, eigenvalues.

Storage follows LAPACK's lower band form: band[d, j] = A[j + d, j] for 0 <= d <= bandwidth.
The rod's DOF vector (Eq. 1) interleaves positions and twists so that every element touches
a contiguous block of at most 11 DOFs: the Hessian has bandwidth 10 and Newton costs O(M).
The plate orders its nodes along the strip (ddg.geometry.plate_mesh), so its Hessian is
banded too, with a bandwidth of about six times the nodes per column: for a strip a banded
Cholesky beats general sparse factorisations (measured in benchmarks/plate_linear_algebra.py).
The element kernels write into this storage directly (ddg.assembly.band_scatter).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..assembly.band_scatter import band_matvec


class SymmetricBanded:
    """A symmetric matrix in lower band storage with the operations the solvers need."""

    def __init__(self, band: np.ndarray):
        self.band = band
        self._cholesky = None
        self._cholesky_tried = False

    @property
    def n(self) -> int:
        return self.band.shape[1]

    def restrict(self, start: int, stop: int) -> "SymmetricBanded":
        """The principal sub-matrix on DOFs start..stop-1 (the free block of the rod)."""
        band = self.band[:, start:stop].copy()
        m = stop - start
        for d in range(1, band.shape[0]):
            band[d, m - d:] = 0.0
        return SymmetricBanded(band)

    def mean_diagonal(self) -> float:
        return float(np.mean(np.abs(self.band[0])))

    def shifted(self, shift: float) -> "SymmetricBanded":
        """A + shift I (cached for the last shift asked, so a trial factorisation is reused)."""
        cached = getattr(self, "_shifted", None)
        if cached is not None and cached[0] == shift:
            return cached[1]
        band = self.band.copy()
        band[0] += shift
        out = SymmetricBanded(band)
        self._shifted = (shift, out)
        return out

    def matvec(self, x: np.ndarray) -> np.ndarray:
        return band_matvec(np.ascontiguousarray(self.band), np.ascontiguousarray(x, dtype=float))

    def cholesky(self) -> bool:
        """Try a banded Cholesky; success proves the matrix positive definite."""
        if not self._cholesky_tried:
            self._cholesky_tried = True
            try:
                self._cholesky = sla.cholesky_banded(self.band, lower=True, check_finite=False)
            except sla.LinAlgError:
                self._cholesky = None
        return self._cholesky is not None

    @property
    def cholesky_factor(self) -> np.ndarray | None:
        """The lower band Cholesky factor (LAPACK storage), or None if A is not positive definite."""
        return self._cholesky if self.cholesky() else None

    @property
    def positive_definite(self) -> bool:
        return self.cholesky()

    def ldlt(self):
        """A = L D L^T without pivoting (ddg.solve.band_ldlt), cached; for indefinite matrices."""
        if getattr(self, "_ldlt", None) is None:
            from .band_ldlt import BandLDLT

            self._ldlt = BandLDLT(self.band)
        return self._ldlt

    def inertia(self):
        """(negative, zero, positive) eigenvalue counts from the LDL^T pivots (Sylvester's law);
        raises band_ldlt.UnreliablePivot where a pivot is zero to rounding."""
        if self.cholesky():
            return (0, 0, self.n)
        return tuple(self.ldlt().inertia())

    #: An LDL^T solve (no pivoting) is kept when its relative residual is below this; else banded LU.
    LDLT_RESIDUAL = 1e-8

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """A^-1 rhs: banded Cholesky where A is positive definite; otherwise LDL^T without pivoting
        (about the Cholesky's cost, cheaper than banded LU: benchmarks/results/plate_linear_algebra.md),
        checked by its residual, and banded LU (partial pivoting) where that check fails."""
        if self.cholesky():
            return sla.cho_solve_banded((self._cholesky, True), rhs, check_finite=False)
        ldlt = self.ldlt()
        if ldlt.reliable:
            x = ldlt.solve(rhs)
            columns = (x,) if x.ndim == 1 else x.T
            targets = (rhs,) if x.ndim == 1 else np.asarray(rhs).T
            tolerance = self.LDLT_RESIDUAL
            if all(np.all(np.isfinite(c)) and np.linalg.norm(self.matvec(c) - b) <= tolerance * np.linalg.norm(b)
                   for c, b in zip(columns, targets)):
                return x
        u = self.band.shape[0] - 1
        full = np.zeros((2 * u + 1, self.n))
        full[u:] = self.band
        for d in range(1, u + 1):
            full[u - d, d:] = self.band[d, : self.n - d]
        return sla.solve_banded((u, u), full, rhs, check_finite=False)

    def lowest_eigenpairs(self, count: int = 1, vectors: bool = False):
        """The `count` lowest eigenvalues (and eigenvectors), by shift-invert Lanczos.

        Positive definite (Cholesky succeeded): Lanczos on the inverse, O(n b^2) to factor and
        O(n b) per iteration, exact for the lowest eigenvalues because all are positive.
        Otherwise the smallest shift sigma in 1e-8, 4e-8, 16e-8, ... times the mean diagonal that
        makes A + sigma I positive definite brackets the lowest eigenvalue in (-sigma, -sigma/4],
        and Lanczos on (A + sigma I)^-1 finds it and its neighbours.
        """
        count = min(count, self.n)
        if self.n <= 4 * count + 20:
            w, v = np.linalg.eigh(self.to_dense())
            return (w[:count], v[:, :count]) if vectors else w[:count]
        from scipy.sparse.linalg import LinearOperator, eigsh

        shift, operator = 0.0, self
        if not self.cholesky():
            shift = 1e-8 * max(self.mean_diagonal(), np.finfo(float).tiny)
            while not self.shifted(shift).cholesky():
                shift *= 4.0
            operator = self.shifted(shift)
        inverse = LinearOperator((self.n, self.n), matvec=operator.solve, dtype=float)
        mu, v = eigsh(inverse, k=count, which="LA", tol=1e-12, ncv=min(self.n, max(2 * count + 1, 20)),
                      v0=np.ones(self.n))
        order = np.argsort(-mu)
        w = 1.0 / mu[order] - shift
        return (w, v[:, order]) if vectors else w

    def to_dense(self) -> np.ndarray:
        a = np.diag(self.band[0])
        for d in range(1, self.band.shape[0]):
            off = np.diag(self.band[d, : self.n - d], -d)
            a += off + off.T
        return a

    def scaled(self, s: np.ndarray) -> "SymmetricBanded":
        """diag(s) A diag(s), still banded (used to normalise eigenvalues). Where A's Cholesky was
        tried, the scaled matrix inherits the outcome without factoring again (s > 0): its factor
        is diag(s) L, L's rows scaled (the unique factor with a positive diagonal), and it is
        positive definite exactly when A is (Sylvester's law of inertia)."""
        band = self.band * s[None, :]
        for d in range(band.shape[0]):
            band[d, : self.n - d] *= s[d:]
        out = SymmetricBanded(band)
        if self._cholesky_tried and np.all(s > 0):
            out._cholesky_tried = True
            if self._cholesky is not None:
                factor = self._cholesky.copy(order="K")  # LAPACK's (Fortran) layout: no copy per solve
                for d in range(factor.shape[0]):
                    factor[d, : self.n - d] *= s[d:]
                out._cholesky = factor
        return out
