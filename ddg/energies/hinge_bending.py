"""Hinge bending of a triangle mesh, Eq. (11b): E = sum over bending pairs c_h |n_a - n_b|^2.

n_a, n_b are the unit normals of the two triangles sharing the hinge edge, each computed from
its counter-clockwise vertices (p0, p1, p2) as n = u / |u|, u = (p1 - p0) x (p2 - p0), so a flat
mesh has all normals +z and zero energy. |n_a - n_b|^2 = 2 (1 - n_a . n_b) = 4 sin^2(theta/2)
with theta the dihedral (bending) angle.

Continuum limit (Seung and Nelson 1988; measured in tests/test_plate_energies.py): on an
equilateral mesh a constant c gives an isotropic bending energy density D_eff/2 (2H)^2 with
D_eff = sqrt(3) c, for any bending direction. So the paper's c = E b^3 / (12 sqrt(3)) gives
exactly D_eff = E b^3 / 12, the plate bending stiffness with Poisson ratio 0 (the rod's EI2 / W).
(A tempting shortcut, taking each triangle's normal as the surface normal at its centroid,
gives 2 c / sqrt(3) and is wrong: a triangle inscribed in a cylinder has the normal of its
chord: on a lattice with edges along the cylinder axis, the angle across those edges is 3/2
times larger and across the others it vanishes; the energy is 3/2 the shortcut's.)

Derivatives. With e_i = p_{i+1} - p_{i+2} the edge opposite vertex i and [e]x the cross-product
matrix, du/dp_i = -[e_i]x and dn/du = P / |u|, P = I - n n^T. Writing S = [[e_0]x; [e_1]x;
[e_2]x] (9 x 3), the Jacobian of the normal is J = (P / |u|) S^T (3 x 9). Since
E = sum_h 2 c_h (1 - n_a . n_b), every triangle sees m_a = sum over its hinges of c_h n_b:

  grad_a E = -2 J_a^T m_a,
  hess E   = -2 [ per triangle: S Hu S^T + B(g)   ;   per hinge: c_h (J_a^T J_b + J_b^T J_a) ],

with Hu = -[ (P m) n^T + n (P m)^T + (m . n) P ] / |u|^2 the Hessian of m . u/|u| in u,
g = P m / |u| its gradient, and B(g) the 9 x 9 block matrix from the bilinearity of u in the
vertices: blocks (i, i+1) = -[g]x and (i+1, i) = +[g]x (indices mod 3).
The triangle terms cost O(T) and the hinge terms O(H); no per-hinge 12 x 12 second
derivatives of normals are formed.
"""
from __future__ import annotations

import numpy as np

def _bilinear_positions():
    """Flat positions in a 9 x 9 block of the entries (a, b) of blocks (i, i+1) and (i+1, i)."""
    upper, lower = [], []
    for i in range(3):
        j = (i + 1) % 3
        for a in range(3):
            for b in range(3):
                upper.append((3 * i + a) * 9 + 3 * j + b)
                lower.append((3 * j + a) * 9 + 3 * i + b)
    return np.array(upper), np.array(lower)


_BILINEAR_UPPER, _BILINEAR_LOWER = _bilinear_positions()


def cross_matrix(v: np.ndarray) -> np.ndarray:
    """[v]x for a stack of vectors (..., 3) -> (..., 3, 3), with [v]x w = v x w."""
    m = np.zeros(v.shape[:-1] + (3, 3))
    m[..., 0, 1], m[..., 0, 2] = -v[..., 2], v[..., 1]
    m[..., 1, 0], m[..., 1, 2] = v[..., 2], -v[..., 0]
    m[..., 2, 0], m[..., 2, 1] = -v[..., 1], v[..., 0]
    return m


def triangle_normals(x: np.ndarray, triangles: np.ndarray):
    """Unit normals (T, 3) and doubled areas |u| (T,) of the deformed triangles."""
    p = x[triangles]
    u = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    double_area = np.linalg.norm(u, axis=1)
    return u / double_area[:, None], double_area


