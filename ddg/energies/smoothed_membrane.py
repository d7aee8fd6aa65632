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
    """Node patches of the `active` triangles (default all), one per node that an active triangle
    touches: (pointer (P + 1,), patch triangles, weights w_Pf, patch areas A_P, node_pointer (P + 1,),
    patch nodes (each patch's nodes, its own first), face slots (per patch triangle, the rows of
    its three vertices in its patch's nodes))."""
    active = np.ones(len(triangles), dtype=bool) if active is None else np.asarray(active, dtype=bool)
    faces = np.flatnonzero(active)
    node = triangles[faces].ravel()
    face = np.repeat(faces, 3)
    order = np.argsort(node, kind="stable")
    node, face = node[order], face[order]
    centres, start = np.unique(node, return_index=True)
    pointer = np.r_[start, len(node)].astype(np.int64)
    share = area[face] / 3.0
    patch_area = np.add.reduceat(share, start)
    weights = share / np.repeat(patch_area, np.diff(pointer))
    node_pointer = [0]
    patch_nodes, face_slots = [], np.empty((len(face), 3), dtype=np.int64)
    for P, centre in enumerate(centres):
        members = [int(centre)]
        for m in range(pointer[P], pointer[P + 1]):
            for v in range(3):
                vertex = int(triangles[face[m], v])
                if vertex not in members:
                    members.append(vertex)
                face_slots[m, v] = members.index(vertex)
        patch_nodes += members
        node_pointer.append(len(patch_nodes))
    return (pointer, face.astype(np.int64), weights, patch_area, np.array(node_pointer, dtype=np.int64),
            np.array(patch_nodes, dtype=np.int64), face_slots)


def plane_stress_matrix(young_modulus: float, thickness: float, poisson_ratio: float) -> np.ndarray:
    """C (3 x 3): W = 1/2 eps^T C eps for eps = (eps11, eps12, eps22), plane-stress St Venant-Kirchhoff."""
    nu = poisson_ratio
    return young_modulus * thickness / (1.0 - nu * nu) * np.array([[1.0, 0.0, nu], [0.0, 2.0 * (1.0 - nu), 0.0],
                                                                    [nu, 0.0, 1.0]])


@njit(cache=True, forceinline=True)
def _lower_gcg(A, C, G, CG, block, nl):
    """block[r, c] = A (G^T C G)[r, c] for c <= r < nl (CG (3, nl) scratch)."""
    for a in range(3):
        ca0, ca1, ca2 = A * C[a, 0], A * C[a, 1], A * C[a, 2]
        for c in range(nl):
            CG[a, c] = ca0 * G[0, c] + ca1 * G[1, c] + ca2 * G[2, c]
    for r in range(nl):
        g0, g1, g2 = G[0, r], G[1, r], G[2, r]
        for c in range(r + 1):
            block[r, c] = g0 * CG[0, c] + g1 * CG[1, c] + g2 * CG[2, c]


