"""The mid-edge plate's compiled kernels against a reference: the same energies, gradients and Hessians.

The kernels (ddg.energies.membrane, .smoothed_membrane, .midedge_bending) were rewritten for speed
(issue 50 item 2): psi's derivatives in closed form from the hinge's two face normals, heights and
edge (module docstring of ddg.energies.midedge_bending) instead of atan2 of bilinear forms; each
element's Hessian formed on its lower triangle and added into the band without a dense block per
element; the triangles visited in order of x. None of this changes the physics, so each kernel's
energy, gradient and Hessian must equal the reference's to round-off on deformed states of several
meshes. The reference below is the implementation before the rewrite (commit fc76322): psi =
atan2(Y, X) with X = u_a . u_b, Y = (u_b x u_a) . e / |e| differentiated through the bilinear
normals u, and every element's dense block scattered by ddg.assembly.band_scatter.add_symmetric_block.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from ddg.assembly.band_scatter import add_symmetric_block
from ddg.energies.membrane import add_membrane_terms
from ddg.energies.midedge_bending import ROLE_FIRST, ROLE_SECOND, add_midedge_terms
from ddg.energies.smoothed_membrane import add_smoothed_membrane_terms
from ddg.geometry.plate_mesh import PlateMesh, ghost_clamp_mesh
from ddg.geometry.strip import Strip
from ddg.models.midedge_plate import MidedgePlateModel

#: Round-off bound, relative to the largest entry of the compared array: the kernels add the same
#: terms in another order and form psi's derivatives by another route; measured up to 2.3e-15 (the
#: bending energy; gradients and Hessians up to 1.4e-15) on the meshes and states below, so a few
#: times that; a change of the physics (a term dropped or misweighed) is O(1) of the entries.
ROUND_OFF = 1e-14

#: (W/L, rows): the issue's strip at two resolutions and a wider strip of another mesh shape.
MESHES = ((1 / 6, 8), (1 / 6, 12), (1 / 2, 8))


# ---------------------------------------------------------------------------- the reference
@njit(cache=True, forceinline=True)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, forceinline=True)
def _normal_jacobian(p, slots, J):
    """J (3, 12) = du/dq of u = (p1 - p0) x (p2 - p0) for the triangle on hinge slots (s0, s1, s2):
    du = sum_i dp_i x c_i, c_i = p_{i+1} - p_{i+2}, i.e. du/dp_i = -[c_i]x."""
    J[:, :] = 0.0
    for i in range(3):
        a, b = slots[(i + 1) % 3], slots[(i + 2) % 3]
        c0, c1, c2 = p[a, 0] - p[b, 0], p[a, 1] - p[b, 1], p[a, 2] - p[b, 2]
        col = 3 * slots[i]
        # -[c]x = [[0, c2, -c1], [-c2, 0, c0], [c1, -c0, 0]]
        J[0, col + 1], J[0, col + 2] = c2, -c1
        J[1, col + 0], J[1, col + 2] = -c2, c0
        J[2, col + 0], J[2, col + 1] = c1, -c0


@njit(cache=True, forceinline=True)
def _add_bilinear(slots, w, scale, H):
    """H += scale * Hessian of w . u in the 12 hinge coordinates (u of the triangle on `slots`):
    blocks (i, i+1) = -[w]x, (i+1, i) = +[w]x."""
    # -[w]x = [[0, w2, -w1], [-w2, 0, w0], [w1, -w0, 0]] (scalars: no array per call)
    w0, w1, w2 = scale * w[0], scale * w[1], scale * w[2]
    for i in range(3):
        r, c = 3 * slots[i], 3 * slots[(i + 1) % 3]
        H[r + 0, c + 1] += w2
        H[c + 1, r + 0] += w2
        H[r + 0, c + 2] -= w1
        H[c + 2, r + 0] -= w1
        H[r + 1, c + 0] -= w2
        H[c + 0, r + 1] -= w2
        H[r + 1, c + 2] += w0
        H[c + 2, r + 1] += w0
        H[r + 2, c + 0] += w1
        H[c + 0, r + 2] += w1
        H[r + 2, c + 1] -= w0
        H[c + 1, r + 2] -= w0


_SLOTS_A = np.array([0, 1, 2], dtype=np.int64)  # a = (v0, v1, o_a)
_SLOTS_B = np.array([1, 0, 3], dtype=np.int64)  # b = (v1, v0, o_b)
_JE = np.hstack([-np.eye(3), np.eye(3), np.zeros((3, 6))])  # de/dq of the hinge edge e = v1 - v0


@njit(cache=True, forceinline=True)
def _add_transposed_products(J1, J2, t3, r, scale, H):
    """H += scale (J1^T (-[r]x) J2 + its transpose): the second variation (dp x dq) . r; t3 (3, 12) scratch."""
    for k in range(12):
        q0, q1, q2 = J2[0, k], J2[1, k], J2[2, k]
        t3[0, k] = r[2] * q1 - r[1] * q2
        t3[1, k] = r[0] * q2 - r[2] * q0
        t3[2, k] = r[1] * q0 - r[0] * q1
    for i in range(12):
        a0, a1, a2 = J1[0, i], J1[1, i], J1[2, i]
        if a0 == 0.0 and a1 == 0.0 and a2 == 0.0:
            continue
        for k in range(12):
            v = scale * (a0 * t3[0, k] + a1 * t3[1, k] + a2 * t3[2, k])
            H[i, k] += v
            H[k, i] += v


@njit(cache=True)
def hinge_angle_into(p, want_gradient, want_hessian, grad, hess, Ja, Jb, HX, HT, t3, dX, dT, dl, dY, vec):
    """hinge_angle with the caller's scratch arrays (allocated once per assembly, not per hinge)."""
    e0, e1, e2 = p[1, 0] - p[0, 0], p[1, 1] - p[0, 1], p[1, 2] - p[0, 2]
    w0, w1, w2 = p[2, 0] - p[0, 0], p[2, 1] - p[0, 1], p[2, 2] - p[0, 2]
    ua, ub, e, ubxua, uaxe, exub = vec[0], vec[1], vec[2], vec[3], vec[4], vec[5]
    ua[0], ua[1], ua[2] = e1 * w2 - e2 * w1, e2 * w0 - e0 * w2, e0 * w1 - e1 * w0
    f0, f1, f2 = -e0, -e1, -e2
    w0, w1, w2 = p[3, 0] - p[1, 0], p[3, 1] - p[1, 1], p[3, 2] - p[1, 2]
    ub[0], ub[1], ub[2] = f1 * w2 - f2 * w1, f2 * w0 - f0 * w2, f0 * w1 - f1 * w0
    e[0], e[1], e[2] = e0, e1, e2
    length = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    X = ua[0] * ub[0] + ua[1] * ub[1] + ua[2] * ub[2]
    _cross(ub, ua, ubxua)
    T = ubxua[0] * e0 + ubxua[1] * e1 + ubxua[2] * e2
    Y = T / length
    psi = math.atan2(Y, X)
    if not want_gradient:
        return psi
    _normal_jacobian(p, _SLOTS_A, Ja)
    _normal_jacobian(p, _SLOTS_B, Jb)
    _cross(ua, e, uaxe)
    _cross(e, ub, exub)
    # Je = [-I, I, 0, 0] (e = v1 - v0) is applied by hand below
    for i in range(12):
        dX[i] = Ja[0, i] * ub[0] + Ja[1, i] * ub[1] + Ja[2, i] * ub[2] \
            + Jb[0, i] * ua[0] + Jb[1, i] * ua[1] + Jb[2, i] * ua[2]
        dT[i] = Jb[0, i] * uaxe[0] + Jb[1, i] * uaxe[1] + Jb[2, i] * uaxe[2] \
            + Ja[0, i] * exub[0] + Ja[1, i] * exub[1] + Ja[2, i] * exub[2]
        dl[i] = 0.0
    for k in range(3):
        dT[k] -= ubxua[k]
        dT[3 + k] += ubxua[k]
        dl[k] = -e[k] / length
        dl[3 + k] = e[k] / length
    R2 = X * X + Y * Y
    for i in range(12):
        dY[i] = dT[i] / length - T * dl[i] / (length * length)
        grad[i] = (X * dY[i] - Y * dX[i]) / R2
    if not want_hessian:
        return psi
    HX[:, :] = 0.0
    _add_bilinear(_SLOTS_A, ub, 1.0, HX)
    _add_bilinear(_SLOTS_B, ua, 1.0, HX)
    for i in range(12):
        for k in range(12):
            v = Ja[0, i] * Jb[0, k] + Ja[1, i] * Jb[1, k] + Ja[2, i] * Jb[2, k]
            HX[i, k] += v
            HX[k, i] += v
    HT[:, :] = 0.0
    _add_bilinear(_SLOTS_B, uaxe, 1.0, HT)
    _add_bilinear(_SLOTS_A, exub, 1.0, HT)
    _add_transposed_products(Jb, Ja, t3, e, 1.0, HT)
    # the pairs with de: (du_a x de) . u_b and (de x du_b) . u_a, de = dv1 - dv0
    _add_transposed_products(Ja, _JE, t3, ub, 1.0, HT)
    _add_transposed_products(_JE, Jb, t3, ua, 1.0, HT)
    inv_l = 1.0 / length
    inv_l2 = inv_l * inv_l
    inv_l3 = inv_l2 * inv_l
    inv_r2 = 1.0 / R2
    inv_r4 = inv_r2 * inv_r2
    # per-index factors hoisted out of the 12 x 12 loop (t3 is free scratch here):
    # t3[0] = g = X dY - Y dX, t3[1] = 2 X dX + 2 Y dY
    for i in range(12):
        t3[0, i] = X * dY[i] - Y * dX[i]
        t3[1, i] = 2.0 * X * dX[i] + 2.0 * Y * dY[i]
    for i in range(12):
        gi, ci, dTi, dli = t3[0, i], t3[1, i], dT[i], dl[i]
        for k in range(i, 12):
            # Hessian of l = |e|: Je^T (I - e e^T / l^2) Je / l, nonzero on the (v0, v1) blocks
            hl = 0.0
            if i < 6 and k < 6:
                a, b = i % 3, k % 3
                sign = (1.0 if (i < 3) == (k < 3) else -1.0)
                hl = sign * ((1.0 if a == b else 0.0) - e[a] * e[b] * inv_l2) * inv_l
            hy = (HT[i, k] * inv_l - (dTi * dl[k] + dli * dT[k]) * inv_l2 - T * hl * inv_l2
                  + 2.0 * T * dli * dl[k] * inv_l3)
            # the antisymmetric terms dY_i dX_k - dX_i dY_k cancel in the symmetrised sum
            common = (X * hy - Y * HX[i, k]) * inv_r2
            v = common - 0.5 * (gi * t3[1, k] + t3[0, k] * ci) * inv_r4
            hess[i, k] = v
            hess[k, i] = v
    return psi



