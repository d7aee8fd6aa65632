"""Discrete twist and the rod's twisting energy, Eqs. (5) and (6c).

tau_i = theta^i - theta^{i-1} + m_ref_i; E_t = 1/2 sum GJ / dl_i tau_i^2. With reference
frames carried by parallel transport in time, d m_ref / de = kb / (2 |e|) and
d m_ref / df = kb / (2 |f|) (Bergou et al. 2010). Stencil layout as in rod_curvature.
"""
from __future__ import annotations

import numpy as np

from .rod_curvature import TE, TF, StencilGeometry, StencilHessian, _outer, _scatter_edges, _skew


def twist_derivatives(g: StencilGeometry, hessian: bool = True):
    """Gradient (n, 11) and Hessian (StencilHessian; the twist is linear in theta) of tau."""
    n = g.e.shape[0]
    grad = np.zeros((n, 11))
    _scatter_edges(0.5 * g.kb / g.norm_e[:, None], 0.5 * g.kb / g.norm_f[:, None], grad)
    grad[:, TE] = -1.0
    grad[:, TF] = 1.0
    if not hessian:
        return grad, None
    chi3 = g.chi[:, None, None]
    inv_e2 = (1.0 / g.norm_e**2)[:, None, None]
    inv_f2 = (1.0 / g.norm_f**2)[:, None, None]
    inv_ef = (1.0 / (g.norm_e * g.norm_f))[:, None, None]
    a_e = g.te + g.tilde_t
    a_f = g.tf + g.tilde_t
    # symmetric parts of the derivatives of kb / (2|e|) and kb / (2|f|)
    h_ee = -0.25 * inv_e2 * (_outer(g.kb, a_e) + _outer(a_e, g.kb))
    h_ff = -0.25 * inv_f2 * (_outer(g.kb, a_f) + _outer(a_f, g.kb))
    h_ef = 0.5 * inv_ef * ((_skew(g.te) + _skew(g.tf)) / chi3 - 0.5 * (_outer(g.kb, g.tilde_t) + _outer(g.tilde_t, g.kb)))
    zero = np.zeros((n, 3, 2))
    return grad, StencilHessian(h_ee, h_ef, h_ff, zero, zero, np.zeros((n, 2)))


def twisting_energy(tau, voronoi_lengths, twisting_stiffness, grad_tau=None, hess_tau=None):
    """E_t per node, its stencil gradient and Hessian (Eq. 6c)."""
    k = twisting_stiffness / voronoi_lengths
    energy = 0.5 * k * tau**2
    if grad_tau is None:
        return energy, None, None
    grad = (k * tau)[:, None] * grad_tau
    if hess_tau is None:
        return energy, grad, None
    hess = k[:, None, None] * (grad_tau[:, :, None] * grad_tau[:, None, :])
    hess += hess_tau.scaled_sum([k * tau]).to_stencil()
    return energy, grad, hess