@njit(cache=True)
def add_smoothed_membrane_terms(x, triangles, T, abar, pointer, patch_faces, weights, patch_area, node_pointer,
                                patch_nodes, face_slots, C, scale, vertex_dof, n, grad, band, want_gradient,
                                want_hessian):
    """scale * sum_P A_P W(eps_P); adds scale times its gradient into grad (n,) and its Hessian
    into the flattened lower band (ddg.assembly.band_scatter). The patches as `node_patches` gives
    them; vertex_dof (N, 3).

    A patch's local DOFs are its nodes' coordinates (3 per node, in patch_nodes' order); its
    Hessian is formed on the lower triangle of the local block only and added into the band at
    |r - c| n + min(r, c)."""
    energy = 0.0
    max_nodes = 0
    for P in range(node_pointer.shape[0] - 1):
        max_nodes = max(max_nodes, node_pointer[P + 1] - node_pointer[P])
    width = 3 * max_nodes
    G = np.zeros((3, width))
    CG = np.empty((3, width))
    dofs = np.empty(width, dtype=np.int64)
    block = np.empty((width, width))
    eps = np.empty(3)
    s = np.empty(3)
    for P in range(pointer.shape[0] - 1):
        first, last = pointer[P], pointer[P + 1]
        eps[0], eps[1], eps[2] = 0.0, 0.0, 0.0
        for m in range(first, last):
            f = patch_faces[m]
            p0, p1, p2 = triangles[f, 0], triangles[f, 1], triangles[f, 2]
            a0, a1, a2 = x[p1, 0] - x[p0, 0], x[p1, 1] - x[p0, 1], x[p1, 2] - x[p0, 2]
            b0, b1, b2 = x[p2, 0] - x[p0, 0], x[p2, 1] - x[p0, 1], x[p2, 2] - x[p0, 2]
            d0 = a0 * a0 + a1 * a1 + a2 * a2 - abar[f, 0]
            d1 = a0 * b0 + a1 * b1 + a2 * b2 - abar[f, 1]
            d2 = b0 * b0 + b1 * b1 + b2 * b2 - abar[f, 2]
            w = weights[m]
            for a in range(3):
                eps[a] += w * (T[f, a, 0] * d0 + T[f, a, 1] * d1 + T[f, a, 2] * d2)
            if want_gradient:
                # G = d eps_P / dq: w T_f J_f, J_f the rows d a11 = 2 e1 . d e1, d a12 = e1 . d e2 + e2 . d e1,
                # d a22 = 2 e2 . d e2 (e1 = p1 - p0, e2 = p2 - p0)
                i0, i1, i2 = 3 * face_slots[m, 0], 3 * face_slots[m, 1], 3 * face_slots[m, 2]
                for a in range(3):
                    t0, t1, t2 = w * T[f, a, 0], w * T[f, a, 1], w * T[f, a, 2]
                    for k, ek, fk in ((0, a0, b0), (1, a1, b1), (2, a2, b2)):
                        u1 = 2.0 * t0 * ek + t1 * fk
                        u2 = t1 * ek + 2.0 * t2 * fk
                        G[a, i1 + k] += u1
                        G[a, i2 + k] += u2
                        G[a, i0 + k] -= u1 + u2
        A = scale * patch_area[P]
        for a in range(3):
            s[a] = A * (C[a, 0] * eps[0] + C[a, 1] * eps[1] + C[a, 2] * eps[2])
        energy += 0.5 * (s[0] * eps[0] + s[1] * eps[1] + s[2] * eps[2])
        if not want_gradient:
            continue
        nodes = node_pointer[P]
        nl = 3 * (node_pointer[P + 1] - nodes)
        for i in range(nl // 3):
            node = patch_nodes[nodes + i]
            for k in range(3):
                dofs[3 * i + k] = vertex_dof[node, k]
        for c in range(nl):
            grad[dofs[c]] += G[0, c] * s[0] + G[1, c] * s[1] + G[2, c] * s[2]
        if want_hessian:
            if nl == 21:  # an interior patch of 6 triangles: compiled with its loop bounds known
                _lower_gcg(A, C, G, CG, block, 21)
            else:
                _lower_gcg(A, C, G, CG, block, nl)
            for m in range(first, last):
                f = patch_faces[m]
                w = weights[m]
                # constant Hessians of delta (a11 on p0, p1; a12; a22 on p0, p2), times u = w T_f^T s
                u0 = w * (T[f, 0, 0] * s[0] + T[f, 1, 0] * s[1] + T[f, 2, 0] * s[2])
                u1 = w * (T[f, 0, 1] * s[0] + T[f, 1, 1] * s[1] + T[f, 2, 1] * s[2])
                u2 = w * (T[f, 0, 2] * s[0] + T[f, 1, 2] * s[1] + T[f, 2, 2] * s[2])
                s11, s12, s22 = 2.0 * u0, u1, 2.0 * u2
                i0, i1, i2 = 3 * face_slots[m, 0], 3 * face_slots[m, 1], 3 * face_slots[m, 2]
                for k in range(3):
                    block[i0 + k, i0 + k] += s11 + 2.0 * s12 + s22
                    block[i1 + k, i1 + k] += s11
                    block[i2 + k, i2 + k] += s22
                    block[max(i0, i1) + k, min(i0, i1) + k] -= s11 + s12
                    block[max(i0, i2) + k, min(i0, i2) + k] -= s22 + s12
                    block[max(i1, i2) + k, min(i1, i2) + k] += s12
            for r in range(nl):
                dr = dofs[r]
                for c in range(r + 1):
                    dc = dofs[c]
                    band[abs(dr - dc) * n + min(dr, dc)] += block[r, c]
        for a in range(3):
            for c in range(nl):
                G[a, c] = 0.0
    return energy
