"""Smoothed membrane of a triangle mesh: constant-strain triangles averaged over patches.

The membrane-locking treatment of the mid-edge plate (ddg.models.midedge_plate). A
flat constant-strain triangle (ddg.energies.membrane) cannot follow a curved, twisted
inextensible deformation whose rulings do not lie along mesh edges without changing its edge
lengths; the spurious membrane energy, of order E b (h^2 kappa^2)^2 per area against the bending
energy E b^3 kappa^2, stiffens a coarse thin plate by (h^2 kappa / b)^2 (at L/b = 1181 and 8 rows
across W/L = 1/6 about 25): the pitchfork U -> US is delayed, folds appear on the way to S.

As the shell reference's partial selective reduced integration (alpha = b^2 / h^2 of the full
membrane, the rest under-integrated), this energy weakens the membrane constraints by averaging:
each patch P (the triangles around a node, `node_patches`) gets the area-weighted mean of its
triangles' Green strains,

  eps_P = sum_f w_Pf eps_f,   w_Pf = (A_f / 3) / A_P,   A_P = sum_f A_f / 3,

and the energy is sum_P A_P W(eps_P) with the plane-stress St Venant-Kirchhoff density
W(eps) = E b / (2 (1 - nu^2)) [nu tr(eps)^2 + (1 - nu) tr(eps^2)], i.e. 1/2 eps^T C eps in Voigt
form (eps11, eps12, eps22) with C = E b / (1 - nu^2) [[1, 0, nu], [0, 2 (1 - nu), 0], [nu, 0, 1]].
A uniform strain gives exactly the constant-strain triangles' energy (the patches' areas add up to
the plate's), so the continuum limit, the elastica and the rod limit are unchanged. The model
mixes alpha times the full membrane with (1 - alpha) times this one (ddg.models.midedge_plate).

Per triangle eps_f = T_f delta_f with delta_f = (a11 - abar11, a12 - abar12, a22 - abar22) the
change of its edge-vector metric (ddg.energies.membrane) and the constant 3 x 3
T_f = voigt(1/2 R^-T S_k R^-1) (R = [E1 E2] the reference edge vectors, S_k the symmetric basis):
eps_f is quadratic in the positions, so grad = G^T s, hess = A_P G^T C G + sum_f w_Pf
sum_k (T_f^T s)_k Hess(delta_fk), with G = d eps_P / dq and s = A_P C eps_P.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..assembly.band_scatter import add_symmetric_block

_S = np.array([[[1.0, 0.0], [0.0, 0.0]], [[0.0, 1.0], [1.0, 0.0]], [[0.0, 0.0], [0.0, 1.0]]])


def strain_maps(nodes: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(T (F, 3, 3), area (F,)): eps_f (Voigt, global reference axes) = T_f delta_f, delta_f the
    change of the metric of ddg.energies.membrane.face_membrane_matrices."""
    p = nodes[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    R = np.stack([e1, e2], axis=2)  # columns E1, E2
    Rinv = np.linalg.inv(R)
    eps = 0.5 * np.einsum("tia,kij,tjb->tkab", Rinv, _S, Rinv)  # (F, k, 2, 2)
    T = np.stack([eps[:, :, 0, 0], eps[:, :, 0, 1], eps[:, :, 1, 1]], axis=1)  # (F, voigt, k)
    return np.ascontiguousarray(T), area


def node_patches(triangles: np.ndarray, area: np.ndarray, active: np.ndarray | None = None):
    """Node patches of the `active` triangles (default all): (pointer (P + 1,), patch triangles,
    weights w_Pf, patch areas A_P), one patch per node that an active triangle touches."""
    active = np.ones(len(triangles), dtype=bool) if active is None else np.asarray(active, dtype=bool)
    faces = np.flatnonzero(active)
    node = triangles[faces].ravel()
    face = np.repeat(faces, 3)
    order = np.argsort(node, kind="stable")
    node, face = node[order], face[order]
    _, start = np.unique(node, return_index=True)
    pointer = np.r_[start, len(node)].astype(np.int64)
    share = area[face] / 3.0
    patch_area = np.add.reduceat(share, start)
    weights = share / np.repeat(patch_area, np.diff(pointer))
    return pointer, face.astype(np.int64), weights, patch_area


def plane_stress_matrix(young_modulus: float, thickness: float, poisson_ratio: float) -> np.ndarray:
    """C (3 x 3): W = 1/2 eps^T C eps for eps = (eps11, eps12, eps22), plane-stress St Venant-Kirchhoff."""
    nu = poisson_ratio
    return young_modulus * thickness / (1.0 - nu * nu) * np.array([[1.0, 0.0, nu], [0.0, 2.0 * (1.0 - nu), 0.0],
                                                                    [nu, 0.0, 1.0]])


@njit(cache=True)
def add_smoothed_membrane_terms(x, triangles, T, abar, pointer, patch_faces, weights, patch_area, C, scale,
                                vertex_dof, n, grad, band, want_gradient, want_hessian):
    """scale * sum_P A_P W(eps_P); adds scale times its gradient into grad (n,) and its Hessian
    into the flattened lower band (ddg.assembly.band_scatter). vertex_dof (N, 3)."""
    energy = 0.0
    max_faces = 0
    for P in range(pointer.shape[0] - 1):
        max_faces = max(max_faces, pointer[P + 1] - pointer[P])
    width = 3 * (2 * max_faces + 1)
    local_nodes = np.empty(2 * max_faces + 1, dtype=np.int64)
    slot = np.empty((max_faces, 3), dtype=np.int64)
    deltas = np.empty((max_faces, 3))
    J = np.empty((max_faces, 3, 9))
    G = np.empty((3, width))
    eps = np.empty(3)
    s = np.empty(3)
    u = np.empty(3)
    dofs = np.empty(width, dtype=np.int64)
    CG = np.empty((3, width))
    block = np.empty((width, width))
    for P in range(pointer.shape[0] - 1):
        first, last = pointer[P], pointer[P + 1]
        count = 0
        eps[:] = 0.0
        for m in range(last - first):
            f = patch_faces[first + m]
            for v in range(3):
                node = triangles[f, v]
                k = 0
                while k < count and local_nodes[k] != node:
                    k += 1
                if k == count:
                    local_nodes[count] = node
                    count += 1
                slot[m, v] = k
            p0, p1, p2 = triangles[f, 0], triangles[f, 1], triangles[f, 2]
            e1 = x[p1] - x[p0]
            e2 = x[p2] - x[p0]
            deltas[m, 0] = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2] - abar[f, 0]
            deltas[m, 1] = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2] - abar[f, 1]
            deltas[m, 2] = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2] - abar[f, 2]
            w = weights[first + m]
            for a in range(3):
                eps[a] += w * (T[f, a, 0] * deltas[m, 0] + T[f, a, 1] * deltas[m, 1] + T[f, a, 2] * deltas[m, 2])
            if want_gradient:
                for k in range(3):
                    J[m, 0, k], J[m, 0, 3 + k], J[m, 0, 6 + k] = -2.0 * e1[k], 2.0 * e1[k], 0.0
                    J[m, 1, k], J[m, 1, 3 + k], J[m, 1, 6 + k] = -(e1[k] + e2[k]), e2[k], e1[k]
                    J[m, 2, k], J[m, 2, 3 + k], J[m, 2, 6 + k] = -2.0 * e2[k], 0.0, 2.0 * e2[k]
        A = patch_area[P]
        for a in range(3):
            s[a] = A * (C[a, 0] * eps[0] + C[a, 1] * eps[1] + C[a, 2] * eps[2])
        energy += 0.5 * (s[0] * eps[0] + s[1] * eps[1] + s[2] * eps[2])
        if not want_gradient:
            continue
        nl = 3 * count
        G[:, :nl] = 0.0
        for m in range(last - first):
            f = patch_faces[first + m]
            w = weights[first + m]
            for a in range(3):
                for c in range(9):
                    col = 3 * slot[m, c // 3] + c % 3
                    G[a, col] += w * (T[f, a, 0] * J[m, 0, c] + T[f, a, 1] * J[m, 1, c] + T[f, a, 2] * J[m, 2, c])
        for i in range(count):
            for k in range(3):
                dofs[3 * i + k] = vertex_dof[local_nodes[i], k]
        for c in range(nl):
            grad[dofs[c]] += scale * (G[0, c] * s[0] + G[1, c] * s[1] + G[2, c] * s[2])
        if not want_hessian:
            continue
        for a in range(3):
            for c in range(nl):
                CG[a, c] = C[a, 0] * G[0, c] + C[a, 1] * G[1, c] + C[a, 2] * G[2, c]
        for r in range(nl):
            for c in range(nl):
                block[r, c] = A * (G[0, r] * CG[0, c] + G[1, r] * CG[1, c] + G[2, r] * CG[2, c])
        for m in range(last - first):
            f = patch_faces[first + m]
            w = weights[first + m]
            for k in range(3):
                u[k] = w * (T[f, 0, k] * s[0] + T[f, 1, k] * s[1] + T[f, 2, k] * s[2])
            # constant Hessians of delta (a11 on p0, p1; a12; a22 on p0, p2), times u_k
            s11, s12, s22 = 2.0 * u[0], u[1], 2.0 * u[2]
            i0, i1, i2 = 3 * slot[m, 0], 3 * slot[m, 1], 3 * slot[m, 2]
            for k in range(3):
                block[i0 + k, i0 + k] += s11 + 2.0 * s12 + s22
                block[i1 + k, i1 + k] += s11
                block[i2 + k, i2 + k] += s22
                block[i0 + k, i1 + k] -= s11 + s12
                block[i1 + k, i0 + k] -= s11 + s12
                block[i0 + k, i2 + k] -= s22 + s12
                block[i2 + k, i0 + k] -= s22 + s12
                block[i1 + k, i2 + k] += s12
                block[i2 + k, i1 + k] += s12
        for r in range(nl):
            for c in range(nl):
                block[r, c] *= scale
        add_symmetric_block(band, n, dofs[:nl], block[:nl, :nl])
    return scale * energy
