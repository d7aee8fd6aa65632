"""Edge stretching, vectorised over edges: E = 1/2 k (|e| - |e_bar|)^2.

The rod's Eq. (6a), 1/2 EA (|e|/|e_bar| - 1)^2 |e_bar|, is this with k = EA / |e_bar|; the
plate's Eq. (11a) is this with k = sqrt(3)/2 E b. Derivatives are taken with respect to the
edge vector e = x_j - x_i; assembly maps them to the two end nodes (+ on x_j, - on x_i).
"""
from __future__ import annotations

import numpy as np


def stretching_energy(edges: np.ndarray, rest_lengths: np.ndarray, stiffness, *, gradient=True, hessian=True):
    """Energy per edge, its gradient (n, 3) and Hessian (n, 3, 3) with respect to each edge vector.

    dE/de = k (|e| - l) t;  d2E/de2 = k [t t^T + (1 - l/|e|) (I - t t^T)].
    """
    length = np.linalg.norm(edges, axis=1)
    extension = length - rest_lengths
    energy = 0.5 * stiffness * extension**2
    if not gradient:
        return energy, None, None
    t = edges / length[:, None]
    grad = (stiffness * extension)[:, None] * t
    if not hessian:
        return energy, grad, None
    tt = t[:, :, None] * t[:, None, :]
    k = np.broadcast_to(stiffness, length.shape)
    ratio = (k * (1.0 - rest_lengths / length))[:, None, None]
    hess = k[:, None, None] * tt + ratio * (np.eye(3) - tt)
    return energy, grad, hess


def two_node_blocks(grad_e: np.ndarray, hess_e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Expand derivatives with respect to e = x_j - x_i to the 6 DOFs (x_i, x_j)."""
    n = grad_e.shape[0]
    grad = np.empty((n, 6))
    grad[:, :3] = -grad_e
    grad[:, 3:] = grad_e
    hess = np.empty((n, 6, 6))
    hess[:, :3, :3] = hess_e
    hess[:, 3:, 3:] = hess_e
    hess[:, :3, 3:] = -hess_e
    hess[:, 3:, :3] = -hess_e
    return grad, hess
