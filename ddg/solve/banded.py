"""Symmetric banded matrices (lower storage) for the rod: assembly, Cholesky, eigenvalues.

Storage follows LAPACK's lower band form: band[d, j] = A[j + d, j] for 0 <= d <= bandwidth.
The rod's DOF vector (Eq. 1) interleaves positions and twists so that every element touches
a contiguous block of at most 11 DOFs: the Hessian has bandwidth 10 and Newton costs O(M).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla


class BandAssembler:
    """Precomputed scatter indices from dense element blocks to lower band storage.

    Each element type is a family of (m x m) blocks placed at DOF offsets `offsets`; the
    flat target index of entry (a, b), a >= b, of block k is (a - b) * n + offsets[k] + b.
    """

    def __init__(self, n: int, bandwidth: int):
        self.n = n
        self.bandwidth = bandwidth
        self._families: list[tuple[np.ndarray, np.ndarray]] = []

    def add_family(self, offsets: np.ndarray, size: int) -> int:
        a, b = np.tril_indices(size)
        if np.any(a - b > self.bandwidth):
            raise ValueError("element block wider than the band")
        flat = (a - b)[None, :] * self.n + offsets[:, None] + b[None, :]
        local = a * size + b
        self._families.append((flat.ravel(), local))
        return len(self._families) - 1

    def assemble(self, blocks: list[np.ndarray]) -> "SymmetricBanded":
        total = np.zeros((self.bandwidth + 1) * self.n)
        for (flat, local), values in zip(self._families, blocks):
            m = values.shape[1]
            total += np.bincount(flat, weights=values.reshape(-1, m * m)[:, local].ravel(), minlength=total.size)
        return SymmetricBanded(total.reshape(self.bandwidth + 1, self.n))


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
        y = self.band[0] * x
        for d in range(1, self.band.shape[0]):
            col = self.band[d, : self.n - d]
            y[d:] += col * x[: self.n - d]
            y[: self.n - d] += col * x[d:]
        return y

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
    def positive_definite(self) -> bool:
        return self.cholesky()

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self.cholesky():
            return sla.cho_solve_banded((self._cholesky, True), rhs, check_finite=False)
        u = self.band.shape[0] - 1
        full = np.zeros((2 * u + 1, self.n))
        full[u:] = self.band
        for d in range(1, u + 1):
            full[u - d, d:] = self.band[d, : self.n - d]
        return sla.solve_banded((u, u), full, rhs, check_finite=False)

    def lowest_eigenpairs(self, count: int = 1, vectors: bool = False):
        """The `count` lowest eigenvalues (and eigenvectors).

        Positive definite (Cholesky succeeded): Lanczos on the inverse, O(n) per iteration,
        exact for the lowest eigenvalues because all are positive. Otherwise LAPACK's banded
        eigensolver for the values (dsbevx: O(n^2) band reduction, used only on unstable
        states) and inverse iteration for the vectors.
        """
        count = min(count, self.n)
        if self.cholesky() and self.n > 4 * count + 20:
            from scipy.sparse.linalg import LinearOperator, eigsh

            inverse = LinearOperator((self.n, self.n), matvec=self.solve, dtype=float)
            mu, v = eigsh(inverse, k=count, which="LA", tol=1e-12, ncv=min(self.n, max(2 * count + 1, 20)),
                          v0=np.ones(self.n))
            order = np.argsort(-mu)
            w = 1.0 / mu[order]
            return (w, v[:, order]) if vectors else w
        w = np.atleast_1d(sla.eig_banded(self.band, lower=True, eigvals_only=True, select="i",
                                         select_range=(0, count - 1), check_finite=False))
        if not vectors:
            return w
        # eigenvectors by inverse iteration just below each eigenvalue (O(n) per iteration;
        # asking LAPACK for them forms the full orthogonal transform, O(n^3))
        vecs = np.empty((self.n, count))
        scale = max(1.0, float(np.max(np.abs(w))))
        rng = np.random.default_rng(0)
        for i, lam in enumerate(w):
            shifted = self.shifted(-(lam - 1e-10 * scale))
            v = rng.standard_normal(self.n)
            for _ in range(4):
                v = shifted.solve(v)
                v -= vecs[:, :i] @ (vecs[:, :i].T @ v)
                v /= np.linalg.norm(v)
            vecs[:, i] = v
        return w, vecs

    def to_dense(self) -> np.ndarray:
        a = np.diag(self.band[0])
        for d in range(1, self.band.shape[0]):
            off = np.diag(self.band[d, : self.n - d], -d)
            a += off + off.T
        return a

    def scaled(self, s: np.ndarray) -> "SymmetricBanded":
        """diag(s) A diag(s), still banded (used to normalise eigenvalues)."""
        band = self.band * s[None, :]
        for d in range(band.shape[0]):
            band[d, : self.n - d] *= s[d:]
        return SymmetricBanded(band)