@njit(cache=True)
def reference_bending(x, theta, triangles, face_edges, face_roles, hinge_of_edge, hinges, K,
                      vertex_dof, edge_dof, n, grad, band, want_gradient, want_hessian):
    """Bending energy sum_f 1/2 phi_f^T K_f phi_f of the mid-edge plate; adds its gradient into
    grad (n,) and its Hessian into the lower band (flattened, ddg.assembly.band_scatter).

    x (N, 3) positions, theta (E,) edge angles; face_edges (T, 3) the edge opposite each vertex,
    face_roles (T, 3) ROLE_FIRST / ROLE_SECOND, hinge_of_edge (E,) the edge's row in hinges (H, 4)
    = (v0, v1, o_a, o_b) with a its first triangle (-1 for a free edge); K (T, 3, 3);
    vertex_dof (N, 3) and edge_dof (E,) the global DOF numbers."""
    energy = 0.0
    # stencil: the triangle's 3 vertices, the far vertex o_a of each edge it is second on, 3 thetas
    dofs = np.empty(21, dtype=np.int64)
    J = np.empty((3, 21))
    hloc = np.empty((12, 12))
    gloc = np.empty(12)
    pts = np.empty((4, 3))
    slot_of = np.empty(4, dtype=np.int64)
    block = np.empty((21, 21))
    gstencil = np.empty(21)
    phi = np.empty(3)
    psis_hess = np.empty((3, 12, 12))
    psis_slots = np.empty((3, 4), dtype=np.int64)
    Ja, Jb, HX, HT, t3, dX, dT, dl, dY = (np.empty((3, 12)), np.empty((3, 12)), np.empty((12, 12)),
                                          np.empty((12, 12)), np.empty((3, 12)), np.empty(12), np.empty(12),
                                          np.empty(12), np.empty(12))
    kphi = np.empty(3)
    KJ = np.empty((3, 21))
    vec = np.empty((6, 3))
    for f in range(triangles.shape[0]):
        m = 0
        for a in range(3):
            for k in range(3):
                dofs[m] = vertex_dof[triangles[f, a], k]
                m += 1
        J[:, :] = 0.0
        for i in range(3):  # stencil slots 9, 10, 11: the thetas
            e = face_edges[f, i]
            dofs[9 + i] = edge_dof[e]
            if face_roles[f, i] == ROLE_FIRST:
                phi[i] = theta[e]
                J[i, 9 + i] = 1.0
            else:
                J[i, 9 + i] = -1.0
        m = 12
        for i in range(3):
            if face_roles[f, i] != ROLE_SECOND:
                continue
            e = face_edges[f, i]
            h = hinge_of_edge[e]
            for s in range(4):
                v = hinges[h, s]
                for k in range(3):
                    pts[s, k] = x[v, k]
                # the hinge's vertices in the stencil: own vertices first, o_a appended
                found = -1
                for a in range(3):
                    if triangles[f, a] == v:
                        found = 3 * a
                if found < 0:
                    found = m
                    for k in range(3):
                        dofs[m + k] = vertex_dof[v, k]
                    m += 3
                slot_of[s] = found
            psi = hinge_angle_into(pts, want_gradient, want_hessian, gloc, hloc, Ja, Jb, HX, HT, t3, dX, dT, dl, dY,
                                   vec)
            phi[i] = -(theta[e] + psi)
            if want_gradient:
                for s in range(4):
                    for k in range(3):
                        J[i, slot_of[s] + k] -= gloc[3 * s + k]
            if want_hessian:
                psis_hess[i] = hloc
                for s in range(4):
                    psis_slots[i, s] = slot_of[s]
        for i in range(3):
            kphi[i] = K[f, i, 0] * phi[0] + K[f, i, 1] * phi[1] + K[f, i, 2] * phi[2]
        energy += 0.5 * (phi[0] * kphi[0] + phi[1] * kphi[1] + phi[2] * kphi[2])
        if not want_gradient:
            continue
        for c in range(m):
            gstencil[c] = J[0, c] * kphi[0] + J[1, c] * kphi[1] + J[2, c] * kphi[2]
            grad[dofs[c]] += gstencil[c]
        if not want_hessian:
            continue
        for i in range(3):
            for c in range(m):
                KJ[i, c] = K[f, i, 0] * J[0, c] + K[f, i, 1] * J[1, c] + K[f, i, 2] * J[2, c]
        for r in range(m):
            for c in range(m):
                block[r, c] = J[0, r] * KJ[0, c] + J[1, r] * KJ[1, c] + J[2, r] * KJ[2, c]
        for i in range(3):
            if face_roles[f, i] != ROLE_SECOND:
                continue
            # d2 phi_i = -d2 psi_i
            for s in range(4):
                for t in range(4):
                    rs, ct = psis_slots[i, s], psis_slots[i, t]
                    for k in range(3):
                        for c in range(3):
                            block[rs + k, ct + c] -= kphi[i] * psis_hess[i, 3 * s + k, 3 * t + c]
        add_symmetric_block(band, n, dofs[:m], block[:m, :m])
    return energy



