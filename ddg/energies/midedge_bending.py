"""Mid-edge bending of a triangle mesh: a discrete Kirchhoff plate with the material's Poisson ratio.

The energy of the second plate model (`plate-midedge`, ddg.models.midedge_plate). The paper's hinge
energy (Eq. 11b, ddg.energies.hinge_bending) weighs each edge's bending angle with a fixed
coefficient, which fixes the bending Poisson ratio at -1/3 and misweighs the edge rows of a free
boundary; this one builds each triangle's second fundamental form from the normals at its three
edge midpoints and integrates the plate's density with the material's Poisson ratio nu (the mid-edge
shells of Chen, Weischedel et al. 2018 and libshell; linearised, Morley's nonconforming element).

Mid-edge normals. Each edge e carries one angle DOF theta_e, the tilt of its mid-edge normal
(the "director", perpendicular to the edge) from the normal of its first triangle a toward a's
outward in-plane edge normal m_a = e_hat x N_a. A triangle f sees, on each of its edges i, the
director's tilt phi_i from its own normal toward its own outward edge normal:

  phi = theta_e               on the first triangle a of an edge (and the only one of a free edge),
  phi = -(theta_e + psi_e)    on the second triangle b,

with psi_e the signed bending angle of the edge's hinge (positive where the surface turns up
toward N_a, a valley; `hinge_angle`). A free edge's theta is free: the natural boundary
condition comes out of the minimisation. A clamped edge has a rigid ghost triangle as a
(ddg.geometry.plate_mesh.ghost_clamp_mesh) and theta = 0: the director is the clamp's normal.

Second fundamental form (Morley's exact identity for quadratic surfaces, derived in the
module's tests): in the basis e1 = p1 - p0, e2 = p2 - p0 of a triangle with its edge i opposite
vertex i, II = sum_i phi_i (4 A / l_i) d_i d_i^T with d_0 = (-1, -1), d_1 = (1, 0), d_2 = (0, 1).
A and l_i are taken in the reference state (the strains are ~1e-4 where the plate is thin;
objectivity is kept, as phi depends on angles only). The bending energy of the triangle is

  E_f = A (D / 2) [nu tr(M)^2 + (1 - nu) tr(M^2)],   M = abar^-1 II,   D = E b^3 / (12 (1 - nu^2)),

the Kirchhoff plate's density for the mixed curvature tensor M, i.e. E_f = 1/2 phi^T K_f phi with
a constant 3 x 3 K_f per triangle (`face_bending_matrices`). phi is linear in theta and psi, so
the derivatives need only psi's gradient and Hessian in the hinge's 12 coordinates:

  psi = atan2(Y, X),  X = u_a . u_b,  Y = (u_b x u_a) . e / |e|,

u_a = (p1 - p0) x (p2 - p0) the unnormalised normal of a = (v0, v1, o_a) and u_b that of
b = (v1, v0, o_b), e = v1 - v0. u is bilinear in the vertices (du/dp_i = -[c_i]x with
c_i = p_{i+1} - p_{i+2}; the Hessian of w . u is the block matrix B(w) of ddg.energies.hinge_bending),
so X and Y have closed-form Hessians, and psi's follows from atan2's.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..assembly.band_scatter import add_symmetric_block

#: Role of a triangle on one of its edges: the edge's first triangle (and a free edge's only one),
#: phi = theta; its second triangle, phi = -(theta + psi).
ROLE_FIRST, ROLE_SECOND = 0, 1

_D = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])


def face_bending_matrices(nodes: np.ndarray, triangles: np.ndarray, young_modulus: float, thickness: float,
                          poisson_ratio: float) -> np.ndarray:
    """K_f (T, 3, 3): the bending energy of triangle f is 1/2 phi^T K_f phi (module docstring).

    nodes (N, 2) reference positions, triangles (T, 3) counter-clockwise. With B = abar^-1,
    c_i = 4 A / l_i and G_ik = d_i^T B d_k: tr M = sum_i c_i G_ii phi_i and
    tr M^2 = sum_ik c_i c_k G_ik^2 phi_i phi_k."""
    nu = poisson_ratio
    D = young_modulus * thickness**3 / (12.0 * (1.0 - nu * nu))
    p = nodes[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    lengths = np.stack([np.linalg.norm(p[:, 2] - p[:, 1], axis=1), np.linalg.norm(p[:, 0] - p[:, 2], axis=1),
                        np.linalg.norm(p[:, 1] - p[:, 0], axis=1)], axis=1)
    abar = np.stack([np.stack([np.einsum("ti,ti->t", e1, e1), np.einsum("ti,ti->t", e1, e2)], axis=1),
                     np.stack([np.einsum("ti,ti->t", e1, e2), np.einsum("ti,ti->t", e2, e2)], axis=1)], axis=1)
    B = np.linalg.inv(abar)
    G = np.einsum("ia,tab,kb->tik", _D, B, _D)
    c = 4.0 * area[:, None] / lengths
    trace = c * np.einsum("tii->ti", G)
    K = nu * np.einsum("ti,tk->tik", trace, trace) + (1.0 - nu) * np.einsum("ti,tk,tik->tik", c, c, G * G)
    return (area * D)[:, None, None] * K


# ---------------------------------------------------------------------------- the hinge angle
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


@njit(cache=True)
def hinge_angle(p, want_gradient, want_hessian, grad, hess):
    """Signed bending angle psi of the hinge p (4, 3) = (v0, v1, o_a, o_b), into grad (12,) and
    hess (12, 12) when asked (module docstring); returns psi."""
    Ja, Jb, HX, HT, t3, dX, dT, dl, dY = (np.empty((3, 12)), np.empty((3, 12)), np.empty((12, 12)),
                                          np.empty((12, 12)), np.empty((3, 12)), np.empty(12), np.empty(12),
                                          np.empty(12), np.empty(12))
    return hinge_angle_into(p, want_gradient, want_hessian, grad, hess, Ja, Jb, HX, HT, t3, dX, dT, dl, dY,
                            np.empty((6, 3)))


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


# ---------------------------------------------------------------------------- assembly
@njit(cache=True)
def add_midedge_terms(x, theta, triangles, face_edges, face_roles, hinge_of_edge, hinges, K,
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

