"""Compiled scatter of element blocks into symmetric lower band storage (LAPACK form).

Band storage: band[d, j] = A[j + d, j], 0 <= d <= bandwidth, for an n x n matrix; with the band
flattened (C order) the entry (r, c), r >= c, sits at (r - c) * n + c. Element kernels (the rod's
stencils and edges, the plate's edges, triangles and hinges) call these helpers for every element
as they compute it, so no per-element block arrays are formed in the assembled evaluation.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, forceinline=True)
def add_entry(band, n, r, c, value):
    """A[r, c] += value and (by symmetry) A[c, r] += value, in lower storage."""
    if r >= c:
        band[(r - c) * n + c] += value
    else:
        band[(c - r) * n + r] += value


@njit(cache=True)
def add_symmetric_block(band, n, dofs, block):
    """A[dofs, dofs] += block for a symmetric block with distinct global DOFs: each global pair
    receives its entry once (from the (a, b) with dofs[a] >= dofs[b])."""
    m = dofs.shape[0]
    for a in range(m):
        r = dofs[a]
        for b in range(m):
            c = dofs[b]
            if r >= c:
                band[(r - c) * n + c] += block[a, b]


@njit(cache=True)
def add_pair_block(band, n, rows, cols, block):
    """A += C + C^T with C = block on (rows, cols): each entry lands once in the lower band, twice
    where a row DOF equals a column DOF (the diagonal of the shared nodes)."""
    for a in range(rows.shape[0]):
        r = rows[a]
        for b in range(cols.shape[0]):
            c = cols[b]
            if r > c:
                band[(r - c) * n + c] += block[a, b]
            elif r < c:
                band[(c - r) * n + r] += block[a, b]
            else:
                band[c] += 2.0 * block[a, b]


@njit(cache=True)
def band_matvec(band, x):
    """y = A x for the symmetric matrix in lower band storage band (bandwidth + 1, n)."""
    n = band.shape[1]
    y = np.empty(n)
    for j in range(n):
        y[j] = band[0, j] * x[j]
    for d in range(1, band.shape[0]):
        for j in range(n - d):
            v = band[d, j]
            y[j + d] += v * x[j]
            y[j] += v * x[j + d]
    return y
