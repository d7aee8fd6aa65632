"""Stability of an equilibrium from the Hessian restricted to the free DOFs.

A successful Cholesky factorisation proves the state stable; the lowest eigenvalues are
computed in the model's lumped metric (see the model's `eigenvalue_metric`) so that the
normalised lambda_min is comparable across resolutions and between the rod and the plate.
"""
from __future__ import annotations

import numpy as np

from .lanczos import lowest_eigenvalue

LANCZOS_MAX_BANDWIDTH = 32


def lowest_modes(model, hessian, count: int = 1, vectors: bool = False):
    """Normalised lowest eigenvalues (and eigenvectors in DOF space) of the free-DOF Hessian.

    The lowest eigenvalue alone of a positive definite Hessian comes from the Cholesky factor
    Newton already computed (ddg.solve.lanczos); other requests, and a Lanczos that does not
    converge, use ARPACK's shift-invert Lanczos on the scaled matrix."""
    metric, unit = model.eigenvalue_metric()
    if count == 1 and not vectors:
        K = model.free_matrix(hessian)
        # narrow bands only (the rod's is 10): on the plate's (83-131) the compiled triangular
        # solves lose to ARPACK with LAPACK's (eigen time per iteration 3.1 -> 4.1 ms at 5740
        # triangles, measured)
        if K.band.shape[0] - 1 <= LANCZOS_MAX_BANDWIDTH and K.cholesky():
            lam = lowest_eigenvalue(K.cholesky_factor, metric)
            if lam is not None:
                return np.array([lam / unit])
    s = 1.0 / np.sqrt(metric)
    K = model.free_matrix(hessian).scaled(s)
    if vectors:
        w, v = K.lowest_eigenpairs(count, vectors=True)
        return np.asarray(w) / unit, v * s[:, None]
    return np.atleast_1d(K.lowest_eigenpairs(count)) / unit
