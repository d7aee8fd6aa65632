"""Hinge bending of a triangle mesh, Eq. (11b): E = sum over bending pairs c_h |n_a - n_b|^2.

n_a, n_b are the unit normals of the two triangles sharing the hinge edge, each computed from
its counter-clockwise vertices (p0, p1, p2) as n = u / |u|, u = (p1 - p0) x (p2 - p0), so a flat
mesh has all normals +z and zero energy. |n_a - n_b|^2 = 2 (1 - n_a . n_b) = 4 sin^2(theta/2)
with theta the dihedral (bending) angle.

Continuum limit (Seung and Nelson 1988; measured in tests/ddg/energies/test_plate_energies.py): on an
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

Compiled (numba): `triangle_normal`, `triangle_terms` and `hinge_cross_block` are the one
implementation, per element; `hinge_bending_energy` returns the blocks per element (tests,
analysis) and `add_hinge_terms` writes the same terms straight into the assembled gradient and band.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..assembly.band_scatter import add_pair_block, add_symmetric_block


def hinge_stiffness(rest_edge_lengths: np.ndarray, rest_pair_areas: np.ndarray, bending_stiffness: float) -> np.ndarray:
    """Per-hinge coefficient c_h giving the continuum plate bending stiffness D.

    On equilateral triangles c = D / sqrt(3) (Eq. 11b with D = E b^3 / 12, D_eff = sqrt(3) c).
    For general meshes it is spread with the discrete-shells weight |e|^2 / (A_a + A_b), which
    is 2 / sqrt(3) on equilateral triangles: c_h = D |e_bar|^2 / (2 (A_a + A_b)).
    """
    return 0.5 * bending_stiffness * rest_edge_lengths**2 / rest_pair_areas


# ---------------------------------------------------------------------------- per element
@njit(cache=True, forceinline=True)
def triangle_normal(x, tri, out):
    """Unit normal of triangle tri (3 node indices into x (N, 3)) into out; returns |u| (twice the area)."""
    p0, p1, p2 = tri[0], tri[1], tri[2]
    a0, a1, a2 = x[p1, 0] - x[p0, 0], x[p1, 1] - x[p0, 1], x[p1, 2] - x[p0, 2]
    b0, b1, b2 = x[p2, 0] - x[p0, 0], x[p2, 1] - x[p0, 1], x[p2, 2] - x[p0, 2]
    u0, u1, u2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    norm = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    out[0], out[1], out[2] = u0 / norm, u1 / norm, u2 / norm
    return norm


@njit(cache=True)
def triangle_terms(x, tri, n, double_area, m, grad, hess, jt, want_hessian):
    """A triangle's share of the hinge energy's derivatives, given its unit normal n, |u| and
    m = sum over its hinges of c_h n_other: grad (9,) = -2 J^T m; hess (9, 9) = -2 (S Hu S^T + B(g));
    jt (9, 3) = J^T = S P / |u|, kept for the hinge cross blocks."""
    opp = np.empty((3, 3))  # e_i = p_{i+1} - p_{i+2}, the edge opposite vertex i
    for i in range(3):
        a, b = tri[(i + 1) % 3], tri[(i + 2) % 3]
        for k in range(3):
            opp[i, k] = x[a, k] - x[b, k]
    proj = np.empty((3, 3))
    for a in range(3):
        for b in range(3):
            proj[a, b] = (1.0 if a == b else 0.0) - n[a] * n[b]
    pm = np.empty(3)
    for a in range(3):
        pm[a] = proj[a, 0] * m[0] + proj[a, 1] * m[1] + proj[a, 2] * m[2]
    inv = 1.0 / double_area
    g0, g1, g2 = pm[0] * inv, pm[1] * inv, pm[2] * inv
    # S = [[e_0]x; [e_1]x; [e_2]x] (9 x 3): rows of [e]x are (0, -e2, e1), (e2, 0, -e0), (-e1, e0, 0)
    S = np.zeros((9, 3))
    for i in range(3):
        e0, e1, e2 = opp[i, 0], opp[i, 1], opp[i, 2]
        S[3 * i, 1], S[3 * i, 2] = -e2, e1
        S[3 * i + 1, 0], S[3 * i + 1, 2] = e2, -e0
        S[3 * i + 2, 0], S[3 * i + 2, 1] = -e1, e0
    for r in range(9):
        grad[r] = -2.0 * (S[r, 0] * g0 + S[r, 1] * g1 + S[r, 2] * g2)
        for b in range(3):
            jt[r, b] = (S[r, 0] * proj[0, b] + S[r, 1] * proj[1, b] + S[r, 2] * proj[2, b]) * inv
    if not want_hessian:
        return
    mn = m[0] * n[0] + m[1] * n[1] + m[2] * n[2]
    hu = np.empty((3, 3))
    for a in range(3):
        for b in range(3):
            hu[a, b] = -(pm[a] * n[b] + n[a] * pm[b] + mn * proj[a, b]) * inv * inv
    shu = np.empty((9, 3))
    for r in range(9):
        for b in range(3):
            shu[r, b] = S[r, 0] * hu[0, b] + S[r, 1] * hu[1, b] + S[r, 2] * hu[2, b]
    for r in range(9):
        for c in range(9):
            hess[r, c] = shu[r, 0] * S[c, 0] + shu[r, 1] * S[c, 1] + shu[r, 2] * S[c, 2]
    # B(g): blocks (i, i+1) = -[g]x, (i+1, i) = +[g]x
    for i in range(3):
        j = (i + 1) % 3
        hess[3 * i, 3 * j + 1] += g2
        hess[3 * i, 3 * j + 2] -= g1
        hess[3 * i + 1, 3 * j] -= g2
        hess[3 * i + 1, 3 * j + 2] += g0
        hess[3 * i + 2, 3 * j] += g1
        hess[3 * i + 2, 3 * j + 1] -= g0
        hess[3 * j, 3 * i + 1] -= g2
        hess[3 * j, 3 * i + 2] += g1
        hess[3 * j + 1, 3 * i] += g2
        hess[3 * j + 1, 3 * i + 2] -= g0
        hess[3 * j + 2, 3 * i] -= g1
        hess[3 * j + 2, 3 * i + 1] += g0
    for r in range(9):
        for c in range(9):
            hess[r, c] *= -2.0


@njit(cache=True, forceinline=True)
def hinge_cross_block(jt_a, jt_b, stiffness, out):
    """C = -2 c_h J_a^T J_b (9 x 9; rows: triangle a's coordinates, columns: b's); enters as C + C^T."""
    for r in range(9):
        for c in range(9):
            out[r, c] = -2.0 * stiffness * (jt_a[r, 0] * jt_b[c, 0] + jt_a[r, 1] * jt_b[c, 1] + jt_a[r, 2] * jt_b[c, 2])


@njit(cache=True)
def _normals_and_energy(x, triangles, hinge_triangles, stiffness):
    count = triangles.shape[0]
    normals = np.empty((count, 3))
    double_area = np.empty(count)
    for t in range(count):
        double_area[t] = triangle_normal(x, triangles[t], normals[t])
    energy = np.empty(hinge_triangles.shape[0])
    m = np.zeros((count, 3))
    for h in range(hinge_triangles.shape[0]):
        a, b = hinge_triangles[h, 0], hinge_triangles[h, 1]
        d0, d1, d2 = normals[a, 0] - normals[b, 0], normals[a, 1] - normals[b, 1], normals[a, 2] - normals[b, 2]
        energy[h] = stiffness[h] * (d0 * d0 + d1 * d1 + d2 * d2)
        for k in range(3):
            m[a, k] += stiffness[h] * normals[b, k]
            m[b, k] += stiffness[h] * normals[a, k]
    return normals, double_area, energy, m


@njit(cache=True)
def _blocks(x, triangles, hinge_triangles, stiffness, want_hessian):
    normals, double_area, energy, m = _normals_and_energy(x, triangles, hinge_triangles, stiffness)
    count = triangles.shape[0]
    grad = np.empty((count, 9))
    hess = np.zeros((count, 9, 9))
    jt = np.empty((count, 9, 3))
    for t in range(count):
        triangle_terms(x, triangles[t], normals[t], double_area[t], m[t], grad[t], hess[t], jt[t], want_hessian)
    cross = np.zeros((hinge_triangles.shape[0] if want_hessian else 0, 9, 9))
    if want_hessian:
        for h in range(hinge_triangles.shape[0]):
            hinge_cross_block(jt[hinge_triangles[h, 0]], jt[hinge_triangles[h, 1]], stiffness[h], cross[h])
    return energy, grad, hess, cross


@njit(cache=True)
def add_hinge_terms(x, triangles, hinge_triangles, stiffness, n_dof, grad, band, want_gradient, want_hessian):
    """Eq. (11b) assembled: adds the gradient (3 DOFs per node, node j at 3 j) to grad and the
    Hessian to the flattened lower band where asked; returns the energy."""
    normals, double_area, energy, m = _normals_and_energy(x, triangles, hinge_triangles, stiffness)
    total = energy.sum()
    if not want_gradient:
        return total
    count = triangles.shape[0]
    g9 = np.empty(9)
    h9 = np.zeros((9, 9))
    cross = np.empty((9, 9))
    jt = np.empty((count, 9, 3))
    dofs = np.empty((count, 9), dtype=np.int64)
    for t in range(count):
        for i in range(3):
            for k in range(3):
                dofs[t, 3 * i + k] = 3 * triangles[t, i] + k
        triangle_terms(x, triangles[t], normals[t], double_area[t], m[t], g9, h9, jt[t], want_hessian)
        for r in range(9):
            grad[dofs[t, r]] += g9[r]
        if want_hessian:
            add_symmetric_block(band, n_dof, dofs[t], h9)
    if want_hessian:
        for h in range(hinge_triangles.shape[0]):
            a, b = hinge_triangles[h, 0], hinge_triangles[h, 1]
            hinge_cross_block(jt[a], jt[b], stiffness[h], cross)
            add_pair_block(band, n_dof, dofs[a], dofs[b], cross)
    return total


# ---------------------------------------------------------------------------- array interface
@njit(cache=True)
def _normals(x, triangles):
    normals = np.empty((triangles.shape[0], 3))
    double_area = np.empty(triangles.shape[0])
    for t in range(triangles.shape[0]):
        double_area[t] = triangle_normal(x, triangles[t], normals[t])
    return normals, double_area


def triangle_normals(x: np.ndarray, triangles: np.ndarray):
    """Unit normals (T, 3) and doubled areas |u| (T,) of the deformed triangles (the kernel's
    triangle_normal, for analysis: resolution indicators, curvatures)."""
    return _normals(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(triangles, dtype=np.int64))


def hinge_bending_energy(x: np.ndarray, triangles: np.ndarray, hinge_triangles: np.ndarray, stiffness: np.ndarray,
                         *, gradient: bool = True, hessian: bool = True):
    """Eq. (11b) for the deformed node positions x (N, 3).

    Returns (energy per hinge (H,), gradient per triangle (T, 9), Hessian per triangle
    (T, 9, 9), cross blocks per hinge (H, 9, 9)), all in the triangles' own vertex order: the
    cross block C couples triangle a's nine coordinates (rows) with triangle b's (columns) and
    enters the Hessian as C + C^T (the shared edge's nodes appear in both, where C + C^T
    lands on the same entries twice). Unrequested parts are None. The models assemble the same
    terms with `add_hinge_terms`.
    """
    x = np.ascontiguousarray(x, dtype=float)
    triangles = np.ascontiguousarray(triangles, dtype=np.int64)
    hinge_triangles = np.ascontiguousarray(hinge_triangles, dtype=np.int64)
    stiffness = np.ascontiguousarray(np.broadcast_to(stiffness, (len(hinge_triangles),)), dtype=float)
    if not gradient:
        return _normals_and_energy(x, triangles, hinge_triangles, stiffness)[2], None, None, None
    energy, grad, hess, cross = _blocks(x, triangles, hinge_triangles, stiffness, bool(hessian))
    return energy, grad, (hess if hessian else None), (cross if hessian else None)
