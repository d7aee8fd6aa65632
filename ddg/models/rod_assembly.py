"""The DAR's energy, gradient and banded Hessian in one compiled call (paper section 3.1, Eq. 6),
and with the quartic twist term of Eq. (A.5) for the Sadowsky ribbon.

The same pieces as the model's Python composition (ddg.models.rod.RodModel.evaluate): frames
transported in time (ddg.geometry.frames.rod_frames), the material curvatures (Eq. 4) and the
twist (Eq. 5), the densities of bending (Eq. 6b), twisting (Eq. 6c) and, where zeta > 0, the
Sadowsky term (ddg.energies.sadowsky), the stretching of the edges (Eq. 6a) and the stencils'
chain rule (ddg.energies.rod_curvature.add_stencil_terms); no physics is written here. One call
instead of a dozen saves the interpreter's ~30 microseconds per evaluation, and it is what the
compiled Newton loop (ddg.solve.compiled_newton) calls.

`rod_energy(q, state, args, want_gradient, want_hessian, grad, band)`: state = the committed
(tangents, d1, m_ref); args = the model's constants (RodModel.assembly_args); grad (n,) and the
flattened lower band ((bandwidth + 1) n) are zeroed by the caller and added into. Returns the
energy by part (stretching, bending, twisting, sadowsky) and the frames of q (tangents, d1, m_ref).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..energies.rod_bending import bending_density
from ..energies.rod_curvature import curvature_rows, add_stencil_terms
from ..energies.rod_twist import discrete_twist, twisting_density
from ..energies.sadowsky import sadowsky_terms
from ..energies.stretch import add_edge_terms
from ..geometry.frames import rod_frames

#: The parts rod_energy returns, in its order (the Sadowsky part is zero without the term).
PARTS = ("stretching", "bending", "twisting", "sadowsky")


@njit(cache=True)
def rod_energy(q, state, args, want_gradient, want_hessian, grad, band):
    old_t, old_d1, old_m_ref = state
    node_stride, edge_nodes, rest_lengths, stretch_k, voronoi, ei2, ei1, gj, zeta = args
    nodes = old_t.shape[0] + 1
    n_dof = q.shape[0]
    x = np.empty((nodes, 3))
    theta = np.empty(nodes - 1)
    for j in range(nodes):
        for k in range(3):
            x[j, k] = q[node_stride * j + k]
        if j < nodes - 1:
            theta[j] = q[node_stride * j + 3]
    t, d1, m1, m2, m_ref = rod_frames(x, old_t, old_d1, theta, old_m_ref)
    kappa = curvature_rows(x, m1, m2)
    kappa_n = kappa[:, 0].copy()
    kappa_g = kappa[:, 1].copy()
    tau = discrete_twist(theta, m_ref)
    e_b, first, second = bending_density(kappa_n, kappa_g, voronoi, ei2, ei1)
    e_t, f_t, s_t = twisting_density(tau, voronoi, gj)
    first += f_t
    second += s_t
    parts = np.zeros(4)
    if zeta > 0.0:
        e_q, f_q, s_q = sadowsky_terms(kappa_n, tau, voronoi, ei2, zeta)
        first += f_q
        second += s_q
        parts[3] = e_q.sum()
    parts[0] = add_edge_terms(x, edge_nodes, rest_lengths, stretch_k, node_stride, n_dof, grad, band,
                              want_gradient, want_hessian)
    parts[1] = e_b.sum()
    parts[2] = e_t.sum()
    if want_gradient:
        add_stencil_terms(x, m1, m2, first, second, node_stride, n_dof, grad, band, want_hessian)
    return parts, (t, d1, m_ref)