@njit(cache=True)
def reference_membrane(x, triangles, C, abar, vertex_dof, n, grad, band, want_gradient, want_hessian):
    """Membrane energy sum_f 1/2 delta^T C_f delta; adds the gradient into grad (n,) and the
    Hessian into the flattened lower band (ddg.assembly.band_scatter). vertex_dof (N, 3)."""
    energy = 0.0
    dofs = np.empty(9, dtype=np.int64)
    J = np.empty((3, 9))
    block = np.empty((9, 9))
    delta = np.empty(3)
    Cd = np.empty(3)
    CJ = np.empty((3, 9))
    for f in range(triangles.shape[0]):
        p0, p1, p2 = triangles[f, 0], triangles[f, 1], triangles[f, 2]
        e1 = x[p1] - x[p0]
        e2 = x[p2] - x[p0]
        delta[0] = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2] - abar[f, 0]
        delta[1] = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2] - abar[f, 1]
        delta[2] = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2] - abar[f, 2]
        Cd0 = C[f, 0, 0] * delta[0] + C[f, 0, 1] * delta[1] + C[f, 0, 2] * delta[2]
        Cd1 = C[f, 1, 0] * delta[0] + C[f, 1, 1] * delta[1] + C[f, 1, 2] * delta[2]
        Cd2 = C[f, 2, 0] * delta[0] + C[f, 2, 1] * delta[1] + C[f, 2, 2] * delta[2]
        Cd[0], Cd[1], Cd[2] = Cd0, Cd1, Cd2
        energy += 0.5 * (delta[0] * Cd[0] + delta[1] * Cd[1] + delta[2] * Cd[2])
        if not want_gradient:
            continue
        for k in range(3):
            dofs[k] = vertex_dof[p0, k]
            dofs[3 + k] = vertex_dof[p1, k]
            dofs[6 + k] = vertex_dof[p2, k]
            # a11 = e1.e1, a12 = e1.e2, a22 = e2.e2 in (p0, p1, p2)
            J[0, k], J[0, 3 + k], J[0, 6 + k] = -2.0 * e1[k], 2.0 * e1[k], 0.0
            J[1, k], J[1, 3 + k], J[1, 6 + k] = -(e1[k] + e2[k]), e2[k], e1[k]
            J[2, k], J[2, 3 + k], J[2, 6 + k] = -2.0 * e2[k], 0.0, 2.0 * e2[k]
        for c in range(9):
            grad[dofs[c]] += J[0, c] * Cd[0] + J[1, c] * Cd[1] + J[2, c] * Cd[2]
        if not want_hessian:
            continue
        for a in range(3):
            for c in range(9):
                CJ[a, c] = C[f, a, 0] * J[0, c] + C[f, a, 1] * J[1, c] + C[f, a, 2] * J[2, c]
        for r in range(9):
            for c in range(9):
                block[r, c] = J[0, r] * CJ[0, c] + J[1, r] * CJ[1, c] + J[2, r] * CJ[2, c]
        # constant Hessians of a11 (on p0, p1), a22 (on p0, p2) and a12, times (C delta)_k
        s11, s12, s22 = 2.0 * Cd[0], Cd[1], 2.0 * Cd[2]
        for k in range(3):
            block[k, k] += s11 + 2.0 * s12 + s22
            block[3 + k, 3 + k] += s11
            block[6 + k, 6 + k] += s22
            block[k, 3 + k] -= s11 + s12
            block[3 + k, k] -= s11 + s12
            block[k, 6 + k] -= s22 + s12
            block[6 + k, k] -= s22 + s12
            block[3 + k, 6 + k] += s12
            block[6 + k, 3 + k] += s12
        add_symmetric_block(band, n, dofs, block)
    return energy


