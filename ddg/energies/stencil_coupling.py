"""Chain rule for rod-family energies that couple more than one stencil's three strains.

The rod's energies (Eqs. 6b, 6c) and the Sadowsky ribbon (Eq. A.5) are sums over the interior
nodes of a density of that node's own strains (kappa_n, kappa_g, tau); `rod_curvature.
add_stencil_terms` assembles them. The ribbons with width need two more kinds of argument:

- the centreline stretch at a node, eps_i = (|e^{i-1}| + |e^i|) / (|e-bar^{i-1}| + |e-bar^i|) - 1
  (the Voronoi mean of Eq. 2's edge strains), which the trapeze ribbon couples to the twist
  (ddg.energies.trapeze);
- the strains of two neighbouring stencils, which the Wunderlich ribbon needs for
  eta' = d(tau / kappa) / ds (ddg.energies.wunderlich).

Both are written here as terms E_p = e_p(s_p1, ..., s_pk) of k strains whose gradients and
Hessians with respect to a contiguous block of D DOFs are known ("local strains"); the chain rule

    grad E_p = sum_a e_a grad s_a,   hess E_p = sum_a e_a hess s_a + sum_ab e_ab grad s_a grad s_b^T

is applied by one compiled kernel, `add_local_terms`, that writes into the assembled gradient and
the lower band. The strains' own derivatives come from rod_curvature.strain_derivatives (the only
implementation of Eqs. 3-5) and from `stencil_stretch` below (Eq. 2).

Local DOF blocks (the rod's DOF order, Eq. 1): a stencil at interior node i is the 11 DOFs
[x_{i-1}, theta^{i-1}, x_i, theta^i, x_{i+1}] starting at DOF 4 (i - 1); a pair of stencils at
nodes i and i + 1 is the 15 DOFs starting at the same place, the second stencil occupying local
DOFs 4..14. The pair's Hessian spans 15 DOFs: a model using pairs has bandwidth 14.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .rod_curvature import STENCIL_SIZE, strain_derivatives

#: DOFs of a pair of neighbouring stencils (x, theta, x, theta, x, theta, x).
PAIR_SIZE = STENCIL_SIZE + 4


@njit(cache=True)
def stencil_stretch_values(x: np.ndarray, rest_edge_lengths: np.ndarray) -> np.ndarray:
    """The centreline stretch at the interior nodes, eps_i = (|e| + |f|) / (|e-bar| + |f-bar|) - 1 (n,)."""
    lengths = np.empty(x.shape[0] - 1)
    for j in range(x.shape[0] - 1):
        total = 0.0
        for k in range(3):
            d = x[j + 1, k] - x[j, k]
            total += d * d
        lengths[j] = np.sqrt(total)
    eps = np.empty(x.shape[0] - 2)
    for i in range(eps.shape[0]):
        eps[i] = (lengths[i] + lengths[i + 1]) / (rest_edge_lengths[i] + rest_edge_lengths[i + 1]) - 1.0
    return eps


def stencil_stretch(x: np.ndarray, rest_edge_lengths: np.ndarray):
    """The centreline stretch at the interior nodes, eps_i = (|e| + |f|) / (|e-bar| + |f-bar|) - 1
    (n,), its gradient (n, 11) and Hessian (n, 11, 11) over the stencil's DOFs (theta entries 0)
    (compiled in rod_curvature.add_stretched_stencil_terms, its edge form)."""
    e = x[1:] - x[:-1]
    lengths = np.linalg.norm(e, axis=1)
    t = e / lengths[:, None]
    rest = rest_edge_lengths[:-1] + rest_edge_lengths[1:]
    eps = stencil_stretch_values(x, rest_edge_lengths)
    n = len(eps)
    grads = np.zeros((n, STENCIL_SIZE))
    grads[:, 0:3] = -t[:-1] / rest[:, None]
    grads[:, 4:7] = (t[:-1] - t[1:]) / rest[:, None]
    grads[:, 8:11] = t[1:] / rest[:, None]
    hessians = np.zeros((n, STENCIL_SIZE, STENCIL_SIZE))
    eye = np.eye(3)
    for edge, (a, b) in ((0, (slice(0, 3), slice(4, 7))), (1, (slice(4, 7), slice(8, 11)))):
        te = t[edge:edge + n]
        block = (eye[None] - te[:, :, None] * te[:, None, :]) / (lengths[edge:edge + n] * rest)[:, None, None]
        hessians[:, a, a] += block
        hessians[:, b, b] += block
        hessians[:, a, b] -= block
        hessians[:, b, a] -= block
    return eps, grads, hessians


def stencil_strain_blocks(x: np.ndarray, m1: np.ndarray, m2: np.ndarray):
    """The three strains' derivatives per stencil (rod_curvature.strain_derivatives): gradients
    (n, 3, 11) and Hessians (n, 3, 11, 11) in the order (kappa_n, kappa_g, tau)."""
    _, grads, hessians = strain_derivatives(x, m1, m2)
    return grads, hessians


def pair_blocks(grads: np.ndarray, hessians: np.ndarray, components: tuple[int, ...]):
    """Derivatives of the chosen strain components of stencils i and i + 1 (i = 0 .. n - 2) over
    the pair's 15 DOFs: gradients (n - 1, 2 c, 15) and Hessians (n - 1, 2 c, 15, 15), stencil i's
    components first. grads/hessians as from stencil_strain_blocks."""
    n = grads.shape[0]
    c = len(components)
    idx = list(components)
    pg = np.zeros((n - 1, 2 * c, PAIR_SIZE))
    ph = np.zeros((n - 1, 2 * c, PAIR_SIZE, PAIR_SIZE))
    s = STENCIL_SIZE
    pg[:, :c, :s] = grads[:-1][:, idx]
    pg[:, c:, 4:4 + s] = grads[1:][:, idx]
    ph[:, :c, :s, :s] = hessians[:-1][:, idx]
    ph[:, c:, 4:4 + s, 4:4 + s] = hessians[1:][:, idx]
    return pg, ph


@njit(cache=True)
def add_local_terms(bases, grads, hessians, first, second, n_dof, grad, band, want_hessian):
    """Adds sum_p E_p to grad and (want_hessian) to the lower band of an n_dof matrix.

    bases (P,) int: first DOF of each term's contiguous block; grads (P, k, D) and hessians
    (P, k, D, D): each strain's derivatives over the block; first (P, k) = de_p / ds_a and second
    (P, k, k) = d2e_p / ds_a ds_b. band is LAPACK's lower band form flattened: entry (r, c), r >= c,
    at band[(r - c) * n_dof + c]; the blocks must fit the band (D - 1 <= bandwidth). The Hessian is
    sum_c first_c H_c + sum_d (sum_c second_cd g_c) g_d^T, O(k D^2) per term."""
    n_terms, h, size = grads.shape
    mixed = np.empty((h, size))
    for p in range(n_terms):
        base = bases[p]
        for a in range(size):
            total = 0.0
            for c in range(h):
                total += first[p, c] * grads[p, c, a]
            grad[base + a] += total
        if not want_hessian:
            continue
        for d in range(h):
            for a in range(size):
                total = 0.0
                for c in range(h):
                    total += second[p, c, d] * grads[p, c, a]
                mixed[d, a] = total
        for a in range(size):
            for b in range(a + 1):
                total = 0.0
                for c in range(h):
                    total += first[p, c] * hessians[p, c, a, b] + mixed[c, a] * grads[p, c, b]
                band[(a - b) * n_dof + base + b] += total
