"""The rod's bending energy, Eq. (6b), as a function of the stencil strains.

E_b = 1/2 sum 1/dl_i [EI2 (kappa_n)^2 + EI1 (kappa_g)^2] for a naturally straight strip,
with kappa_n (out of plane) and kappa_g (geodesic) from rod_curvature; dl_i is the
undeformed Voronoi length. The chain rule to the DOFs is rod_curvature.add_stencil_terms.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .rod_curvature import KAPPA_G, KAPPA_N


@njit(cache=True)
def bending_density(kappa_n, kappa_g, voronoi_lengths, bending_stiffness, geodesic_bending_stiffness):
    """E_b per stencil (n,), its partials in (kappa_n, kappa_g, tau) (n, 3) and second partials (n, 3, 3)."""
    n = kappa_n.shape[0]
    energy = np.empty(n)
    first = np.zeros((n, 3))
    second = np.zeros((n, 3, 3))
    for i in range(n):
        a = bending_stiffness / voronoi_lengths[i]
        c = geodesic_bending_stiffness / voronoi_lengths[i]
        energy[i] = 0.5 * (a * kappa_n[i] * kappa_n[i] + c * kappa_g[i] * kappa_g[i])
        first[i, KAPPA_N] = a * kappa_n[i]
        first[i, KAPPA_G] = c * kappa_g[i]
        second[i, KAPPA_N, KAPPA_N] = a
        second[i, KAPPA_G, KAPPA_G] = c
    return energy, first, second