@njit(cache=True)
def reference_smoothed_membrane(x, triangles, T, abar, pointer, patch_faces, weights, patch_area, C, scale,
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


# ---------------------------------------------------------------------------- the comparison
@pytest.fixture(scope="module", params=MESHES, ids=lambda m: f"W/L={m[0]:.3g}, rows={m[1]}")
def model(request):
    ratio, rows = request.param
    return MidedgePlateModel(Strip.from_ratios(ratio, 0.5), rows=rows)


def deformed_state(model, seed):
    """The buckled guess at dL = L/2, nodes moved by 1e-2 L at random and edge angles of 0.1: no
    term of the energies vanishes or is small."""
    L = model.strip.length
    rng = np.random.default_rng(seed)
    q = model.apply_clamps(model.buckled_guess(0.5 * L), 0.5 * L, 0.0)
    q[model.free] += 1e-2 * L * rng.standard_normal(model.free.stop - model.free.start)
    q[model.edge_dofs] += 0.1 * rng.standard_normal(len(model.edge_dofs))
    return np.ascontiguousarray(q[model.node_dofs]), np.ascontiguousarray(q[model.edge_dofs])


def run(kernel, model, *arguments):
    """(energy, gradient, flattened lower band) of one kernel with the energy, gradient and Hessian
    asked; and the energy and gradient again with less asked, which must be the same numbers."""
    n = model.n_dof
    grad, band = np.zeros(n), np.zeros((model.bandwidth + 1) * n)
    energy = kernel(*arguments, n, grad, band, True, True)
    alone, gradient_alone = kernel(*arguments, n, np.zeros(n), np.empty(0), True, False), np.zeros(n)
    kernel(*arguments, n, gradient_alone, np.empty(0), True, False)
    assert alone == pytest.approx(energy, rel=ROUND_OFF)
    assert kernel(*arguments, n, np.empty(0), np.empty(0), False, False) == pytest.approx(energy, rel=ROUND_OFF)
    np.testing.assert_allclose(gradient_alone, grad, rtol=0, atol=ROUND_OFF * np.abs(grad).max())
    return energy, grad, band


def assert_same(new, reference):
    for a, b in zip(new, reference):
        scale = np.abs(b).max()
        assert scale > 0.0
        np.testing.assert_allclose(a, b, rtol=0, atol=ROUND_OFF * scale)


@pytest.mark.parametrize("seed", range(2))
def test_membrane_is_the_reference(model, seed):
    x, _ = deformed_state(model, seed)
    t = model._by_x
    new = run(add_membrane_terms, model, x, t["triangles"], t["membrane"], t["abar"], model._node_dofs)
    reference = run(reference_membrane, model, x, model._triangles, model.membrane_alpha * model._membrane,
                    model._abar, model._node_dofs)
    assert_same(new, reference)


@pytest.mark.parametrize("seed", range(2))
def test_smoothed_membrane_is_the_reference(model, seed):
    x, _ = deformed_state(model, seed)
    scale = 1.0 - model.membrane_alpha
    new = run(add_smoothed_membrane_terms, model, x, model._triangles, model._strain_T, model._abar, *model._patches,
              model._plane_stress, scale, model._node_dofs)
    reference = run(reference_smoothed_membrane, model, x, model._triangles, model._strain_T, model._abar,
                    *model._patches[:4], model._plane_stress, scale, model._node_dofs)
    assert_same(new, reference)


@pytest.mark.parametrize("seed", range(2))
def test_midedge_bending_is_the_reference(model, seed):
    x, theta = deformed_state(model, seed)
    t = model._by_x
    new = run(add_midedge_terms, model, x, theta, t["stencil"], t["hinge_slots"], t["face_edges"], t["bending"],
              model._node_dofs, model._edge_dofs)
    roles = np.where(model._hinge_slots[:, :, 0] >= 0, ROLE_SECOND, ROLE_FIRST)
    reference = run(reference_bending, model, x, theta, model._triangles, model._face_edges, roles,
                    model._hinge_of_edge, model._hinges, model._bending, model._node_dofs, model._edge_dofs)
    assert_same(new, reference)


def split_mesh_model():
    """The W/L = 1/6 plate on 4 rows with its triangle nearest the centre split at its centroid:
    a vertex of three triangles, where two hinges of one triangle have the same far vertex (its
    stencil holds that vertex once)."""
    strip = Strip.from_ratios(1 / 6, 0.5)
    base = ghost_clamp_mesh(strip.length, strip.width, rows=4)
    centres = base.nodes[base.triangles].mean(axis=1)
    f = int(np.argmin(np.abs(centres[:, 0] - 0.5 * strip.length) + np.abs(centres[:, 1])))
    a, b, d = base.triangles[f]
    nodes = np.vstack([base.nodes, centres[f]])
    c = len(nodes) - 1
    triangles = np.vstack([np.delete(base.triangles, f, axis=0), [[a, b, c], [b, d, c], [d, a, c]]])
    order = np.lexsort((nodes[:, 1], nodes[:, 0]))
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    mesh = PlateMesh(nodes[order], rank[triangles], strip.length, strip.width, 0.0, 0.0)
    return MidedgePlateModel(strip, mesh=mesh)


def test_midedge_bending_is_the_reference_where_two_hinges_share_their_far_vertex():
    model = split_mesh_model()
    hinges_second = (model._hinge_slots[:, :, 0] >= 0).sum(axis=1)
    assert (hinges_second > (model._stencil[:, 3:] >= 0).sum(axis=1)).sum() == 1
    test_midedge_bending_is_the_reference(model, 0)
