"""Stability of an equilibrium from the Hessian restricted to the free DOFs.

A successful Cholesky factorisation proves the state stable; the lowest eigenvalues are
computed in the model's lumped metric (see the model's `eigenvalue_metric`) so that the
normalised lambda_min is comparable across resolutions and between the rod and the plate.
"""
from __future__ import annotations

import numpy as np


def lowest_modes(model, hessian, count: int = 1, vectors: bool = False):
    """Normalised lowest eigenvalues (and eigenvectors in DOF space) of the free-DOF Hessian."""
    metric, unit = model.eigenvalue_metric()
    s = 1.0 / np.sqrt(metric)
    K = model.free_matrix(hessian).scaled(s)
    if vectors:
        w, v = K.lowest_eigenpairs(count, vectors=True)
        return np.asarray(w) / unit, v * s[:, None]
    return np.atleast_1d(K.lowest_eigenpairs(count)) / unit
