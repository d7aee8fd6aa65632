"""Mid-edge bending of a triangle mesh: a discrete Kirchhoff plate with the material's Poisson ratio.

The bending of `plate-midedge` (ddg.models.midedge_plate): each triangle's second fundamental form
from the normals at its three edge midpoints, integrated with the plate's density and Poisson ratio
nu (the mid-edge shells of Chen, Weischedel et al. 2018 and libshell; linearised, Morley's element),
where the paper's hinge energy (Eq. 11b, ddg.energies.hinge_bending) fixes the ratio at -1/3.

Mid-edge normals. Each edge e carries one angle DOF theta_e, the tilt of its mid-edge normal from
the normal of its first triangle a toward a's outward in-plane edge normal m_a = e_hat x N_a. A
triangle sees on its edge i the tilt phi_i from its own normal toward its own outward edge normal:
phi = theta_e on the first triangle a of an edge (and the only one of a free edge, whose theta is
free: the natural boundary condition), phi = -(theta_e + psi_e) on the second triangle b, with psi_e
the signed bending angle of the edge's hinge (positive where the surface turns up toward N_a, a
valley; `hinge_angle`). A clamped edge has a rigid ghost triangle as a
(ddg.geometry.plate_mesh.ghost_clamp_mesh) and theta = 0: the director is the clamp's normal.

Second fundamental form (Morley's exact identity for quadratic surfaces, derived in the tests): in
the basis e1 = p1 - p0, e2 = p2 - p0, edge i opposite vertex i, II = sum_i phi_i (4 A / l_i) d_i d_i^T
with d_0 = (-1, -1), d_1 = (1, 0), d_2 = (0, 1); A and l_i in the reference state (strains ~1e-4). Then

  E_f = A (D / 2) [nu tr(M)^2 + (1 - nu) tr(M^2)],   M = abar^-1 II,   D = E b^3 / (12 (1 - nu^2)),

i.e. E_f = 1/2 phi^T K_f phi with a constant 3 x 3 K_f (`face_bending_matrices`); phi is linear in
theta and psi, so the derivatives need only psi's gradient and Hessian in the hinge's 12 coordinates.

The hinge angle. e = v1 - v0 (length l, unit e_hat), u_a = e x (o_a - v0), u_b = (v0 - v1) x (o_b - v1):
psi = atan2(Y, X), X = u_a . u_b, Y = (u_b x u_a) . e / l. Its derivatives in closed form (as Bridson
et al. 2003 and Tamstorf & Grinspun 2013), per wing w = a, b with far vertex o_w: q_w = e x (o_w - v0),
n = q_w / |q_w|, t = e_hat x n, height h = |q_w| / l, foot xi = (o_w - v0) . e / l^2, s = +1 on a, -1 on b:

  d psi / d o_w = s n / h,  d psi / d v1 = -xi s n / h,  d psi / d v0 = -(1 - xi) s n / h   (summed over w),

and Hess psi sums each wing's symmetric 9 x 9 on (v0, v1, o_w), with c = (-(1 - xi), -xi, 1) and
b = (-1, 1, 0) over (v0, v1, o_w), block (i, j)

  s [(c_i c_j / h^2 + b_i b_j / (2 l^2)) (t n^T + n t^T) - (b_i c_j n e_hat^T + c_i b_j e_hat n^T) / (l h)]

(d(n / h) / d(o_w - v0) = (t n^T + n t^T) / h^2 and the chain rule through xi and l; the two wings'
antisymmetric parts in e alone cancel, so each is written symmetric).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..assembly.band_scatter import prefetch_lower

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
def _hinge_frame(P, i0, i1, ia, ib, edge, wing):
    """psi of the hinge (v0, v1, o_a, o_b) = rows (i0, i1, ia, ib) of P; with its frame (module
    docstring): edge = (e_hat, l), wing[w] = (n, t, h, xi) of w = a, b. Returns psi."""
    e0, e1, e2 = P[i1, 0] - P[i0, 0], P[i1, 1] - P[i0, 1], P[i1, 2] - P[i0, 2]
    ll = e0 * e0 + e1 * e1 + e2 * e2
    length = math.sqrt(ll)
    inv_l = 1.0 / length
    # q_w = e x d_w, d_w = o_w - v0 (u_a = q_a, u_b = -q_b)
    da0, da1, da2 = P[ia, 0] - P[i0, 0], P[ia, 1] - P[i0, 1], P[ia, 2] - P[i0, 2]
    db0, db1, db2 = P[ib, 0] - P[i0, 0], P[ib, 1] - P[i0, 1], P[ib, 2] - P[i0, 2]
    qa0, qa1, qa2 = e1 * da2 - e2 * da1, e2 * da0 - e0 * da2, e0 * da1 - e1 * da0
    qb0, qb1, qb2 = e1 * db2 - e2 * db1, e2 * db0 - e0 * db2, e0 * db1 - e1 * db0
    # psi = atan2(Y, X), X = u_a . u_b, Y = (u_b x u_a) . e / l
    X = -(qa0 * qb0 + qa1 * qb1 + qa2 * qb2)
    Y = -((qb1 * qa2 - qb2 * qa1) * e0 + (qb2 * qa0 - qb0 * qa2) * e1 + (qb0 * qa1 - qb1 * qa0) * e2) * inv_l
    psi = math.atan2(Y, X)
    h0, h1, h2 = e0 * inv_l, e1 * inv_l, e2 * inv_l
    edge[0], edge[1], edge[2], edge[3] = h0, h1, h2, length
    for w in range(2):
        if w == 0:
            q0, q1, q2, xi = qa0, qa1, qa2, (da0 * e0 + da1 * e1 + da2 * e2) / ll
        else:
            q0, q1, q2, xi = qb0, qb1, qb2, (db0 * e0 + db1 * e1 + db2 * e2) / ll
        norm = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2)
        inv = 1.0 / norm
        n0, n1, n2 = q0 * inv, q1 * inv, q2 * inv
        wing[w, 0], wing[w, 1], wing[w, 2] = n0, n1, n2
        wing[w, 3], wing[w, 4], wing[w, 5] = h1 * n2 - h2 * n1, h2 * n0 - h0 * n2, h0 * n1 - h1 * n0
        wing[w, 6] = norm * inv_l
        wing[w, 7] = xi
    return psi


@njit(cache=True, forceinline=True)
def _wing_gradient(wing, w):
    """(s n / h, xi) of wing w: d psi / d o_w = s n / h, d psi / d v1 = -xi s n / h, d psi / d v0 =
    -(1 - xi) s n / h (s = +1 on a, -1 on b)."""
    s = (1.0 if w == 0 else -1.0) / wing[w, 6]
    return s * wing[w, 0], s * wing[w, 1], s * wing[w, 2]


@njit(cache=True, forceinline=True)
def _add_wing_hessian(edge, wing, w, scale, rows, block, S, N):
    """block += scale times wing w's part of Hess psi (module docstring), on the lower triangle
    (row >= column) of the local block whose rows rows = (r0, r1, r2) start the coordinates of
    (v0, v1, o_w): coefficients (c, b) = (-(1 - xi), -1) on v0, (-xi, 1) on v1, (1, 0) on o_w,
    block (i, j) = s [(c_i c_j / h^2 + b_i b_j / (2 l^2)) S - (b_i c_j N + c_i b_j N^T) / (l h)]
    with S = t n^T + n t^T and N = n e_hat^T. S, N (3, 3) scratch."""
    s = scale if w == 0 else -scale
    h, length, xi = wing[w, 6], edge[3], wing[w, 7]
    for k in range(3):
        for m in range(3):
            S[k, m] = wing[w, 3 + k] * wing[w, m] + wing[w, k] * wing[w, 3 + m]
            N[k, m] = wing[w, k] * edge[m]
    c = (-(1.0 - xi), -xi, 1.0)
    b = (-1.0, 1.0, 0.0)
    inv_h2, inv_l2, inv_lh = 1.0 / (h * h), 0.5 / (length * length), 1.0 / (length * h)
    for i in range(3):
        r = rows[i]
        alpha = s * (c[i] * c[i] * inv_h2 + b[i] * b[i] * inv_l2)
        beta = s * b[i] * c[i] * inv_lh
        for k in range(3):
            for m in range(k + 1):
                block[r + k, r + m] += alpha * S[k, m] - beta * (N[k, m] + N[m, k])
        for j in range(i):
            # the pair (i, j) written as (hi, lo), hi the one with the larger rows
            hi, lo = (i, j) if rows[i] > rows[j] else (j, i)
            rh, rl = rows[hi], rows[lo]
            alpha = s * (c[hi] * c[lo] * inv_h2 + b[hi] * b[lo] * inv_l2)
            beta1 = s * b[hi] * c[lo] * inv_lh
            beta2 = s * c[hi] * b[lo] * inv_lh
            for k in range(3):
                for m in range(3):
                    block[rh + k, rl + m] += alpha * S[k, m] - beta1 * N[k, m] - beta2 * N[m, k]


@njit(cache=True)
def hinge_angle(p, want_gradient, want_hessian, grad, hess):
    """Signed bending angle psi of the hinge p (4, 3) = (v0, v1, o_a, o_b), into grad (12,) and
    hess (12, 12) when asked (module docstring); returns psi."""
    edge, wing, S, N = np.empty(4), np.empty((2, 8)), np.empty((3, 3)), np.empty((3, 3))
    psi = _hinge_frame(p, 0, 1, 2, 3, edge, wing)
    if not want_gradient:
        return psi
    grad[:] = 0.0
    for w in range(2):
        g0, g1, g2 = _wing_gradient(wing, w)
        xi = wing[w, 7]
        for k, gk in enumerate((g0, g1, g2)):
            grad[6 + 3 * w + k] = gk
            grad[3 + k] -= xi * gk
            grad[k] -= (1.0 - xi) * gk
    if not want_hessian:
        return psi
    hess[:, :] = 0.0
    for w in range(2):
        _add_wing_hessian(edge, wing, w, 1.0, (0, 3, 6 + 3 * w), hess, S, N)
    for r in range(12):
        for c in range(r):
            hess[c, r] = hess[r, c]
    return psi


# ---------------------------------------------------------------------------- assembly
@njit(cache=True, forceinline=True)
def _lower_jkj(K, f, J, KJ, block, m):
    """block[r, c] = (J^T K_f J)[r, c] for c <= r < m (KJ (3, m) scratch)."""
    for i in range(3):
        k0, k1, k2 = K[f, i, 0], K[f, i, 1], K[f, i, 2]
        for c in range(m):
            KJ[i, c] = k0 * J[0, c] + k1 * J[1, c] + k2 * J[2, c]
    for r in range(m):
        j0, j1, j2 = J[0, r], J[1, r], J[2, r]
        for c in range(r + 1):
            block[r, c] = j0 * KJ[0, c] + j1 * KJ[1, c] + j2 * KJ[2, c]


@njit(cache=True, forceinline=True)
def _stencil_dofs(stencil, face_edges, vertex_dof, edge_dof, f, dofs):
    """The global DOFs of triangle f's stencil in its local numbering (add_midedge_terms); returns
    their number m."""
    nv = 3
    while nv < 6 and stencil[f, nv] >= 0:
        nv += 1
    for s in range(nv):
        b = 3 * s if s < 3 else 3 * s + 3
        v = stencil[f, s]
        for k in range(3):
            dofs[b + k] = vertex_dof[v, k]
    for i in range(3):
        dofs[9 + i] = edge_dof[face_edges[f, i]]
    return 3 * nv + 3


@njit(cache=True)
def add_midedge_terms(x, theta, stencil, hinge_slots, face_edges, K, vertex_dof, edge_dof, n, grad, band,
                      want_gradient, want_hessian):
    """Bending energy sum_f 1/2 phi_f^T K_f phi_f of the mid-edge plate; adds its gradient into
    grad (n,) and its Hessian into the lower band (flattened, ddg.assembly.band_scatter).

    x (N, 3) positions, theta (E,) edge angles; stencil (T, 6) each triangle's vertices (its own
    three, then the far vertices o_a of the edges it is second on, each once; -1 after them);
    hinge_slots (T, 3, 4) the stencil rows of the hinge (v0, v1, o_a, o_b) of edge i (opposite
    vertex i) where the triangle is its second triangle b (phi_i = -(theta + psi)), -1 where it is
    the first (phi_i = theta); face_edges (T, 3); K (T, 3, 3); vertex_dof (N, 3) and edge_dof (E,)
    the global DOF numbers.

    Local numbering of a triangle's stencil: its own vertices' coordinates 0-8, its three angles
    9-11, the far vertices' coordinates from 12 on. The Hessian J^T K J - sum_i kphi_i Hess(psi_i),
    kphi = K phi, is formed on the lower triangle of the local block only and added into the band at
    |r - c| n + min(r, c), the next triangle's entries prefetched meanwhile (ddg.assembly.band_scatter:
    the wide stencil's entries are often not yet in cache; the membranes' narrower ones mostly are,
    and they are not prefetched)."""
    energy = 0.0
    dofs = np.empty(21, dtype=np.int64)
    J = np.zeros((3, 21))
    KJ = np.empty((3, 21))
    block = np.empty((21, 21))
    P = np.empty((6, 3))
    base = np.empty(6, dtype=np.int64)
    phi = np.empty(3)
    kphi = np.empty(3)
    edges = np.empty((3, 4))
    wings = np.empty((3, 2, 8))
    S = np.empty((3, 3))
    N = np.empty((3, 3))
    ahead = np.empty(21, dtype=np.int64)
    for f in range(stencil.shape[0]):
        if want_hessian and f + 1 < stencil.shape[0]:
            prefetch_lower(band, n, ahead, _stencil_dofs(stencil, face_edges, vertex_dof, edge_dof, f + 1, ahead))
        m = _stencil_dofs(stencil, face_edges, vertex_dof, edge_dof, f, dofs)
        nv = m // 3 - 1
        for s in range(nv):
            v = stencil[f, s]
            base[s] = 3 * s if s < 3 else 3 * s + 3
            for k in range(3):
                P[s, k] = x[v, k]
        for i in range(3):
            e = face_edges[f, i]
            if hinge_slots[f, i, 0] < 0:
                phi[i] = theta[e]
                J[i, 9 + i] = 1.0
                continue
            s0, s1, sa, sb = hinge_slots[f, i, 0], hinge_slots[f, i, 1], hinge_slots[f, i, 2], hinge_slots[f, i, 3]
            psi = _hinge_frame(P, s0, s1, sa, sb, edges[i], wings[i])
            phi[i] = -(theta[e] + psi)
            if not want_gradient:
                continue
            J[i, 9 + i] = -1.0
            # d phi_i = -d psi_i
            b0, b1 = base[s0], base[s1]
            for w in range(2):
                g0, g1, g2 = _wing_gradient(wings[i], w)
                xi = wings[i, w, 7]
                bo = base[sa] if w == 0 else base[sb]
                J[i, bo] -= g0
                J[i, bo + 1] -= g1
                J[i, bo + 2] -= g2
                J[i, b1] += xi * g0
                J[i, b1 + 1] += xi * g1
                J[i, b1 + 2] += xi * g2
                J[i, b0] += (1.0 - xi) * g0
                J[i, b0 + 1] += (1.0 - xi) * g1
                J[i, b0 + 2] += (1.0 - xi) * g2
        for i in range(3):
            kphi[i] = K[f, i, 0] * phi[0] + K[f, i, 1] * phi[1] + K[f, i, 2] * phi[2]
        energy += 0.5 * (phi[0] * kphi[0] + phi[1] * kphi[1] + phi[2] * kphi[2])
        if not want_gradient:
            continue
        for c in range(m):
            grad[dofs[c]] += J[0, c] * kphi[0] + J[1, c] * kphi[1] + J[2, c] * kphi[2]
        if want_hessian:
            # m = 12 + 3 (far vertices): each size compiled with its loop bounds known
            if m == 21:
                _lower_jkj(K, f, J, KJ, block, 21)
            elif m == 18:
                _lower_jkj(K, f, J, KJ, block, 18)
            elif m == 15:
                _lower_jkj(K, f, J, KJ, block, 15)
            else:
                _lower_jkj(K, f, J, KJ, block, 12)
            for i in range(3):
                if hinge_slots[f, i, 0] < 0:
                    continue
                # d2 phi_i = -d2 psi_i
                r0, r1 = base[hinge_slots[f, i, 0]], base[hinge_slots[f, i, 1]]
                _add_wing_hessian(edges[i], wings[i], 0, -kphi[i], (r0, r1, base[hinge_slots[f, i, 2]]), block, S, N)
                _add_wing_hessian(edges[i], wings[i], 1, -kphi[i], (r0, r1, base[hinge_slots[f, i, 3]]), block, S, N)
            for r in range(m):
                dr = dofs[r]
                for c in range(r + 1):
                    dc = dofs[c]
                    band[abs(dr - dc) * n + min(dr, dc)] += block[r, c]
        for i in range(3):
            for c in range(m):
                J[i, c] = 0.0
    return energy
