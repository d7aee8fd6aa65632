"""Discrete twist and the rod's twisting energy, Eqs. (5) and (6c).

tau_i = theta^i - theta^{i-1} + m_ref_i; E_t = 1/2 sum GJ / dl_i tau_i^2. The derivatives of
tau (through m_ref, for reference frames carried by parallel transport in time) are computed with
the curvatures' in rod_curvature; the chain rule to the DOFs is rod_curvature.add_stencil_terms.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .rod_curvature import TAU


@njit(cache=True)
def discrete_twist(theta: np.ndarray, reference_twist: np.ndarray) -> np.ndarray:
    """tau at the interior nodes (Eq. 5) from the M - 1 twist angles and the M - 2 reference twists."""
    tau = np.empty(reference_twist.shape[0])
    for i in range(tau.shape[0]):
        tau[i] = theta[i + 1] - theta[i] + reference_twist[i]
    return tau


@njit(cache=True)
def twisting_density(tau, voronoi_lengths, twisting_stiffness):
    """E_t per stencil (n,), its partials in (kappa_n, kappa_g, tau) (n, 3) and second partials (n, 3, 3)."""
    n = tau.shape[0]
    energy = np.empty(n)
    first = np.zeros((n, 3))
    second = np.zeros((n, 3, 3))
    for i in range(n):
        k = twisting_stiffness / voronoi_lengths[i]
        energy[i] = 0.5 * k * tau[i] * tau[i]
        first[i, TAU] = k * tau[i]
        second[i, TAU, TAU] = k
    return energy, first, second
