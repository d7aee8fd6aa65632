"""Edge stretching: E = 1/2 k (|e| - |e_bar|)^2 per edge, compiled.

The rod's Eq. (6a), 1/2 EA (|e|/|e_bar| - 1)^2 |e_bar|, is this with k = EA / |e_bar|; the
plate's Eq. (11a) is this with k = sqrt(3)/2 E b. Derivatives are taken with respect to the
edge vector e = x_j - x_i; assembly maps them to the two end nodes (+ on x_j, - on x_i).
`edge_stretch` is the one implementation; `add_edge_terms` assembles it for the rod and the plate,
`stretching_energy` returns it per edge (tests, analysis).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..assembly.band_scatter import add_entry


@njit(cache=True, forceinline=True)
def edge_stretch(e0, e1, e2, rest, k, grad, hess, want_gradient, want_hessian):
    """Energy of one edge vector e; writes dE/de (3,) and d2E/de2 (3, 3) where asked:
    dE/de = k (|e| - l) t;  d2E/de2 = k [t t^T + (1 - l/|e|) (I - t t^T)]."""
    length = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    extension = length - rest
    if want_gradient:
        t0, t1, t2 = e0 / length, e1 / length, e2 / length
        force = k * extension
        grad[0], grad[1], grad[2] = force * t0, force * t1, force * t2
        if want_hessian:
            ratio = k * (1.0 - rest / length)
            t = (t0, t1, t2)
            for a in range(3):
                for b in range(3):
                    tab = t[a] * t[b]
                    hess[a, b] = k * tab + ratio * ((1.0 if a == b else 0.0) - tab)
    return 0.5 * k * extension * extension


@njit(cache=True)
def _per_edge(edges, rest, k, want_gradient, want_hessian):
    n = edges.shape[0]
    energy = np.empty(n)
    grad = np.zeros((n, 3))
    hess = np.zeros((n, 3, 3))
    for i in range(n):
        energy[i] = edge_stretch(edges[i, 0], edges[i, 1], edges[i, 2], rest[i], k[i], grad[i], hess[i],
                                 want_gradient, want_hessian)
    return energy, grad, hess


def stretching_energy(edges: np.ndarray, rest_lengths: np.ndarray, stiffness, *, gradient=True, hessian=True):
    """Energy per edge, its gradient (n, 3) and Hessian (n, 3, 3) with respect to each edge vector
    (None where not asked)."""
    edges = np.ascontiguousarray(edges, dtype=float)
    n = edges.shape[0]
    rest = np.ascontiguousarray(np.broadcast_to(rest_lengths, (n,)), dtype=float)
    k = np.ascontiguousarray(np.broadcast_to(stiffness, (n,)), dtype=float)
    energy, grad, hess = _per_edge(edges, rest, k, bool(gradient), bool(gradient and hessian))
    return energy, (grad if gradient else None), (hess if gradient and hessian else None)


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


@njit(cache=True)
def add_edge_terms(x, edge_nodes, rest, k, node_stride, n_dof, grad, band, want_gradient, want_hessian):
    """Stretching energy of the edges (node pairs edge_nodes (n, 2) of positions x (N, 3)), adding
    its gradient to grad and its Hessian to the flattened lower band where asked; node j's
    coordinates are DOFs node_stride * j + (0, 1, 2). Returns the total energy."""
    g = np.empty(3)
    h = np.empty((3, 3))
    total = 0.0
    for i in range(edge_nodes.shape[0]):
        p, q = edge_nodes[i, 0], edge_nodes[i, 1]
        total += edge_stretch(x[q, 0] - x[p, 0], x[q, 1] - x[p, 1], x[q, 2] - x[p, 2], rest[i], k[i], g, h,
                              want_gradient, want_hessian)
        if not want_gradient:
            continue
        dp, dq = node_stride * p, node_stride * q
        for a in range(3):
            grad[dp + a] -= g[a]
            grad[dq + a] += g[a]
        if want_hessian:
            for a in range(3):
                for b in range(3):
                    v = h[a, b]
                    if a >= b:  # the diagonal node blocks are symmetric: the lower half of each
                        add_entry(band, n_dof, dp + a, dp + b, v)
                        add_entry(band, n_dof, dq + a, dq + b, v)
                    add_entry(band, n_dof, dq + a, dp + b, -v)  # the off-diagonal block, once
    return total
