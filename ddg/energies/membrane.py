"""Membrane energy of a triangle mesh: constant-strain triangles of an isotropic material.

The membrane of the mid-edge plate (ddg.models.midedge_plate); the paper's plate keeps its
edge springs (Eq. 11a, ddg.energies.stretch), whose continuum limit has Poisson ratio 1/3.
Per triangle with deformed edge vectors e1 = p1 - p0, e2 = p2 - p0, metric a = [e_j . e_k] and
reference metric abar, the Green strain (mixed) is eps = abar^-1 (a - abar) / 2 and

  E_f = A (E b / (2 (1 - nu^2))) [nu tr(eps)^2 + (1 - nu) tr(eps^2)]   (plane stress, St Venant-Kirchhoff).

With delta = (a11 - abar11, a12 - abar12, a22 - abar22) this is 1/2 delta^T C_f delta with a
constant 3 x 3 C_f (`face_membrane_matrices`): tr(abar^-1 Delta) = w . delta with
w = (B11, 2 B12, B22), B = abar^-1, and tr(B Delta B Delta) = delta^T P delta with
P_ab = tr(B S_a B S_b) for the symmetric basis S. delta is quadratic in the positions
(d a11 = 2 e1 . d e1, d a12 = e1 . d e2 + e2 . d e1, d a22 = 2 e2 . d e2), so
grad = J^T C delta and hess = J^T C J + sum_k (C delta)_k Hess(a_k) with constant Hess(a_k).
"""
from __future__ import annotations

import numpy as np
from numba import njit

_S = np.array([[[1.0, 0.0], [0.0, 0.0]], [[0.0, 1.0], [1.0, 0.0]], [[0.0, 0.0], [0.0, 1.0]]])


def face_membrane_matrices(nodes: np.ndarray, triangles: np.ndarray, young_modulus: float, thickness: float,
                           poisson_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """(C (T, 3, 3), abar (T, 3) = (abar11, abar12, abar22)) of the reference triangles (nodes (N, 2))."""
    nu = poisson_ratio
    p = nodes[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    a11, a12, a22 = (np.einsum("ti,ti->t", e1, e1), np.einsum("ti,ti->t", e1, e2), np.einsum("ti,ti->t", e2, e2))
    abar = np.stack([np.stack([a11, a12], axis=1), np.stack([a12, a22], axis=1)], axis=1)
    B = np.linalg.inv(abar)
    w = np.stack([B[:, 0, 0], 2.0 * B[:, 0, 1], B[:, 1, 1]], axis=1)
    BS = np.einsum("tij,ajk->taik", B, _S)
    P = np.einsum("taij,tbji->tab", BS, BS)
    coefficient = area * young_modulus * thickness / (4.0 * (1.0 - nu * nu))
    C = coefficient[:, None, None] * (nu * np.einsum("ta,tb->tab", w, w) + (1.0 - nu) * P)
    return C, np.stack([a11, a12, a22], axis=1)


@njit(cache=True)
def add_membrane_terms(x, triangles, C, abar, vertex_dof, n, grad, band, want_gradient, want_hessian):
    """Membrane energy sum_f 1/2 delta^T C_f delta; adds the gradient into grad (n,) and the
    Hessian into the flattened lower band (ddg.assembly.band_scatter). vertex_dof (N, 3).

    The 9 x 9 Hessian of a triangle is formed on its lower triangle only (local order p0, p1, p2)
    and added into the band at |r - c| n + min(r, c)."""
    energy = 0.0
    dofs = np.empty(9, dtype=np.int64)
    J = np.empty((3, 9))
    CJ = np.empty((3, 9))
    block = np.empty((9, 9))
    for f in range(triangles.shape[0]):
        p0, p1, p2 = triangles[f, 0], triangles[f, 1], triangles[f, 2]
        a0, a1, a2 = x[p1, 0] - x[p0, 0], x[p1, 1] - x[p0, 1], x[p1, 2] - x[p0, 2]
        b0, b1, b2 = x[p2, 0] - x[p0, 0], x[p2, 1] - x[p0, 1], x[p2, 2] - x[p0, 2]
        d0 = a0 * a0 + a1 * a1 + a2 * a2 - abar[f, 0]
        d1 = a0 * b0 + a1 * b1 + a2 * b2 - abar[f, 1]
        d2 = b0 * b0 + b1 * b1 + b2 * b2 - abar[f, 2]
        Cd0 = C[f, 0, 0] * d0 + C[f, 0, 1] * d1 + C[f, 0, 2] * d2
        Cd1 = C[f, 1, 0] * d0 + C[f, 1, 1] * d1 + C[f, 1, 2] * d2
        Cd2 = C[f, 2, 0] * d0 + C[f, 2, 1] * d1 + C[f, 2, 2] * d2
        energy += 0.5 * (d0 * Cd0 + d1 * Cd1 + d2 * Cd2)
        if not want_gradient:
            continue
        # a11 = e1.e1, a12 = e1.e2, a22 = e2.e2 in (p0, p1, p2), e1 = p1 - p0, e2 = p2 - p0
        for k, ek, fk in ((0, a0, b0), (1, a1, b1), (2, a2, b2)):
            dofs[k] = vertex_dof[p0, k]
            dofs[3 + k] = vertex_dof[p1, k]
            dofs[6 + k] = vertex_dof[p2, k]
            J[0, k], J[0, 3 + k], J[0, 6 + k] = -2.0 * ek, 2.0 * ek, 0.0
            J[1, k], J[1, 3 + k], J[1, 6 + k] = -(ek + fk), fk, ek
            J[2, k], J[2, 3 + k], J[2, 6 + k] = -2.0 * fk, 0.0, 2.0 * fk
        for c in range(9):
            grad[dofs[c]] += J[0, c] * Cd0 + J[1, c] * Cd1 + J[2, c] * Cd2
        if not want_hessian:
            continue
        for a in range(3):
            for c in range(9):
                CJ[a, c] = C[f, a, 0] * J[0, c] + C[f, a, 1] * J[1, c] + C[f, a, 2] * J[2, c]
        for r in range(9):
            j0, j1, j2 = J[0, r], J[1, r], J[2, r]
            for c in range(r + 1):
                block[r, c] = j0 * CJ[0, c] + j1 * CJ[1, c] + j2 * CJ[2, c]
        # constant Hessians of a11 (on p0, p1), a22 (on p0, p2) and a12, times (C delta)_k
        s11, s12, s22 = 2.0 * Cd0, Cd1, 2.0 * Cd2
        for k in range(3):
            block[k, k] += s11 + 2.0 * s12 + s22
            block[3 + k, 3 + k] += s11
            block[6 + k, 6 + k] += s22
            block[3 + k, k] -= s11 + s12
            block[6 + k, k] -= s22 + s12
            block[6 + k, 3 + k] += s12
        for r in range(9):
            dr = dofs[r]
            for c in range(r + 1):
                dc = dofs[c]
                band[abs(dr - dc) * n + min(dr, dc)] += block[r, c]
    return energy
