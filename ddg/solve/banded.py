"""Symmetric banded matrices (lower storage): assembly, Cholesky, solves, eigenvalues.

Storage follows LAPACK's lower band form: band[d, j] = A[j + d, j] for 0 <= d <= bandwidth.
The rod's DOF vector (Eq. 1) interleaves positions and twists so that every element touches
a contiguous block of at most 11 DOFs: the Hessian has bandwidth 10 and Newton costs O(M).
The plate orders its nodes along the strip (ddg.geometry.plate_mesh), so its Hessian is
banded too, with a bandwidth of about six times the nodes per column: for a strip a banded
Cholesky beats general sparse factorisations (measured in benchmarks/plate_path.py).
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
        self._families: list[tuple[np.ndarray, np.ndarray, str]] = []
        self._all_flat = None  # concatenated targets of all families, built at the first assemble

    def _add(self, flat: np.ndarray, local: np.ndarray, kind: str) -> int:
        self._families.append((flat, local, kind))
        self._all_flat = None
        return len(self._families) - 1

    def add_family(self, offsets: np.ndarray, size: int) -> int:
        a, b = np.tril_indices(size)
        if np.any(a - b > self.bandwidth):
            raise ValueError("element block wider than the band")
        flat = (a - b)[None, :] * self.n + offsets[:, None] + b[None, :]
        local = a * size + b
        return self._add(flat.ravel(), local, "contiguous")

    def add_indexed_family(self, dofs: np.ndarray) -> int:
        """A family of symmetric (m x m) blocks on arbitrary DOFs dofs (K, m), e.g. a triangle's
        nine coordinates; only the entries that fall in the lower band are gathered."""
        rows, cols = dofs[:, :, None], dofs[:, None, :]
        lower = np.broadcast_to(rows >= cols, (len(dofs),) + (dofs.shape[1],) * 2)
        if np.any(np.abs(rows - cols) > self.bandwidth):
            raise ValueError("element block wider than the band")
        flat = ((rows - cols) * self.n + cols)[lower]
        return self._add(flat, np.flatnonzero(lower.ravel()), "indexed")

    def add_pair_family(self, row_dofs: np.ndarray, col_dofs: np.ndarray) -> int:
        """A family of blocks C (K, m, p) entering the matrix as C + C^T on rows row_dofs (K, m)
        and columns col_dofs (K, p): each entry lands once in the lower band (twice on the
        diagonal, where C and C^T coincide)."""
        rows, cols = row_dofs[:, :, None], col_dofs[:, None, :]
        if np.any(np.abs(rows - cols) > self.bandwidth):
            raise ValueError("element block wider than the band")
        low, high = np.minimum(rows, cols), np.maximum(rows, cols)
        flat = ((high - low) * self.n + low).ravel()
        return self._add(flat, np.where(rows == cols, 2.0, 1.0).ravel(), "pair")

    def assemble(self, blocks: list[np.ndarray]) -> "SymmetricBanded":
        """Sum the element blocks (one array per family, in the order added) into the band:
        the lower-band entries of all families are gathered into one buffer, one bincount."""
        if self._all_flat is None:
            self._all_flat = np.concatenate([f for f, _, _ in self._families])
            self._buffer = np.empty(len(self._all_flat))
        start = 0
        for (flat, local, kind), values in zip(self._families, blocks):
            out = self._buffer[start:start + len(flat)]
            if kind == "indexed":  # positions in the whole stack of blocks
                np.take(values.ravel(), local, out=out)
            elif kind == "pair":  # local holds the multiplicity (2 on the diagonal)
                np.multiply(values.ravel(), local, out=out)
            else:
                m = values.shape[1]
                out[:] = values.reshape(-1, m * m)[:, local].ravel()
            start += len(flat)
        total = np.bincount(self._all_flat, weights=self._buffer, minlength=(self.bandwidth + 1) * self.n)
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
        """The `count` lowest eigenvalues (and eigenvectors), by shift-invert Lanczos.

        Positive definite (Cholesky succeeded): Lanczos on the inverse, O(n b^2) to factor and
        O(n b) per iteration, exact for the lowest eigenvalues because all are positive.
        Otherwise the smallest shift sigma (growing by 4x from 1e-8 of the mean diagonal) that
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
        """diag(s) A diag(s), still banded (used to normalise eigenvalues)."""
        band = self.band * s[None, :]
        for d in range(band.shape[0]):
            band[d, : self.n - d] *= s[d:]
        return SymmetricBanded(band)
