"""Mid-edge bending of a triangle mesh: a discrete Kirchhoff plate with the material's Poisson ratio.

The second plate model (`plate-midedge`, ddg.models.midedge_plate). Where the paper's hinge
energy (Eq. 11b, ddg.energies.hinge_bending) weighs each edge's bending angle with a fixed
coefficient, and so fixes the bending Poisson ratio at -1/3 and misweighs the edge rows of a
free boundary, this energy builds each triangle's second fundamental form from the normals at
its three edge midpoints and integrates the plate's bending energy density with the material's
Poisson ratio nu (the mid-edge shells of Chen, Weischedel et al. 2018 and of libshell;
linearised, the nonconforming Morley plate element, whose eigenvalues converge at second order).

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

from ..solve.band_scatter import add_symmetric_block

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
@njit(cache=True, inline="always")
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
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


@njit(cache=True)
def _add_bilinear(slots, w, scale, H):
    """H += scale * Hessian of w . u in the 12 hinge coordinates (u of the triangle on `slots`):
    blocks (i, i+1) = -[w]x, (i+1, i) = +[w]x."""
    for i in range(3):
        r, c = 3 * slots[i], 3 * slots[(i + 1) % 3]
        # -[w]x
        H[r + 0, c + 1] += scale * w[2]
        H[r + 0, c + 2] -= scale * w[1]
        H[r + 1, c + 0] -= scale * w[2]
        H[r + 1, c + 2] += scale * w[0]
        H[r + 2, c + 0] += scale * w[1]
        H[r + 2, c + 1] -= scale * w[0]
        # its transpose into (i+1, i)
        H[c + 1, r + 0] += scale * w[2]
        H[c + 2, r + 0] -= scale * w[1]
        H[c + 0, r + 1] -= scale * w[2]
        H[c + 2, r + 1] += scale * w[0]
        H[c + 0, r + 2] += scale * w[1]
        H[c + 1, r + 2] -= scale * w[0]


@njit(cache=True)
def _cross_pair(Jp, Jq, r, scale, H):
    """H += scale * (Jp^T (-[r]x) Jq + its transpose): the second variation (dp x dq) . r."""
    # (-[r]x) Jq
    t = np.empty((3, 12))
    for k in range(12):
        q0, q1, q2 = Jq[0, k], Jq[1, k], Jq[2, k]
        t[0, k] = r[2] * q1 - r[1] * q2
        t[1, k] = r[0] * q2 - r[2] * q0
        t[2, k] = r[1] * q0 - r[0] * q1
    for i in range(12):
        for k in range(12):
            v = scale * (Jp[0, i] * t[0, k] + Jp[1, i] * t[1, k] + Jp[2, i] * t[2, k])
            H[i, k] += v
            H[k, i] += v


_SLOTS_A = np.array([0, 1, 2], dtype=np.int64)  # a = (v0, v1, o_a)
_SLOTS_B = np.array([1, 0, 3], dtype=np.int64)  # b = (v1, v0, o_b)


@njit(cache=True)
def hinge_angle(p, want_gradient, want_hessian, grad, hess):
    """Signed bending angle psi of the hinge p (4, 3) = (v0, v1, o_a, o_b), into grad (12,) and
    hess (12, 12) when asked (module docstring); returns psi."""
    slots_a, slots_b = _SLOTS_A, _SLOTS_B
    ua, ub, e, w = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for k in range(3):
        e[k] = p[1, k] - p[0, k]
        w[k] = p[2, k] - p[0, k]
    _cross(e, w, ua)
    a1 = np.empty(3)
    for k in range(3):
        a1[k] = p[0, k] - p[1, k]
        w[k] = p[3, k] - p[1, k]
    _cross(a1, w, ub)
    length = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    X = ua[0] * ub[0] + ua[1] * ub[1] + ua[2] * ub[2]
    ubxua = np.empty(3)
    _cross(ub, ua, ubxua)
    T = ubxua[0] * e[0] + ubxua[1] * e[1] + ubxua[2] * e[2]
    Y = T / length
    psi = math.atan2(Y, X)
    if not want_gradient:
        return psi
    Ja, Jb = np.empty((3, 12)), np.empty((3, 12))
    _normal_jacobian(p, slots_a, Ja)
    _normal_jacobian(p, slots_b, Jb)
    # e = v1 - v0: Je = [-I, I, 0, 0]
    Je = np.zeros((3, 12))
    for k in range(3):
        Je[k, k] = -1.0
        Je[k, 3 + k] = 1.0
    ehat = e / length
    uaxe, exub = np.empty(3), np.empty(3)
    _cross(ua, e, uaxe)
    _cross(e, ub, exub)
    dX = Ja.T @ ub + Jb.T @ ua
    dT = Jb.T @ uaxe + Ja.T @ exub + Je.T @ ubxua
    dl = Je.T @ ehat
    dY = dT / length - T * dl / length**2
    R2 = X * X + Y * Y
    for i in range(12):
        grad[i] = (X * dY[i] - Y * dX[i]) / R2
    if not want_hessian:
        return psi
    # X = ua . ub
    HX = np.zeros((12, 12))
    _add_bilinear(slots_a, ub, 1.0, HX)
    _add_bilinear(slots_b, ua, 1.0, HX)
    JaJb = Ja.T @ Jb
    HX += JaJb + JaJb.T
    # T = (ub x ua) . e: second variations of each factor, then the pairs
    HT = np.zeros((12, 12))
    _add_bilinear(slots_b, uaxe, 1.0, HT)
    _add_bilinear(slots_a, exub, 1.0, HT)
    _cross_pair(Jb, Ja, e, 1.0, HT)
    _cross_pair(Ja, Je, ub, 1.0, HT)
    _cross_pair(Je, Jb, ua, 1.0, HT)
    # l = |e|
    proj = np.eye(3) - np.outer(ehat, ehat)
    Hl = Je.T @ proj @ Je / length
    HY = (HT / length - (np.outer(dT, dl) + np.outer(dl, dT)) / length**2 - T * Hl / length**2
          + 2.0 * T * np.outer(dl, dl) / length**3)
    g = X * dY - Y * dX
    H = (X * HY - Y * HX + np.outer(dY, dX) - np.outer(dX, dY)) / R2 \
        - np.outer(g, 2.0 * X * dX + 2.0 * Y * dY) / (R2 * R2)
    for i in range(12):
        for k in range(12):
            hess[i, k] = 0.5 * (H[i, k] + H[k, i])
    return psi


# ---------------------------------------------------------------------------- assembly
@njit(cache=True)
def add_midedge_terms(x, theta, triangles, face_edges, face_roles, hinge_of_edge, hinges, K,
                      vertex_dof, edge_dof, n, grad, band, want_gradient, want_hessian):
    """Bending energy sum_f 1/2 phi_f^T K_f phi_f of the mid-edge plate; adds its gradient into
    grad (n,) and its Hessian into the lower band (flattened, ddg.solve.band_scatter).

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
            psi = hinge_angle(pts, want_gradient, want_hessian, gloc, hloc)
            phi[i] = -(theta[e] + psi)
            if want_gradient:
                for s in range(4):
                    for k in range(3):
                        J[i, slot_of[s] + k] -= gloc[3 * s + k]
            if want_hessian:
                psis_hess[i] = hloc
                for s in range(4):
                    psis_slots[i, s] = slot_of[s]
        Kf = K[f]
        kphi = Kf @ phi
        energy += 0.5 * (phi[0] * kphi[0] + phi[1] * kphi[1] + phi[2] * kphi[2])
        if not want_gradient:
            continue
        for c in range(m):
            gstencil[c] = J[0, c] * kphi[0] + J[1, c] * kphi[1] + J[2, c] * kphi[2]
            grad[dofs[c]] += gstencil[c]
        if not want_hessian:
            continue
        KJ = Kf @ J
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


def midedge_bending_energy(x, theta, triangles, face_edges, face_roles, hinge_of_edge, hinges, K):
    """The bending energy alone (no derivatives), for tests and analysis."""
    n = 0
    vertex_dof = np.zeros((len(x), 3), dtype=np.int64)
    edge_dof = np.zeros(len(theta), dtype=np.int64)
    return add_midedge_terms(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(theta, dtype=float),
                             triangles, face_edges, face_roles, hinge_of_edge, hinges, K, vertex_dof, edge_dof,
                             n, np.empty(0), np.empty(0), False, False)