def hinge_stiffness(rest_edge_lengths: np.ndarray, rest_pair_areas: np.ndarray, bending_stiffness: float) -> np.ndarray:
    """Per-hinge coefficient c_h giving the continuum plate bending stiffness D.

    On equilateral triangles c = D / sqrt(3) (Eq. 11b with D = E b^3 / 12, D_eff = sqrt(3) c).
    For general meshes it is spread with the discrete-shells weight |e|^2 / (A_a + A_b), which
    is 2 / sqrt(3) on equilateral triangles: c_h = D |e_bar|^2 / (2 (A_a + A_b)).
    """
    return 0.5 * bending_stiffness * rest_edge_lengths**2 / rest_pair_areas


def hinge_bending_energy(x: np.ndarray, triangles: np.ndarray, hinge_triangles: np.ndarray, stiffness: np.ndarray,
                         *, gradient: bool = True, hessian: bool = True):
    """Eq. (11b) for the deformed node positions x (N, 3).

    Returns (energy per hinge (H,), gradient per triangle (T, 9), Hessian per triangle
    (T, 9, 9), cross blocks per hinge (H, 9, 9)), all in the triangles' own vertex order: the
    cross block C couples triangle a's nine coordinates (rows) with triangle b's (columns) and
    enters the Hessian as C + C^T (the shared edge's nodes appear in both, where C + C^T
    lands on the same entries twice). Unrequested parts are None. Assembly sums the blocks
    (ddg.models.plate).
    """
    n, double_area = triangle_normals(x, triangles)
    tri_a, tri_b = hinge_triangles[:, 0], hinge_triangles[:, 1]
    diff = n[tri_a] - n[tri_b]
    energy = stiffness * np.einsum("hi,hi->h", diff, diff)
    if not gradient:
        return energy, None, None, None
    count = len(triangles)
    m = np.stack([np.bincount(tri_a, weights=stiffness * n[tri_b, k], minlength=count)
                  + np.bincount(tri_b, weights=stiffness * n[tri_a, k], minlength=count) for k in range(3)], axis=1)
    p = x[triangles]
    opposite = np.stack([p[:, 1] - p[:, 2], p[:, 2] - p[:, 0], p[:, 0] - p[:, 1]], axis=1)  # e_i, (T, 3, 3)
    S = cross_matrix(opposite).reshape(count, 9, 3)
    projector = np.eye(3) - n[:, :, None] * n[:, None, :]
    pm = np.einsum("tij,tj->ti", projector, m)
    g_u = pm / double_area[:, None]
    grad = -2.0 * (S @ g_u[:, :, None])[:, :, 0]
    if not hessian:
        return energy, grad, None, None
    mn = np.einsum("ti,ti->t", m, n)
    h_u = -(pm[:, :, None] * n[:, None, :] + n[:, :, None] * pm[:, None, :] + mn[:, None, None] * projector)
    h_u /= (double_area**2)[:, None, None]
    St = S.transpose(0, 2, 1)
    hess_tri = S @ h_u @ St
    # B(g): blocks (i, i+1) = -[g]x, (i+1, i) = +[g]x; [g]x is antisymmetric, so both are
    # +/- the same nine numbers at fixed positions of the flattened 9 x 9 block
    G = cross_matrix(g_u).reshape(count, 9)
    flat = hess_tri.reshape(count, 81)
    flat[:, _BILINEAR_UPPER] -= np.tile(G, 3)
    flat[:, _BILINEAR_LOWER] += np.tile(G, 3)
    hess_tri *= -2.0

    Jt = S @ (projector / double_area[:, None, None])  # J^T, (T, 9, 3): P is symmetric
    cross = Jt[tri_a] @ (Jt[tri_b].transpose(0, 2, 1) * (-2.0 * stiffness)[:, None, None])
    return energy, grad, hess_tri, cross
