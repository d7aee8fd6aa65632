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
    converge, use ARPACK's shift-invert Lanczos on the scaled matrix, which gives the eigenvectors
    with the eigenvalues: both are kept on `hessian` (an evaluation's, which nothing changes), so
    that a later request for them on the same state (branch switching from an unstable state whose
    lambda_min was recorded) reuses them instead of solving again."""
    kept = getattr(hessian, "_lowest_modes", None)
    if kept is not None and kept[0].shape[0] >= count:
        w, v = kept
        return (w[:count], v[:, :count]) if vectors else w[:count]
    metric, unit = model.eigenvalue_metric()
    if count == 1 and not vectors:
        K = model.free_matrix(hessian)
        # narrow bands only (the rod's is 10): on the plate's (83-131) the compiled triangular
        # solves lose to ARPACK with LAPACK's (docs/findings/measured.md)
        if K.band.shape[0] - 1 <= LANCZOS_MAX_BANDWIDTH and K.cholesky():
            lam = lowest_eigenvalue(K.cholesky_factor, metric)
            if lam is not None:
                return np.array([lam / unit])
    s = 1.0 / np.sqrt(metric)
    K = model.free_matrix(hessian).scaled(s)
    w, v = K.lowest_eigenpairs(count, vectors=True)   # ARPACK computes the vectors either way
    w, v = np.atleast_1d(np.asarray(w)) / unit, v * s[:, None]
    try:
        hessian._lowest_modes = (w, v)
    except AttributeError:   # an object that takes no attributes: nothing kept
        pass
    return (w, v) if vectors else w
