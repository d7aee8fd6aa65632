"""LAPACK's band routines callable from compiled (numba) code: the Cholesky factor and solve of a
symmetric positive definite band matrix (dpbtrf, dpbtrs) and the LU solve of a general band
matrix (dgbsv), the routines scipy.linalg.cholesky_banded, cho_solve_banded and solve_banded call.

They are scipy's own LAPACK (scipy.linalg.cython_lapack), registered with LLVM under names of
ours so that compiled functions calling them can be cached by numba (a ctypes pointer in a
compiled function's globals cannot be). Storage: the transposed lower band t (n, bandwidth + 1),
C-contiguous, t[j, d] = A[j + d, j], which is LAPACK's column-major lower band form.
"""
from __future__ import annotations

import llvmlite.binding as llvm
import numpy as np
from numba import njit, types
from numba.extending import get_cython_function_address

for _routine in ("dpbtrf", "dpbtrs", "dgbsv"):
    llvm.add_symbol(f"ddg_{_routine}", get_cython_function_address("scipy.linalg.cython_lapack", _routine))

_p = types.voidptr
_dpbtrf = types.ExternalFunction("ddg_dpbtrf", types.void(_p, _p, _p, _p, _p, _p))
_dpbtrs = types.ExternalFunction("ddg_dpbtrs", types.void(_p, _p, _p, _p, _p, _p, _p, _p, _p))
_dgbsv = types.ExternalFunction("ddg_dgbsv", types.void(_p, _p, _p, _p, _p, _p, _p, _p, _p, _p))

_LOWER = 76  # ord("L")


@njit(cache=True)
def band_cholesky(t):
    """In place: t (n, w) becomes its lower Cholesky factor. Returns True where A is positive
    definite (LAPACK's info = 0), False otherwise (t is then partly overwritten)."""
    n, w = t.shape
    if n == 0:
        return True
    ints = np.array([n, w - 1, w, 0], dtype=np.int32)  # n, kd, ldab, info
    uplo = np.array([_LOWER], dtype=np.uint8)
    _dpbtrf(uplo.ctypes, ints[0:1].ctypes, ints[1:2].ctypes, t.ctypes, ints[2:3].ctypes, ints[3:4].ctypes)
    return ints[3] == 0


@njit(cache=True)
def band_cholesky_solve(factor, x):
    """In place: x becomes A^-1 x, with factor (n, w) from band_cholesky."""
    n, w = factor.shape
    if n == 0:
        return
    ints = np.array([n, w - 1, w, 1, 0], dtype=np.int32)  # n, kd, ldab, nrhs, info
    uplo = np.array([_LOWER], dtype=np.uint8)
    _dpbtrs(uplo.ctypes, ints[0:1].ctypes, ints[1:2].ctypes, ints[3:4].ctypes, factor.ctypes, ints[2:3].ctypes,
            x.ctypes, ints[0:1].ctypes, ints[4:5].ctypes)


@njit(cache=True)
def band_lu_solve(t, rhs):
    """A^-1 rhs for the symmetric A of transposed lower band t (n, w), by LU with partial pivoting
    (dgbsv); returns (x, ok), ok False where A is singular."""
    n, w = t.shape
    kd = w - 1
    ldab = 3 * kd + 1
    ab = np.zeros((n, ldab))  # column-major (ldab, n): A[i, j] at ab[j, 2 kd + i - j]
    for j in range(n):
        for d in range(w):
            if j + d < n:
                ab[j, 2 * kd + d] = t[j, d]          # A[j + d, j]
                ab[j + d, 2 * kd - d] = t[j, d]      # A[j, j + d]
    x = rhs.copy()
    pivots = np.zeros(max(n, 1), dtype=np.int32)
    ints = np.array([n, kd, kd, 1, ldab, n, 0], dtype=np.int32)  # n, kl, ku, nrhs, ldab, ldb, info
    _dgbsv(ints[0:1].ctypes, ints[1:2].ctypes, ints[2:3].ctypes, ints[3:4].ctypes, ab.ctypes, ints[4:5].ctypes,
           pivots.ctypes, x.ctypes, ints[5:6].ctypes, ints[6:7].ctypes)
    return x, ints[6] == 0
